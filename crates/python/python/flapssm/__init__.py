"""flapssm from Python: compact probabilistic state-space models of flapping-wing aerodynamics.

numpy arrays in and out (float64). Shapes and units (wing frame, unit span distance):

- ``inputs``  ``(n, T, 7)``: AoA (rad), |v| (m/s), a_x a_y a_z (m/s²), pitch rate (rad/s),
  pitch acceleration (rad/s²) — :data:`INPUT_NAMES`, :data:`INPUT_UNITS`.
- ``outputs`` ``(n, T, 5)``: F_x F_y (N), M_x M_y M_z (N·mm) — :data:`OUTPUT_NAMES`.
- ``euler_rad`` ``(n, T, 3)``: stroke φ, deviation ψ, pitch α (rad).

The work runs in Rust (the ``flapssm-jobs`` application layer, as the ``flapssm`` CLI) with the
GIL released; errors are ``ValueError`` (bad values, shapes, files of the wrong content),
``TypeError`` (dtypes), ``FileNotFoundError`` / ``OSError`` (files) and ``KeyboardInterrupt``
(Ctrl-C during training, after a checkpoint), carrying the CLI's messages.
"""

from __future__ import annotations

import json
import os
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np

from . import _native
from ._native import INPUT_NAMES, INPUT_UNITS, OUTPUT_NAMES, OUTPUT_UNITS, TRAINING_OPTIONS, Stream
from ._arrays import as_float_array

__all__ = [
    "INPUT_NAMES",
    "INPUT_UNITS",
    "OUTPUT_NAMES",
    "OUTPUT_UNITS",
    "TRAINING_OPTIONS",
    "Dataset",
    "dataset_from_arrays",
    "LRQSM",
    "PRSSM",
    "Stream",
    "simulate",
    "simulate_angles",
    "paper_angles",
    "trajectories",
    "kinematics",
    "sysid",
    "train",
    "evaluate",
    "history_curve",
    "rig_check",
    "rig_template",
    "load_rig",
    "build_dataset",
    "rehearse_rig",
    "STROKE_QUANTITIES",
    "design_target",
    "design_hover",
    "design_control",
    "LRQSMRegressor",
    "PRSSMRegressor",
]

PathLike = Union[str, "os.PathLike[str]"]
Progress = Callable[[str, int, int], Any]

Dataset = _native.Dataset
LRQSM = _native.Lrqsm
PRSSM = _native.Prssm


RigLike = Union[str, "os.PathLike[str]", dict]


def _rig_args(rig: RigLike) -> tuple:
    """(path, json) of a rig description given as a file path or a dict."""
    if isinstance(rig, dict):
        return None, json.dumps(rig)
    if isinstance(rig, (str, os.PathLike)):
        return os.fspath(rig), None
    raise TypeError(f"rig: a rig description file (str or os.PathLike) or a dict, got {type(rig).__name__}")


def dataset_from_arrays(
    euler_rad: Any,
    inputs: Any,
    outputs: Any = None,
    n_train: Optional[int] = None,
    dt_s: float = 0.04,
    u_ref_m_s: Any = None,
    rig: Optional[RigLike] = None,
) -> "_native.Dataset":
    """A dataset from arrays: ``euler_rad`` ``(n, T, 3)``, ``inputs`` ``(n, T, 7)``,
    ``outputs`` ``(n, T, 5)`` or None, the first ``n_train`` (default all) for training,
    sampling period ``dt_s`` (s; the paper's 25 Hz: 0.04), ``u_ref_m_s`` ``(n,)`` (default:
    the published rule at the wing's U_ref radius from the stroke and deviation angles).

    ``rig``: the rig description (a TOML file or a dict, docs/own-rig.md) whose wing, fluid and
    U_ref radius the dataset takes — they set U_ref and every coefficient. ``"paper"`` takes the
    paper's wing in its oil; None does too, with a ``UserWarning`` that says so."""
    e = as_float_array("euler_rad", euler_rad, (None, None, 3))
    n, t = e.shape[0], e.shape[1]
    u = as_float_array("inputs", inputs, (n, t, 7))
    y = None if outputs is None else as_float_array("outputs", outputs, (n, t, 5))
    r = None if u_ref_m_s is None else as_float_array("u_ref_m_s", u_ref_m_s, (n,))
    path = rig_json = None
    if rig is None:
        import warnings

        warnings.warn(
            "dataset_from_arrays: no rig given, so the paper's wing is assumed (0.18 x 0.06 m, "
            "U_ref at 0.235 m, oil of 800 kg/m^3) for U_ref and the coefficients; pass rig= "
            "your rig's description, or rig='paper' to say so",
            UserWarning,
            stacklevel=2,
        )
    elif not (isinstance(rig, str) and rig == "paper"):
        path, rig_json = _rig_args(rig)
    return _native.Dataset.from_arrays(e, u, y, n if n_train is None else int(n_train), float(dt_s), r,
                                       path, rig_json)


