"""Tables of a rig ablation (scripts/rig/ablation.sh): one row per configuration directory of
OUT holding rig-check.json, in the order given by OUT/order.txt when present, else by name.

    python3 scripts/rig/table.py OUT
"""
import json
import pathlib
import sys

CHANNELS = ["F_x", "F_y", "M_x", "M_y", "M_z"]


def load(out):
    order_file = out / "order.txt"
    if order_file.exists():
        names = [n.strip() for n in order_file.read_text().split() if n.strip()]
    else:
        names = sorted(p.parent.name for p in out.glob("*/rig-check.json"))
    rows = []
    for name in names:
        path = out / name / "rig-check.json"
        if path.exists():
            rows.append((name, json.loads(path.read_text())))
    return rows


def lag(s, inp):
    for p in s["lags"]:
        if p["input"] == inp and p["output"] == "F_x":
            return p
    return None


def main():
    out = pathlib.Path(sys.argv[1])
    rows = load(out)
    if not rows:
        sys.exit(f"no rig-check.json under {out}")
    ref = rows[0][1]
    print("#### r with the stand-in (train / test)\n")
    print("| wing | " + " | ".join(CHANNELS) + " |")
    print("|---" * 6 + "|")
    for name, c in rows:
        cells = [f"{c['train']['channels'][k]['r']:.3f} / {c['test']['channels'][k]['r']:.3f}" for k in range(5)]
        print(f"| {name} | " + " | ".join(cells) + " |")
    print("\n#### z-RMSE with the stand-in, σ (train / test)\n")
    print("| wing | " + " | ".join(CHANNELS) + " |")
    print("|---" * 6 + "|")
    for name, c in rows:
        cells = [f"{c['train']['channels'][k]['z_rmse']:.3f} / {c['test']['channels'][k]['z_rmse']:.3f}" for k in range(5)]
        print(f"| {name} | " + " | ".join(cells) + " |")
    print("\n#### Couplings and Fig. 5 lags on F_x (train / test)\n")
    print("| wing | r(F_y, F_x) | r(M_x, F_x) | a_x → F_x median lag (cycles) | AoA → F_x lag IQR (cycles) |")
    print("|---|---|---|---|---|")

    def line(name, key, c):
        t, s = c["train"], c["test"]
        ax_t, ax_s = lag(t, "a_x")[key], lag(s, "a_x")[key]
        aoa_t, aoa_s = lag(t, "AoA")[key], lag(s, "AoA")[key]
        print(
            f"| {name} | {t[key + '_couplings']['fy_fx']:.3f} / {s[key + '_couplings']['fy_fx']:.3f}"
            f" | {t[key + '_couplings']['mx_fx']:.3f} / {s[key + '_couplings']['mx_fx']:.3f}"
            f" | {ax_t['median_lag_cycles']:.3f} / {ax_s['median_lag_cycles']:.3f}"
            f" | {aoa_t['lag_iqr_cycles']:.3f} / {aoa_s['lag_iqr_cycles']:.3f} |"
        )

    line("stand-in (published model)", "reference", ref)
    for name, c in rows:
        line(name, "dataset", c)


if __name__ == "__main__":
    main()
