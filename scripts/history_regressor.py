"""How much of a wing dataset's loads a flexible regressor learns from the inputs' history.

The measure of learnable memory of docs/vortex-method.md. A regressor is fitted on the training trajectories of a
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
what is learnable within one distribution of trajectories. ``--fitted N`` fits on the first N of
the remaining training trajectories only (a learning curve), and ``--extra OTHER.npz`` adds every
trajectory of another dataset of the same wing (for example generated ones) to the fitted set,
so that a data limit can be told from content the inputs do not determine; RMSE stays in the
standard deviations of DATA's own fitted rows. Each history row also prints the share of the
u_t row's miss it explains, 1 - (RMSE / RMSE_u_t)^2, per output.
If history helps little, what the static model misses is not memory the inputs determine.

    python scripts/history_regressor.py DATA.npz [--lags 2:40:2] [--ewma 4,8,16,32,64,128]
        [--holdout 51] [--fitted N] [--extra OTHER.npz] [--sets u_t,lags,ewma,lags+ewma]
        [--model trees|mlp] [--iterations N] [--seed 0]

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


def sets_from(text):
    keys = text.split(",")
    if bad := [k for k in keys if k not in ("u_t", "lags", "ewma", "lags+ewma")]:
        raise argparse.ArgumentTypeError(f"--sets {','.join(bad)}: known sets are u_t, lags, ewma, lags+ewma")
    return keys


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
    p.add_argument("--sets", type=sets_from, default=None, help="input sets to fit (default: all that apply)")
    p.add_argument("--fitted", type=int, default=None, metavar="N")
    p.add_argument("--extra", default=None, metavar="OTHER.npz")
    p.add_argument("--model", choices=("trees", "mlp"), default="trees")
    p.add_argument("--iterations", type=int, default=None, help="tree iterations (300) or MLP epochs (60)")
    p.add_argument("--seed", type=int, default=0)
    a = p.parse_args()
    if a.iterations is None:
        a.iterations = 300 if a.model == "trees" else 60
    u, y, train, names = load(a.dataset)
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
    if a.fitted is not None:
        idx = np.flatnonzero(train)
        if not 0 < a.fitted <= len(idx):
            sys.exit(f"error: --fitted {a.fitted}: need 0 < N <= {len(idx)} fitted trajectories")
        train = np.zeros_like(train)
        train[idx[: a.fitted]] = True
    sd = y[train][:, START:, :].reshape(-1, y.shape[2]).std(axis=0)
    n_extra = 0
    if a.extra is not None:
        u_x, y_x, _, names_x = load(a.extra)
        if names_x != names or u_x.shape[1:] != u.shape[1:]:
            sys.exit(f"error: --extra {a.extra}: outputs {names_x}, u {u_x.shape} do not match {a.dataset}'s {names}, u {u.shape}")
        n_extra = len(u_x)
        u = np.concatenate([u, u_x])
        y = np.concatenate([y, y_x])
        train = np.concatenate([train, np.ones(n_extra, dtype=bool)])
        test = np.concatenate([test, np.zeros(n_extra, dtype=bool)])
    y_rows = {s: y[m][:, START:, :].reshape(-1, y.shape[2]) for s, m in (("train", train), ("test", test))}
    held_out = "held out of the training set" if a.holdout is not None else "test"
    extra = f" (of them {n_extra} from {a.extra})" if n_extra else ""
    print(f"{a.dataset}: {train.sum()} fitted{extra} / {test.sum()} {held_out} trajectories, samples {START}..")
    print(f"{'inputs':<22}" + "".join(f"{n:>8}" for n in names) + "    time")
    sets = {"u_t": ("u_t", [], ()), "lags": (f"u_t + {len(a.lags)} lags", a.lags, ())}
    if a.ewma:
        k = len(a.ewma)
        sets |= {"ewma": (f"u_t + {k} EWMA", [], a.ewma), "lags+ewma": (f"u_t + lags + {k} EWMA", a.lags, a.ewma)}
    if a.sets is not None:
        if missing := [k for k in a.sets if k not in sets]:
            sys.exit(f"error: --sets {','.join(missing)}: needs --ewma")
        sets = {k: sets[k] for k in a.sets}
    fit = fit_trees if a.model == "trees" else fit_mlp
    static = None
    for key, (label, lags, taus) in sets.items():
        x = {s: features(u[m], lags, taus) for s, m in (("train", train), ("test", test))}
        t0 = time.perf_counter()
        predict = fit(x["train"], y_rows["train"] / sd, a)
        rmse = {s: np.sqrt(np.mean((predict(x[s]) - y_rows[s] / sd) ** 2, axis=0)) for s in x}
        print(f"{label:<22}" + "".join(f"{r:8.3f}" for r in rmse["test"]) + f"  {time.perf_counter() - t0:5.0f} s")
        print(f"{'  (fitted set)':<22}" + "".join(f"{r:8.3f}" for r in rmse["train"]))
        if key == "u_t":
            static = rmse["test"]
        elif static is not None:
            print(f"{'  (share of u_t miss)':<22}" + "".join(f"{v:8.2f}" for v in 1 - (rmse["test"] / static) ** 2))


def load(path):
    """(u, y, is_train, output names) of a flapssm dataset, or exit naming the file."""
    try:
        d = np.load(path, allow_pickle=False)
        u, y, train = d["u"], d["y"], d["is_train"].astype(bool)
        names = [str(n) for n in d["output_names"]]
    except (OSError, KeyError, ValueError) as e:
        sys.exit(f"error: {path}: {e}")
    if u.ndim != 3 or u.shape[1] <= START or y.shape[:2] != u.shape[:2]:
        sys.exit(f"error: {path}: u {u.shape} and y {y.shape} need more than {START} samples per trajectory")
    return u, y, train, names


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
