"""Prediction through Python against the Rust bench (issue: within 5 %).

    python crates/python/bench/overhead.py [path/to/flapssm]

Times `PRSSM.predict_inputs` of one 470-step trajectory with 30 particles (the published
model, D_x 12, M 100; median of 21 runs) and runs `flapssm bench --batches 1 --reps 21`,
whose prediction line times the same computation in Rust on a model of the same size; five
alternating rounds, the fastest of each reported (the least disturbed by other load on a
shared machine).
"""

import pathlib
import re
import subprocess
import sys
import time

import numpy as np

import flapssm

repo = pathlib.Path(__file__).resolve().parents[3]
exe = sys.argv[1] if len(sys.argv) > 1 else str(repo / "target" / "release" / "flapssm")
ref = repo.parent / "shared" / "reference" / "bayiz2021-prssm" / "reference.npz"

model = flapssm.PRSSM.import_published(ref)
u = np.load(ref)["u_in"]


def python_median_ms() -> float:
    times = []
    for r in range(21):
        t0 = time.perf_counter()
        model.predict_inputs(u, particles=30, seed=r)
        times.append(time.perf_counter() - t0)
    return 1e3 * sorted(times)[len(times) // 2]


def rust_median_ms() -> float:
    out = subprocess.run([exe, "bench", "--batches", "1", "--reps", "21"], check=True,
                         capture_output=True, text=True).stdout
    match = re.search(r"prediction \(470 steps x 30 particles, 1 thread\): ([0-9.]+) ms", out)
    if not match:
        sys.exit(f"no prediction line in the bench output:\n{out}")
    return float(match.group(1))


rounds = [(python_median_ms(), rust_median_ms()) for _ in range(5)]
python_ms = min(p for p, _ in rounds)
rust_ms = min(r for _, r in rounds)
print("rounds (Python, Rust) ms:", ", ".join(f"({p:.2f}, {r:.2f})" for p, r in rounds))
print(f"prediction of 470 steps x 30 particles: Python {python_ms:.3f} ms, Rust bench {rust_ms:.3f} ms, "
      f"ratio {python_ms / rust_ms:.3f}")
