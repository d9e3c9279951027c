"""The figures of scripts/rig/ceiling.sh (docs/rig-agreement.md), as Markdown on stdout.

Every fit is least squares on the paper's 512 training trajectories (samples 93 on) and scored
by Pearson r with the stand-in, on those and on the 36 test trajectories.

    python3 scripts/rig/ceiling.py OUT
"""
import pathlib
import sys

import numpy as np

START = 93
NAMES = ["F_x", "F_y", "M_x", "M_y", "M_z"]


def main():
    out = pathlib.Path(sys.argv[1])
    load = lambda name: np.load(out / f"{name}.npz")
    l0 = load("l0")
    y, u = l0["y"], l0["u"]
    stand = load("stand-in")
    ref, var = stand["output_mean"], stand["output_var"]
    train = stand["is_train"].astype(bool)
    rot = y - load("l0-no-rotational")["y"]
    am = y - load("l0-no-added-mass")["y"]
    trans = y - rot - am
    static = load("static-residual")["y"] - y
    inertial = load("inertial-residual")["y"] - y
    aoa, speed2 = u[..., 0], u[..., 1] ** 2

    def flat(a, sel):
        return a[sel][:, START:].reshape(-1, *a.shape[2:])

    def fit(columns, k):
        """r on train / test of the least-squares fit of the stand-in's channel k on columns
        (functions of the selection giving one regressor each)."""
        r = []
        coef = None
        for sel in (train, ~train):
            x = np.column_stack([np.ones(flat(y, sel).shape[0])] + [c(sel) for c in columns])
            b = flat(ref, sel)[:, k]
            if coef is None:
                coef, *_ = np.linalg.lstsq(x, b, rcond=None)
            r.append(np.corrcoef(x @ coef, b)[0, 1])
        return r

    comp = lambda a, k, lag=0: (lambda sel: flat(np.roll(a, lag, axis=1), sel)[:, k])
    basis = lambda f: (lambda sel: flat(f, sel))
    fourier = lambda order: [basis(speed2 * g(j * aoa)) for j in range(1, order + 1) for g in (np.sin, np.cos)]

    print("#### The stand-in's own spread\n")
    sd = np.sqrt(flat(var, ~train)).mean(axis=0) / flat(ref, train).std(axis=0)
    print("Mean predictive SD on the test trajectories, in SD of the training outputs: "
          + ", ".join(f"{n} {v:.3f}" for n, v in zip(NAMES, sd)) + ".\n")

    print("#### Memoryless wings, fitted (r with the stand-in, train / test)\n")
    print("| regressors | F_x | M_y | M_z |")
    print("|---|---|---|---|")
    rows = [
        ("L0 as it is (no fit)", None),
        ("L0's translational, rotational and added-mass parts, free weights", []),
        ("the same + any C_N(AoA): Fourier order 2 in AoA × |v|²", fourier(2)),
        ("the same, order 6", fourier(6)),
    ]
    for label, extra in rows:
        cells = []
        for k in (0, 3, 4):
            if extra is None:
                r = [np.corrcoef(flat(y, s)[:, k], flat(ref, s)[:, k])[0, 1] for s in (train, ~train)]
            else:
                r = fit([comp(trans, k), comp(rot, k), comp(am, k)] + extra, k)
            cells.append(f"{r[0]:.3f} / {r[1]:.3f}")
        print(f"| {label} | " + " | ".join(cells) + " |")
    cells = []
    for k in (0, 3, 4):
        cols = [comp(a, k, lag) for a in (trans, rot, am) for lag in (0, 1, 2)] + fourier(2)
        r = fit(cols, k)
        cells.append(f"{r[0]:.3f} / {r[1]:.3f}")
    print("| with memory: the three parts at lags 0, 1, 2 samples (80 ms) + order-2 C_N | " + " | ".join(cells) + " |")
    munk = lambda sel: flat(speed2 * np.sin(2 * aoa), sel)
    r = fit([comp(trans, 4), comp(rot, 4), comp(am, 4), munk], 4)
    print(f"\nM_z with a pitching moment ∝ |v|² sin 2AoA added (the steady added-mass, Munk, form): "
          f"r {r[0]:.3f} / {r[1]:.3f}; with k·F_x added (the moment's reference point moved along the "
          f"chord): r {fit([comp(trans, 4), comp(rot, 4), comp(am, 4), comp(y, 0)], 4)[0]:.3f} / "
          f"{fit([comp(trans, 4), comp(rot, 4), comp(am, 4), comp(y, 0)], 4)[1]:.3f}.\n")

    print("#### Where the normal force vanishes\n")
    fast = flat(u[..., 1], train) > np.percentile(flat(u[..., 1], train), 60)
    a = np.degrees(flat(aoa, train))[fast]
    v2 = flat(speed2, train)[fast]
    edges = np.arange(-30, 31, 5)
    centre = 0.5 * (edges[1:] + edges[:-1])

    def crossing(f):
        g = f[fast] / v2
        m = np.array([g[(a >= lo) & (a < hi)].mean() for lo, hi in zip(edges[:-1], edges[1:])])
        k = np.nonzero(np.diff(np.sign(m)) > 0)[0][0]
        return centre[k] - m[k] * (centre[k + 1] - centre[k]) / (m[k + 1] - m[k])

    print("F_x/|v|² averaged in 5° bins of AoA (the fastest 40 % of the training samples) crosses "
          f"zero at AoA {crossing(flat(ref, train)[:, 0]):+.1f}° in the stand-in and "
          f"{crossing(flat(y, train)[:, 0]):+.1f}° in L0 (the plate aligned).\n")

    print("#### What the stand-in's chordwise channels follow (r, train / test)\n")
    print("| series | stand-in F_y | stand-in M_x |")
    print("|---|---|---|")
    series = [
        ("L0's F_y (its own chordwise force)", y[..., 1]),
        ("L0's M_x", y[..., 2]),
        ("L0's F_x (the normal force)", y[..., 0]),
        ("the plate's static load after the tare, F_y", static[..., 1]),
        ("the plate's static load after the tare, M_x", static[..., 2]),
        ("the plate's inertial load, F_y", inertial[..., 1]),
        ("the plate's inertial load, M_x", inertial[..., 2]),
    ]
    for label, s in series:
        cells = []
        for k in (1, 2):
            r = [np.corrcoef(flat(s, sel), flat(ref, sel)[:, k])[0, 1] for sel in (train, ~train)]
            cells.append(f"{r[0]:+.3f} / {r[1]:+.3f}")
        print(f"| {label} | " + " | ".join(cells) + " |")
    cells = []
    for k in (1, 2):
        cols = [basis(y[..., c]) for c in range(5)] + [basis(u[..., c]) for c in range(7)]
        r = fit(cols, k)
        cells.append(f"{r[0]:.3f} / {r[1]:.3f}")
    print("| best linear mix of L0's five loads and the seven inputs (fitted) | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