def rig_template() -> str:
    """A documented rig description (TOML) to start from, as ``flapssm dataset rig-template``
    writes it."""
    return _native.rig_template()


def load_rig(rig: RigLike) -> dict:
    """The rig description ``rig`` (a TOML file or a dict), checked field by field (a bad or
    unknown field raises ``ValueError`` naming it), as a dict with every default filled in."""
    path, rig_json = _rig_args(rig)
    return json.loads(_native.load_rig_description(path, rig_json))


def build_dataset(
    rig: RigLike,
    recordings: Sequence[PathLike],
    n_train: Optional[int] = None,
    steps: Optional[PathLike] = None,
    progress: Optional[Progress] = None,
) -> "_native.Dataset":
    """A dataset from a rig's raw recordings (``flapssm dataset build``; CSV, text or MAT
    v4/v5/v7.3 files with the rig's angle and sensor columns), processed as the rig description
    ``rig`` says: tare, sensor frame, subtraction of gravity, buoyancy and inertia, low-pass,
    resampling and cutting. The dataset has the rig's wing and fluid; each recording's report
    (tare offset, motion at rest, residual at rest) is in its metadata under
    ``settings.recordings``. ``steps``: a directory for each recording's processing steps (CSV
    and figure)."""
    path, rig_json = _rig_args(rig)
    files = [os.fspath(f) for f in recordings]
    ds, _ = _native.build_dataset(files, path, rig_json, n_train,
                                  None if steps is None else os.fspath(steps), progress)
    return ds


