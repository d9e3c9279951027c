"""The spectrum of a wing's loads beyond the quasi-steady ones: do they follow flow time scales?

A wing's residual against L0 (the quasi-steady loads of the same trajectories)
should hold the flow's own time scales, the stroke's harmonics and the convective time c/U_ref,
not bursts faster than any of them. Each DATA.npz is `flapssm simulate --noise-free` of the same
trajectories at one fidelity; REFERENCE.npz is the same at L0. Per dataset and output channel,
from sample 93 on (the published evaluation window): the residual's rms (in the units of the
file), its lag-1 autocorrelation at the sampling rate, and the share of its power above 1 Hz and
above the convective frequency f_c = U_ref / c (from the file's metadata: U_ref the mean
reference speed, c the chord). The power spectrum is the mean over trajectories of the Hann-
windowed periodogram of the mean-removed residual. `--plot FILE.png` draws it (needs matplotlib),
with the median stroke frequency and f_c marked.

    python scripts/residual_spectrum.py REFERENCE.npz DATA.npz [DATA.npz ...] [--plot FILE.png]

Needs numpy (a study, not part of the test suite).
"""

import argparse
import json
import os
import sys

import numpy as np

START = 93


def load(path):
    """(y, euler angles, sample interval s, chord m, mean U_ref m/s, fidelity, output names and
    units) of a flapssm dataset, or exit naming the file."""
    try:
        d = np.load(path, allow_pickle=False)
        meta = json.loads(str(d["metadata"]))
        return dict(
            y=d["y"],
            euler=d["euler_rad"],
            dt=float(d["dt_s"]),
            chord=float(meta["wing"]["chord_m"]),
            u_ref=float(meta["settings"]["mean_u_ref_m_s"]),
            fidelity=str(meta["settings"]["fidelity"]).upper(),
            names=[str(n) for n in d["output_names"]],
            units=[str(n) for n in d["output_units"]],
        )
    except (OSError, KeyError, ValueError, TypeError) as e:
        sys.exit(f"error: {path}: {e}")


def periodogram(x, dt):
    """Frequencies (Hz) and the Hann-windowed periodogram of x (traj, time, ch) along time; x is
    expected with its mean over time removed."""
    w = np.hanning(x.shape[1])[None, :, None]
    return np.fft.rfftfreq(x.shape[1], dt), np.abs(np.fft.rfft(x * w, axis=1)) ** 2


def stroke_frequency(euler, dt):
    """Median over trajectories of the stroke angle's spectral peak (Hz)."""
    stroke = euler[:, START:, :1]
    f, p = periodogram(stroke - stroke.mean(axis=1, keepdims=True), dt)
    return float(np.median(f[np.argmax(p[:, 1:, 0], axis=1) + 1]))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("reference")
    p.add_argument("datasets", nargs="+")
    p.add_argument("--plot", default=None, metavar="FILE.png")
    a = p.parse_args()
    ref = load(a.reference)
    f_stroke = stroke_frequency(ref["euler"], ref["dt"])
    f_c = ref["u_ref"] / ref["chord"]
    print(f"{a.reference} ({ref['fidelity']}): median stroke frequency {f_stroke:.3f} Hz, "
          f"convective frequency U_ref/c {f_c:.2f} Hz, samples {START}..")
    curves = []
    for path in a.datasets:
        d = load(path)
        if d["y"].shape != ref["y"].shape or d["names"] != ref["names"] or not np.allclose(d["euler"], ref["euler"]):
            sys.exit(f"error: {path}: not the same trajectories and channels as {a.reference}")
        r = (d["y"] - ref["y"])[:, START:, :]
        rc = r - r.mean(axis=1, keepdims=True)
        f, p_traj = periodogram(rc, d["dt"])
        psd = p_traj.mean(axis=0)
        total = psd[1:].sum(axis=0)
        above_1 = psd[f > 1.0].sum(axis=0) / total
        above_c = psd[f > f_c].sum(axis=0) / total
        lag1 = (rc[:, 1:] * rc[:, :-1]).sum(axis=(0, 1)) / (rc**2).sum(axis=(0, 1))
        rms = np.sqrt((r**2).mean(axis=(0, 1)))
        print(f"\n{path} ({d['fidelity']} - {ref['fidelity']}):")
        print(f"{'':<26}" + "".join(f"{n:>9}" for n in d["names"]))
        print(f"{'rms':<26}" + "".join(f"{v:9.4g}" for v in rms) + "  (" + ", ".join(d["units"]) + ")")
        print(f"{'lag-1 autocorrelation':<26}" + "".join(f"{v:9.3f}" for v in lag1))
        print(f"{'power above 1 Hz':<26}" + "".join(f"{v:9.1%}" for v in above_1))
        print(f"{'power above f_c':<26}" + "".join(f"{v:9.1%}" for v in above_c))
        curves.append((f"{d['fidelity']} − {ref['fidelity']}", f, psd))
    if a.plot:
        plot(a.plot, curves, ref, f_stroke, f_c)


def plot(path, curves, ref, f_stroke, f_c):
    """One panel per output channel: each residual's power spectrum, normalized to its total."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = ref["names"]
    fig, axes = plt.subplots(1, len(names), figsize=(3.2 * len(names), 3.2), sharey=True)
    for k, ax in enumerate(axes):
        for label, f, psd in curves:
            ax.loglog(f[1:], psd[1:, k] / psd[1:, k].sum(), label=label, lw=1)
        ax.axvline(f_stroke, color="grey", ls=":", lw=1)
        ax.axvline(f_c, color="grey", ls="--", lw=1)
        ax.set_title(f"{names[k]} residual")
        ax.set_xlabel("frequency (Hz)")
    axes[0].set_ylabel("share of power per bin")
    axes[0].legend(fontsize=7, title=f"stroke {f_stroke:.2f} Hz (:), U_ref/c {f_c:.1f} Hz (--)", title_fontsize=7)
    fig.tight_layout()
    fig.savefig(path + ".tmp.png", dpi=110)
    os.replace(path + ".tmp.png", path)
    print(f"\nwrote {path}")


if __name__ == "__main__":
    main()
