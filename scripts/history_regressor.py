"""How much of a wing dataset's loads a flexible regressor learns from the inputs' history.

Issue 27's measure of learnable memory. A regressor is fitted on the training trajectories of a
flapssm dataset (``.npz`` of ``flapssm simulate``), from sample 93 on (the published evaluation
window), once on the instantaneous inputs u_t, once on u_t plus u at ``--lags`` steps back and,
with ``--ewma``, on u_t plus exponentially weighted moving averages of u (causal, time constants
in samples: a compact summary of a fading memory longer than the lags reach), with and without
the lags. The regressor is gradient-boosted trees (scikit-learn ``HistGradientBoostingRegressor``,
one per output; the default) or, with ``--model mlp``, one multi-output neural network
(``MLPRegressor``, two hidden layers of 256 units). Printed: RMSE on held-out trajectories in
standard deviations of each output (training statistics), and on the fitted set below it.
The held-out trajectories are the dataset's test set, or with ``--holdout N`` the last N of its
training trajectories (fitting on the others): the paper's 36 test trajectories are chosen shapes
(figure-eights, U-shapes, flat and oval strokes), so only a hold-out from the training set measures
what is learnable within one distribution of trajectories.
If history helps little, what the static model misses is not memory the inputs determine.

    python scripts/history_regressor.py DATA.npz [--lags 2:40:2] [--ewma 4,8,16,32,64,128]
        [--holdout 51] [--model trees|mlp] [--iterations N] [--seed 0]

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


def taus_from(text):
    try:
        taus = [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"--ewma {text}: need comma-separated numbers")
    if not taus or min(taus) <= 0:
        raise argparse.ArgumentTypeError(f"--ewma {text}: time constants must be > 0 samples")
    return taus


def ewma(u, tau):
    """e_t = a·e_{t-1} + (1 - a)·u_t with a = exp(-1/tau), e_0 = u_0, along axis 1 of (N, T, 7)."""
    a = np.exp(-1.0 / tau)
    e = np.empty_like(u)
    e[:, 0] = u[:, 0]
    for t in range(1, u.shape[1]):
        e[:, t] = a * e[:, t - 1] + (1.0 - a) * u[:, t]
    return e


def features(u, lags, taus=()):
    """Rows [u_t, u_{t-l} for l in lags, EWMA_tau(u)_t for tau in taus] for t >= START of every
    trajectory: (T·N, 7·(1 + L + len(taus)))."""
    n_traj, n_t, n_u = u.shape
    if max(lags, default=0) > START:
        sys.exit(f"error: the largest lag ({max(lags)}) reaches before sample 0")
    cols = [u[:, START:, :]] + [u[:, START - lag : n_t - lag, :] for lag in lags]
    cols += [ewma(u, tau)[:, START:, :] for tau in taus]
    return np.concatenate(cols, axis=2).reshape(-1, n_u * len(cols))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("dataset")
    p.add_argument("--lags", type=lags_from, default=lags_from("2:40:2"))
    p.add_argument("--ewma", type=taus_from, default=None)
    p.add_argument("--holdout", type=int, default=None, metavar="N")
    p.add_argument("--model", choices=("trees", "mlp"), default="trees")
    p.add_argument("--iterations", type=int, default=None, help="tree iterations (300) or MLP epochs (60)")
    p.add_argument("--seed", type=int, default=0)
    a = p.parse_args()
    if a.iterations is None:
        a.iterations = 300 if a.model == "trees" else 60
    try:
        d = np.load(a.dataset, allow_pickle=False)
        u, y, train = d["u"], d["y"], d["is_train"]
        names = list(d["output_names"])
    except (OSError, KeyError, ValueError) as e:
        sys.exit(f"error: {a.dataset}: {e}")
    if u.ndim != 3 or u.shape[1] <= START or y.shape[:2] != u.shape[:2]:
        sys.exit(f"error: {a.dataset}: u {u.shape} and y {y.shape} need more than {START} samples per trajectory")
    if a.holdout is not None:
        idx = np.flatnonzero(train)
        if not 0 < a.holdout < len(idx):
            sys.exit(f"error: --holdout {a.holdout}: need 0 < N < {len(idx)} training trajectories")
        held = np.zeros_like(train)
        held[idx[-a.holdout :]] = True
        train = train & ~held
        test = held
    else:
        test = ~train
    y_rows = {s: y[m][:, START:, :].reshape(-1, y.shape[2]) for s, m in (("train", train), ("test", test))}
    sd = y_rows["train"].std(axis=0)
    held_out = "held out of the training set" if a.holdout is not None else "test"
    print(f"{a.dataset}: {train.sum()} fitted / {test.sum()} {held_out} trajectories, samples {START}..")
    print(f"{'inputs':<22}" + "".join(f"{n:>8}" for n in names) + "    time")
    sets = [("u_t", [], ()), (f"u_t + {len(a.lags)} lags", a.lags, ())]
    if a.ewma:
        k = len(a.ewma)
        sets += [(f"u_t + {k} EWMA", [], a.ewma), (f"u_t + lags + {k} EWMA", a.lags, a.ewma)]
    fit = fit_trees if a.model == "trees" else fit_mlp
    for label, lags, taus in sets:
        x = {s: features(u[m], lags, taus) for s, m in (("train", train), ("test", test))}
        t0 = time.perf_counter()
        predict = fit(x["train"], y_rows["train"] / sd, a)
        rmse = {s: np.sqrt(np.mean((predict(x[s]) - y_rows[s] / sd) ** 2, axis=0)) for s in x}
        print(f"{label:<22}" + "".join(f"{r:8.3f}" for r in rmse["test"]) + f"  {time.perf_counter() - t0:5.0f} s")
        print(f"{'  (fitted set)':<22}" + "".join(f"{r:8.3f}" for r in rmse["train"]))


def fit_trees(x, y, a):
    """One HistGradientBoostingRegressor per output; returns the (rows, outputs) predictor."""
    from sklearn.ensemble import HistGradientBoostingRegressor

    models = [HistGradientBoostingRegressor(max_iter=a.iterations, random_state=a.seed).fit(x, y[:, k]) for k in range(y.shape[1])]
    return lambda x: np.stack([m.predict(x) for m in models], axis=1)


def fit_mlp(x, y, a):
    """One multi-output MLP (two hidden layers of 256 ReLU units, Adam, minibatches of 512, at
    most ``--iterations`` epochs, stopped early on a random 10 % of the fitted rows) on
    standardized features and outputs; returns the (rows, outputs) predictor."""
    from sklearn.neural_network import MLPRegressor
    from sklearn.preprocessing import StandardScaler

    scale = StandardScaler().fit(x)
    mean = y.mean(axis=0)
    model = MLPRegressor(
        hidden_layer_sizes=(256, 256),
        batch_size=512,
        learning_rate_init=1e-3,
        max_iter=a.iterations,
        early_stopping=True,
        n_iter_no_change=8,
        random_state=a.seed,
    ).fit(scale.transform(x), y - mean)
    return lambda x: model.predict(scale.transform(x)) + mean

if __name__ == "__main__":
    main()