def rehearse_rig(
    rig: RigLike,
    directory: PathLike,
    n: int = 10,
    seed: int = 0,
    fidelity: Optional[str] = None,
    motion_s: float = 16.0,
    n_train: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> "_native.Dataset":
    """The virtual wing as the rig ``rig`` (``flapssm simulate --rig``): writes the raw recordings
    the rig would make of ``n`` generated motions of ``motion_s`` seconds into ``directory``
    (``recording_000.csv``, …) and returns the wing's own loads on them, the answer
    :func:`build_dataset` should recover. ``fidelity`` as in :func:`simulate` (default ``l0``)."""
    path, rig_json = _rig_args(rig)
    return _native.rehearse_rig(os.fspath(directory), path, rig_json, int(n), int(seed), fidelity,
                                float(motion_s), n_train, progress)


def _wing_json(wing: Optional[dict]) -> Optional[str]:
    return None if wing is None else json.dumps(wing)


def simulate(
    n: int = 548,
    seed: int = 0,
    fidelity: Optional[str] = None,
    n_train: Optional[int] = None,
    noise_free: bool = False,
    flat: bool = False,
    progress: Optional[Progress] = None,
    wing: Optional[dict] = None,
) -> "_native.Dataset":
    """Simulates the virtual wing on ``n`` generated trajectories (``flapssm simulate``):
    the same seed gives the same dataset as the CLI. ``fidelity``: ``l0`` quasi-steady,
    ``l1`` unsteady low-order, ``l2`` vortex strips, ``l3`` vortex lattice (default: the
    wing's). ``wing``: a dict of wing settings over the default wing, as the JSON file of
    ``flapssm simulate --wing-config`` (an unknown field raises ``ValueError``).
    ``progress(stage, position, total)``."""
    return _native.simulate(int(n), int(seed), fidelity, _wing_json(wing), n_train, noise_free, flat, progress)


def simulate_angles(
    euler_rad: Any,
    seed: int = 0,
    fidelity: Optional[str] = None,
    n_train: Optional[int] = None,
    noise_free: bool = False,
    progress: Optional[Progress] = None,
    wing: Optional[dict] = None,
) -> "_native.Dataset":
    """Simulates the virtual wing on given Euler angles ``(n, 470, 3)`` [φ, ψ, α] (rad) at
    25 Hz — for example the paper's 548 measured trajectories (:func:`paper_angles`): rates and
    accelerations by a Savitzky–Golay fit, quintic Hermite interpolation to the wing's 250 Hz,
    then the aerodynamics and the sensor chain as in :func:`simulate` (``fidelity`` and ``wing``
    likewise)."""
    e = as_float_array("euler_rad", euler_rad, (None, 470, 3))
    return _native.simulate_angles(e, int(seed), fidelity, _wing_json(wing), n_train, noise_free, progress)


def paper_angles(n: Optional[int] = None) -> np.ndarray:
    """The paper's measured trajectories (Bayiz & Cheng 2021; the first ``n``, default all 548,
    the last 36 being the paper's test set) as Euler angles ``(n, 470, 3)`` [φ, ψ, α] (rad) at
    25 Hz in flapssm's convention — the file's deviation and pitch negated (docs/kinematics.md).
    ``simulate_angles(paper_angles())`` drives the virtual wing with them."""
    return _native.paper_angles(n)


def trajectories(n: int = 548, seed: int = 0, n_train: Optional[int] = None) -> "_native.Dataset":
    """Random wing trajectories (``flapssm trajectories``): a kinematics-only dataset
    (``outputs`` is None), identical to the CLI's for the same seed."""
    return _native.trajectories(int(n), int(seed), n_train)


def kinematics(euler_rad: Any, dt_s: float, half_window: Optional[int] = None,
               order: Optional[int] = None) -> np.ndarray:
    """The wing-frame inputs ``(T, 7)`` of measured Euler angles ``(T, 3)`` [φ, ψ, α] (rad)
    sampled every ``dt_s`` (s): Savitzky–Golay derivatives (window ``2·half_window + 1``
    samples, default spanning 0.48 s; degree ``order``, default 6), then the kinematics at
    unit span distance. Samples within a half window of either end are extrapolated by the
    edge polynomials."""
    e = as_float_array("euler_rad", euler_rad, (None, 3))
    return _native.kinematics(e, float(dt_s), half_window, order)


def sysid(
    path: PathLike,
    inputs: Sequence[Union[str, int]],
    outputs: Sequence[Union[str, int]],
    split: float = 0.5,
    seeds: int = 3,
    restarts: int = 2,
    combine: str = "ensemble",
    iterations: int = 3000,
    lr: float = 0.1,
    progress: Optional[Callable[[int, float], Any]] = None,
) -> dict:
    """The system-identification protocol on a recorded file (CSV, whitespace table or MAT;
    ``flapssm sysid --json``): columns by name or 0-based index; returns the report as a dict
    (test RMSE and NLL over seeds, per-seed runs). ``progress(seed, test_rmse)``."""
    text = _native.sysid(os.fspath(path), list(inputs), list(outputs), float(split), int(seeds),
                         int(restarts), combine, int(iterations), float(lr), progress)
    return json.loads(text)


def train(
    dataset: "_native.Dataset",
    out: Optional[PathLike] = None,
    preset: str = "paper",
    *,
    dx: Optional[int] = None,
    inducing: Optional[int] = None,
    particles: Optional[int] = None,
    epochs: Optional[int] = None,
    iterations: Optional[int] = None,
    batch: Optional[int] = None,
    lr: Optional[float] = None,
    schedule: Optional[str] = None,
    eval_every: Optional[int] = None,
    seed: int = 0,
    val_fraction: float = 0.1,
    checkpoint_every: int = 10,
    resume: bool = False,
    progress: Optional[Progress] = None,
    best_by: str = "rmse",
    objective: str = "standard",
    inducing_init: Optional[str] = None,
    patience: Optional[int] = None,
    precision: Optional[str] = None,
    windows_per_task: Optional[int] = None,
    lengthscale_init: Optional[float] = None,
) -> "_native.Prssm":
    """Trains a PR-SSM (``flapssm train``) on the dataset's training trajectories; writes
    the best model to ``out``, the last to ``<out>.last.json``, checkpoints to
    ``<out>.ckpt.json`` and the learning curve to ``<out>.curve.csv``. Ctrl-C raises
    ``KeyboardInterrupt`` after a checkpoint; ``resume=True`` continues from it (a larger
    budget extends a finished run). With ``out=None`` nothing is written and the best model
    is returned from memory (an interruption then loses the run).

    The training keywords are ``flapssm train``'s flags with ``_`` for ``-``, one schema
    (``TRAINING_OPTIONS``), and take the values the command line does; ``None`` keeps the
    preset's. ``schedule``: ``"constant"``, ``"step:EVERY:FACTOR"``, ``"exp:FINAL"`` or
    ``"cosine:FINAL"``. ``eval_every``: evaluate (best-model tracking) every that many
    epochs. ``best_by``: ``"rmse"`` (validation, else training
    rollouts) or ``"training-loss"`` (the published code's ``best.ckpt``; with
    ``val_fraction=0``, the published protocol). ``objective``:
    ``"standard"`` (the unbiased ELBO) or ``"published-code"`` (the authors' objective and
    shared noise draws, to re-run their exact training). ``inducing_init``: ``"uniform"``
    or ``"kmeans"``. ``patience``: end when that many evaluated
    epochs in a row bring no new best model. ``precision``: ``"f64"`` (the reference) or
    ``"mixed"`` (the ELBO's large products in f32). ``windows_per_task``:
    sequences per parallel task (a minibatch of ``batch`` keeps at most
    ``batch / n`` threads busy; results change only in the last bits). ``lengthscale_init``:
    the initial lengthscale of every GP input in standardized units.
    Presets: ``"paper"`` (the published run), ``"paper-fast"`` (the paper's model trained for
    time to quality), ``"sysid"`` (Doerr et al.)."""
    given = dict(locals())
    options = [
        (name, _option_text(given[name]))
        for name in TRAINING_OPTIONS
        if given[name] is not None
    ]
    return _native.train(
        dataset, None if out is None else os.fspath(out), options, bool(resume), progress
    )


def _option_text(value: Any) -> str:
    """A training option's value as the command line spells it."""
    if isinstance(value, bool):
        raise TypeError(f"a training option takes a number or a name, not {value!r}")
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    return str(value)


def evaluate(
    dataset: "_native.Dataset",
    out: PathLike,
    prssm: Optional["_native.Prssm"] = None,
    lrqsm: Optional["_native.Lrqsm"] = None,
    particles: int = 30,
    seed: int = 0,
    start_sample: int = 93,
    progress: Optional[Progress] = None,
    baselines: Sequence[str] = (),
) -> dict:
    """The paper's analyses (``flapssm evaluate``): RMSE per output, standardized-error 95 %
    intervals, half-stroke averages, control authority of the latent states, figures and
    ``report.html`` in ``out``; returns ``metrics.json`` as a dict. ``baselines``: keys of
    registered baselines fitted on the dataset's training trajectories (``"arx"``,
    ``"gp-static"``, ``"gp-history"``); the first model is compared with every other one by a
    paired bootstrap (``comparisons``)."""
    text = _native.evaluate(dataset, os.fspath(out), prssm, lrqsm, particles, seed, start_sample, progress,
                            list(baselines))
    return json.loads(text)


def history_curve(
    datasets: "dict[str, _native.Dataset]",
    out: PathLike,
    cycles: Optional[Sequence[float]] = None,
    start_sample: int = 93,
    seed: int = 0,
    progress: Optional[Progress] = None,
) -> dict:
    """The history curve (``flapssm history``): for each dataset (label → dataset), the GP
    baseline given 0 to one stroke cycle of input history (``cycles``, increasing from 0), its
    test RMSE per output and the paired difference against no history; writes
    ``history_curve.{json,csv,png}`` in ``out`` and returns the JSON as a dict."""
    text = _native.history_curve(list(datasets.items()), os.fspath(out),
                                 None if cycles is None else [float(c) for c in cycles],
                                 start_sample, seed, progress)
    return json.loads(text)


def rig_check(
    dataset: "_native.Dataset",
    reference: PathLike,
    out: Optional[PathLike] = None,
    particles: int = 30,
    seed: int = 1,
    lags: bool = True,
    progress: Optional[Progress] = None,
) -> dict:
    """The rig as the judge (``flapssm rig check``): ``dataset`` — the paper's trajectories
    0..n in the authors' order, for example ``simulate_angles(paper_angles(), noise_free=True)``
    — against the published model's prediction of the rig's loads (``reference``: its
    ``reference.npz`` or an imported model file), on the paper's 512 training and 36 test
    trajectories: per channel ``r``, ``z_rmse`` and ``band_share``, the couplings and (with
    ``lags``) the Fig. 5 lag statistics. With ``out``, writes ``rig-check.json``,
    ``rig-check.md`` and ``rig-examples.png`` there. Returns ``rig-check.json`` as a dict."""
    text = _native.rig_check(
        dataset, os.fspath(reference), None if out is None else os.fspath(out),
        int(particles), int(seed), bool(lags), progress,
    )
    return json.loads(text)


STROKE_QUANTITIES = (
    "thrust_n", "lift_n", "side_force_n", "roll_moment_n_mm", "yaw_moment_n_mm",
    "pitch_moment_n_mm", "power_w",
)
"""The stroke-frame quantities of a design, in order (docs/design.md has the frame)."""

_DESIGN_DEFAULTS = dict(
    harmonics=3, particles=16, starts=4, iterations=150, learning_rate=0.01,
    robust_weight=0.5, seed=0,
)


def _design_knobs(kwargs: dict) -> dict:
    unknown = set(kwargs) - set(_DESIGN_DEFAULTS)
    if unknown:
        raise TypeError(f"unknown design settings: {sorted(unknown)}; known: {sorted(_DESIGN_DEFAULTS)}")
    knobs = dict(_DESIGN_DEFAULTS)
    knobs.update(kwargs)
    return knobs


def design_target(
    prssm: PathLike,
    targets: dict,
    lrqsm: Optional[PathLike] = None,
    frequency_hz: Optional[float] = None,
    power_weight: float = 0.0,
    out: Optional[PathLike] = None,
    progress: Optional[Progress] = None,
    **settings,
) -> dict:
    """Kinematics whose cycle-mean stroke-frame loads meet ``targets`` (``flapssm design
    target``): a dict over the first six of :data:`STROKE_QUANTITIES` (N, N·mm), the others
    free, optionally at least power (``power_weight``). Designed with the PR-SSM file
    ``prssm``, the LRQSM file ``lrqsm`` when given and the quasi-steady wing, each verified on
    the default virtual wing. ``settings``: harmonics, particles, starts, iterations,
    learning_rate, robust_weight, seed. With ``out``, writes ``design.json`` and
    ``design.md``. Returns the report as a dict; a bad target raises ``ValueError`` naming
    it."""
    names = STROKE_QUANTITIES[:6]
    unknown = set(targets) - set(names)
    if unknown:
        raise ValueError(f"target: unknown quantities {sorted(unknown)}; known: {list(names)}")
    values = [None if targets.get(n) is None else float(targets[n]) for n in names]
    k = _design_knobs(settings)
    text = _native.design_target(
        os.fspath(prssm), values, None if lrqsm is None else os.fspath(lrqsm), frequency_hz,
        float(power_weight), None if out is None else os.fspath(out), k["harmonics"],
        k["particles"], k["starts"], k["iterations"], k["learning_rate"], k["robust_weight"],
        k["seed"], progress,
    )
    return json.loads(text)


def design_hover(
    prssm: PathLike,
    weight_n: float,
    lrqsm: Optional[PathLike] = None,
    frequency_hz: Optional[float] = None,
    power_weight: float = 0.05,
    out: Optional[PathLike] = None,
    progress: Optional[Progress] = None,
    **settings,
) -> dict:
    """Hover (``flapssm design hover``): mean lift equal to ``weight_n`` (N, carried by this
    wing), zero mean thrust and pitch moment, at least aerodynamic power; as
    :func:`design_target`."""
    weight = float(weight_n)
    if not (weight > 0 and weight != float("inf")):
        raise ValueError(f"setting weight_n = {weight_n}: finite and > 0 (N)")
    targets = {"lift_n": weight, "thrust_n": 0.0, "pitch_moment_n_mm": 0.0}
    return design_target(
        prssm, targets, lrqsm=lrqsm, frequency_hz=frequency_hz, power_weight=power_weight,
        out=out, progress=progress, **settings,
    )


def design_control(
    prssm: PathLike,
    lift_n: float,
    density_factor: float = 1.2,
    bias_fx_n: float = 0.0,
    cycles: int = 12,
    frequency_hz: Optional[float] = None,
    out: Optional[PathLike] = None,
    particles: int = 16,
    seed: int = 0,
    progress: Optional[Progress] = None,
) -> dict:
    """The closed loop (``flapssm design control``): a hover design for ``lift_n`` flown on
    the default wing in a fluid ``density_factor`` times as dense and with ``bias_fx_n`` (N)
    on its F_x channel — a mismatch the model has not seen — its stroke amplitude chosen cycle
    by cycle with the streaming PR-SSM. Returns the report (``cycles``: per cycle the stroke
    scale, the measured and predicted lift, the error in %) as a dict."""
    text = _native.design_control(
        os.fspath(prssm), float(lift_n), float(density_factor), float(bias_fx_n), int(cycles),
        frequency_hz, None if out is None else os.fspath(out), int(particles), int(seed),
        progress,
    )
    return json.loads(text)


from .estimators import LRQSMRegressor, PRSSMRegressor  # noqa: E402  (uses the names above)
