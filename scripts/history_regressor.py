"""How much of a wing dataset's loads a flexible regressor learns from the inputs' history.

Issue 27's measure of learnable memory: gradient-boosted trees (scikit-learn
``HistGradientBoostingRegressor``) fitted once on the instantaneous inputs u_t and once on u_t
plus u at ``--lags`` steps back, per output, on the training trajectories of a flapssm dataset
(``.npz`` of ``flapssm simulate``), from sample 93 on (the published evaluation window); test
RMSE on the held-out trajectories in standard deviations of each output (training statistics).
If history helps little, what the static model misses is not memory the inputs determine.

    python scripts/history_regressor.py DATA.npz [--lags 2:40:2] [--iterations 300] [--seed 0]

Needs numpy and scikit-learn (a study, not part of the test suite).
"""

import argparse
import sys
import time

import numpy as np

START = 93


def lags_from(text):
    lo, hi, step = (int(v) for v in text.split(":"))
    if not (0 < lo <= hi and step > 0):
        raise argparse.ArgumentTypeError(f"--lags {text}: need 0 < first <= last and step > 0")
    return list(range(lo, hi + 1, step))


def features(u, lags):
    """Rows [u_t, u_{t-l} for l in lags] for t >= START of every trajectory: (T·N, 7·(1+L))."""
    n_traj, n_t, n_u = u.shape
    if max(lags, default=0) > START:
        sys.exit(f"error: the largest lag ({max(lags)}) reaches before sample 0")
    cols = [u[:, START:, :]] + [u[:, START - lag : n_t - lag, :] for lag in lags]
    return np.concatenate(cols, axis=2).reshape(-1, n_u * (1 + len(lags)))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("dataset")
    p.add_argument("--lags", type=lags_from, default=lags_from("2:40:2"))
    p.add_argument("--iterations", type=int, default=300)
    p.add_argument("--seed", type=int, default=0)
    a = p.parse_args()
    from sklearn.ensemble import HistGradientBoostingRegressor

    try:
        d = np.load(a.dataset, allow_pickle=False)
        u, y, train = d["u"], d["y"], d["is_train"]
        names = list(d["output_names"])
    except (OSError, KeyError, ValueError) as e:
        sys.exit(f"error: {a.dataset}: {e}")
    if u.ndim != 3 or u.shape[1] <= START or y.shape[:2] != u.shape[:2]:
        sys.exit(f"error: {a.dataset}: u {u.shape} and y {y.shape} need more than {START} samples per trajectory")
    y_rows = {s: y[m][:, START:, :].reshape(-1, y.shape[2]) for s, m in (("train", train), ("test", ~train))}
    sd = y_rows["train"].std(axis=0)
    print(f"{a.dataset}: {train.sum()} training / {(~train).sum()} test trajectories, samples {START}..")
    print(f"{'inputs':<22}" + "".join(f"{n:>8}" for n in names) + "    time")
    for label, lags in (("u_t", []), (f"u_t + {len(a.lags)} lags", a.lags)):
        x = {s: features(u[m], lags) for s, m in (("train", train), ("test", ~train))}
        t0 = time.perf_counter()
        rmse = []
        for k in range(y.shape[2]):
            model = HistGradientBoostingRegressor(max_iter=a.iterations, random_state=a.seed)
            model.fit(x["train"], y_rows["train"][:, k] / sd[k])
            err = model.predict(x["test"]) - y_rows["test"][:, k] / sd[k]
            rmse.append(float(np.sqrt(np.mean(err**2))))
        print(f"{label:<22}" + "".join(f"{r:8.3f}" for r in rmse) + f"  {time.perf_counter() - t0:5.0f} s")


if __name__ == "__main__":
    main()
