"""flapssm from Python in under a minute: simulate the virtual wing, fit the LRQSM and a small
PR-SSM, predict a test trajectory with its ±2σ band, plot it, and run the paper's analyses
(control authority of the latent states included).

    python examples/python/quickstart.py [OUT_DIR]

Needs `pip install ./crates/python matplotlib`. Writes OUT_DIR/quickstart.png and the
evaluation (metrics.json, figures, report.html) under OUT_DIR/eval.
"""

import pathlib
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import flapssm  # noqa: E402

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "flapssm-quickstart")
out.mkdir(parents=True, exist_ok=True)
t0 = time.perf_counter()


done = set()


def progress(stage, position, total):
    if total and position == total and stage not in done:
        done.add(stage)
        print(f"  {stage}: done ({time.perf_counter() - t0:.1f} s)", flush=True)


# 1. Data: 24 trajectories of the unsteady low-order wing (L1), 20 for training.
ds = flapssm.simulate(24, seed=1, fidelity="l1", n_train=20, progress=progress)
print(ds)

# 2. The quasi-steady baseline.
lrqsm = flapssm.LRQSM.fit(ds)
print("LRQSM λ per output:", np.round(lrqsm.lambda_, 5))

# 3. A small PR-SSM (the paper's model has D_x 12, M 100, 30 particles, 1000 epochs).
model = flapssm.train(ds, out / "prssm.json", "paper", inducing=30, particles=10, batch=8,
                      epochs=250, seed=1, progress=progress)
print(model)

# 4. Predict the first test trajectory, as a batch and as a stream (the same numbers).
test = ds.n_train
u = ds.inputs[test]
mean, var, _, _ = model.predict_inputs(u, particles=30, seed=0)
stream = model.stream(particles=30, seed=0)
streamed = np.array([stream.step(u_t)[0] for u_t in u])
assert np.array_equal(streamed, mean)
qs = lrqsm.predict(ds)[test]

# 5. Plot F_x (N) with the PR-SSM's ±2σ band.
t = np.arange(ds.n_samples) * ds.dt_s
y = ds.outputs[test]
fig, axes = plt.subplots(2, 1, figsize=(9, 5), sharex=True)
for ax, k in zip(axes, [0, 1]):
    ax.plot(t, y[:, k], "k", lw=1, label="measured (virtual wing)")
    ax.plot(t, qs[:, k], "C1", lw=1, label="LRQSM")
    ax.plot(t, mean[:, k], "C0", lw=1, label="PR-SSM")
    sd = np.sqrt(var[:, k])
    ax.fill_between(t, mean[:, k] - 2 * sd, mean[:, k] + 2 * sd, color="C0", alpha=0.2, lw=0)
    ax.set_ylabel(f"{flapssm.OUTPUT_NAMES[k]} ({flapssm.OUTPUT_UNITS[k]})")
axes[0].legend(loc="upper right", fontsize=8)
axes[1].set_xlabel("time (s)")
fig.tight_layout()
fig.savefig(out / "quickstart.png", dpi=120)

# 6. The paper's analyses: RMSE, intervals, half-stroke averages, control authority.
report = flapssm.evaluate(ds, out / "eval", prssm=model, lrqsm=lrqsm, particles=30)
for m in report["models"]:
    print(f"{m['model']:7s} test RMSE (σ units):", np.round(m["test"]["rmse_standardized"], 3))
for finding in report["authority_findings"][:3]:
    print("authority:", finding)
print(f"done in {time.perf_counter() - t0:.1f} s; figure {out / 'quickstart.png'}")
