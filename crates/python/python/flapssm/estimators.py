"""Load models as scikit-learn estimators, with **trajectories as samples**.

``X`` is the wing's motion and ``y`` its loads, one row per trajectory:

- ``X``: Euler angles ``(n, T, 3)`` [stroke φ, deviation ψ, pitch α] in rad, sampled every
  ``dt_s`` (the paper's 25 Hz: 0.04 s), or the same flattened to ``(n, 3·T)`` (sample-major:
  φ₀ ψ₀ α₀ φ₁ …), or a :class:`flapssm.Dataset` (which also carries its own inputs);
- ``y``: loads ``(n, T, 5)`` [F_x, F_y (N), M_x, M_y, M_z (N·mm)], or flattened ``(n, 5·T)``.

The wing-frame inputs ``u`` (:data:`flapssm.INPUT_NAMES`) are computed from the angles by
:func:`flapssm.kinematics`, the same in ``fit`` and ``predict``. ``predict`` returns the loads in
``X``'s layout. Because the samples are trajectories, scikit-learn's tools split, resample and
cross-validate whole trajectories: ``cross_val_score(est, X, y, groups=g, cv=GroupKFold())``,
``GridSearchCV``, ``clone`` and ``Pipeline`` work as with any regressor.

With scikit-learn installed the estimators are built on its ``BaseEstimator`` and
``RegressorMixin`` (``get_params``, ``set_params``, ``clone``, tags); without it, on a small
stand-in with the same methods, so that ``import flapssm`` never needs scikit-learn.
"""

from __future__ import annotations

import inspect
from typing import Any, Optional

import numpy as np

import flapssm

try:  # scikit-learn is optional: its base classes when present.
    from sklearn.base import BaseEstimator, RegressorMixin

    _SKLEARN = True
except ImportError:  # pragma: no cover - exercised by the test without scikit-learn
    _SKLEARN = False

N_ANGLES = 3
N_LOADS = 5


class _Params:
    """``get_params`` / ``set_params`` / ``repr`` from the constructor's keyword arguments,
    as scikit-learn's ``BaseEstimator`` (used when scikit-learn is not installed)."""

    @classmethod
    def _get_param_names(cls) -> list:
        sig = inspect.signature(cls.__init__)
        return [p for p in sig.parameters if p != "self"]

    def get_params(self, deep: bool = True) -> dict:
        return {k: getattr(self, k) for k in self._get_param_names()}

    def set_params(self, **params: Any) -> "_Params":
        names = self._get_param_names()
        for k, v in params.items():
            if k not in names:
                raise ValueError(f"invalid parameter {k!r} for estimator {type(self).__name__}; valid: {names}")
            setattr(self, k, v)
        return self

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"


_BASES: tuple = (RegressorMixin, BaseEstimator) if _SKLEARN else (_Params,)


def _as_array(a: Any, name: str) -> np.ndarray:
    """float64 array; with scikit-learn, through its ``check_array`` (its messages for sparse,
    complex, object, empty and non-finite data)."""
    if _SKLEARN:
        from sklearn.utils.validation import check_array

        return check_array(a, dtype=np.float64, allow_nd=True, ensure_2d=False, input_name=name)
    return np.asarray(a, dtype=np.float64)


def _angles(X: Any) -> tuple:
    """``(euler_rad (n, T, 3), flat)`` from ``X`` in either layout, checked."""
    a = _as_array(X, "X")
    if a.ndim == 3 and a.shape[2] == N_ANGLES:
        out, flat = a, False
    elif a.ndim == 2 and a.shape[1] % N_ANGLES == 0 and a.shape[1] > 0:
        out, flat = a.reshape(a.shape[0], a.shape[1] // N_ANGLES, N_ANGLES), True
    else:
        raise ValueError(
            f"X: Euler angles (n_trajectories, n_samples, 3) in rad, or (n_trajectories, 3·n_samples) "
            f"flattened; got shape {a.shape}"
        )
    if out.shape[0] == 0 or out.shape[1] < 2:
        raise ValueError(f"X: at least one trajectory of at least 2 samples; got {out.shape[:2]}")
    if not np.isfinite(out).all():
        raise ValueError("X: the Euler angles hold NaN or infinity")
    return out, flat


def _loads(y: Any, n: int, t: int) -> np.ndarray:
    a = _as_array(y, "y")
    if a.shape == (n, t, N_LOADS):
        return a
    if a.shape == (n, t * N_LOADS):
        return a.reshape(n, t, N_LOADS)
    raise ValueError(
        f"y: loads (n_trajectories, n_samples, 5) = ({n}, {t}, 5), or ({n}, {5 * t}) flattened; got shape {a.shape}"
    )


def _dataset(est: Any, X: Any, y: Any = None, n_train: Optional[int] = None) -> tuple:
    """A :class:`flapssm.Dataset` of ``X`` (and ``y``), whether ``X`` was flattened, and its
    number of features (3 per sample; None for a Dataset)."""
    if isinstance(X, flapssm.Dataset):
        return X, False, None
    if y is None and n_train is None:
        raise ValueError(f"{type(est).__name__} requires y to be passed, but the target y is None")
    euler, flat = _angles(X)
    n, t = euler.shape[:2]
    u = np.stack([flapssm.kinematics(e, est.dt_s) for e in euler])
    loads = None if y is None else _loads(y, n, t)
    # The estimators score loads in their own units; the wing's geometry enters only U_ref and
    # the coefficients, which they do not use.
    ds = flapssm.dataset_from_arrays(euler, u, loads, n_train=n_train, dt_s=est.dt_s, rig="paper")
    return ds, flat, t * N_ANGLES


def _layout(loads: np.ndarray, flat: bool) -> np.ndarray:
    return loads.reshape(loads.shape[0], -1) if flat else loads


class _LoadRegressor(*_BASES):
    """What both estimators share: the data contract, ``score`` and the tags."""

    def _check_fitted(self) -> None:
        if not hasattr(self, "model_"):
            msg = f"this {type(self).__name__} instance is not fitted yet: call fit first"
            if _SKLEARN:
                from sklearn.exceptions import NotFittedError

                raise NotFittedError(msg)
            raise ValueError(msg)

    def _set_n_features(self, n_features: Optional[int]) -> None:
        if n_features is not None:
            self.n_features_in_ = n_features

    def score(self, X: Any, y: Any = None, sample_weight: Any = None) -> float:
        """R² of the predicted loads, the mean over the five channels, pooled over the
        trajectories' samples from ``start_sample`` on (the published evaluation window).
        ``y``: the loads (or, with a :class:`flapssm.Dataset` as ``X``, its own)."""
        pred = np.asarray(self.predict(X), dtype=np.float64)
        n = pred.shape[0]
        t = pred.size // (n * N_LOADS)
        if isinstance(X, flapssm.Dataset) and y is None:
            y = X.outputs
        true = _loads(y, n, t)[:, self.start_sample:, :].reshape(-1, N_LOADS)
        pred = pred.reshape(n, t, N_LOADS)[:, self.start_sample:, :].reshape(-1, N_LOADS)
        w = None
        if sample_weight is not None:
            w = np.repeat(np.asarray(sample_weight, dtype=np.float64), t - self.start_sample)
        mean = np.average(true, axis=0, weights=w)
        ss_res = np.average((true - pred) ** 2, axis=0, weights=w)
        ss_tot = np.average((true - mean) ** 2, axis=0, weights=w)
        return float(np.mean(1.0 - ss_res / np.where(ss_tot > 0, ss_tot, 1.0)))

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.three_d_array = True  # (n_trajectories, n_samples, 3) as well as 2-D
        tags.target_tags.multi_output = True  # five loads per sample
        tags.target_tags.single_output = False
        tags.regressor_tags.poor_score = True  # scikit-learn's random data are not a wing's motion
        return tags


class LRQSMRegressor(_LoadRegressor):
    """The LRQSM baseline (:class:`flapssm.LRQSM`): elastic net on the quasi-steady features,
    λ by K-fold cross-validation.

    Parameters: ``features`` (``"published"``: the paper's 11), ``l1_ratio`` (default the
    paper's 0.75), ``n_folds`` (default 10), ``dt_s`` (sampling period of ``X``, s),
    ``start_sample`` (``score``'s first sample). Fitted attributes: ``model_``, ``coef_``
    ``(5, n_features)``, ``intercept_`` ``(5,)``, ``lambda_`` ``(5,)``, ``n_features_in_``."""

    def __init__(self, features: str = "published", l1_ratio: Optional[float] = None,
                 n_folds: Optional[int] = None, dt_s: float = 0.04, start_sample: int = 93) -> None:
        self.features = features
        self.l1_ratio = l1_ratio
        self.n_folds = n_folds
        self.dt_s = dt_s
        self.start_sample = start_sample

    def fit(self, X: Any, y: Any = None) -> "LRQSMRegressor":
        ds, _, n_features = _dataset(self, X, y)
        self.model_ = flapssm.LRQSM.fit(ds, self.features, self.l1_ratio, self.n_folds)
        self.coef_ = self.model_.coef_
        self.intercept_ = self.model_.intercept_
        self.lambda_ = self.model_.lambda_
        self._set_n_features(n_features)
        return self

    def predict(self, X: Any) -> np.ndarray:
        """Loads (N, N·mm) in ``X``'s layout: ``(n, T, 5)`` or ``(n, 5·T)``."""
        self._check_fitted()
        ds, flat, _ = _dataset(self, X, n_train=0)
        return _layout(self.model_.predict(ds), flat)


class PRSSMRegressor(_LoadRegressor):
    """The PR-SSM (:func:`flapssm.train`) with the CLI's presets and options; trained in
    memory, nothing written.

    ``predict`` returns the mean loads; ``predict(X, return_std=True)`` also their standard
    deviations (N, N·mm), by ``predict_particles`` particles with seed ``seed``. Fitted
    attributes: ``model_`` (:class:`flapssm.PRSSM`), ``n_state_``, ``n_features_in_``."""

    def __init__(self, preset: str = "paper", dx: Optional[int] = None, inducing: Optional[int] = None,
                 particles: Optional[int] = None, epochs: Optional[int] = None,
                 iterations: Optional[int] = None, batch: Optional[int] = None, lr: Optional[float] = None,
                 seed: int = 0, val_fraction: float = 0.1, predict_particles: int = 30,
                 dt_s: float = 0.04, start_sample: int = 93) -> None:
        self.preset = preset
        self.dx = dx
        self.inducing = inducing
        self.particles = particles
        self.epochs = epochs
        self.iterations = iterations
        self.batch = batch
        self.lr = lr
        self.seed = seed
        self.val_fraction = val_fraction
        self.predict_particles = predict_particles
        self.dt_s = dt_s
        self.start_sample = start_sample

    def fit(self, X: Any, y: Any = None, progress: Any = None) -> "PRSSMRegressor":
        """``progress(stage, position, total)``, as :func:`flapssm.train`'s."""
        ds, _, n_features = _dataset(self, X, y)
        self.model_ = flapssm.train(
            ds, None, self.preset, dx=self.dx, inducing=self.inducing, particles=self.particles,
            epochs=self.epochs, iterations=self.iterations, batch=self.batch, lr=self.lr,
            seed=self.seed, val_fraction=self.val_fraction, progress=progress,
        )
        self.n_state_ = self.model_.n_state
        self._set_n_features(n_features)
        return self

    def predict(self, X: Any, return_std: bool = False) -> Any:
        self._check_fitted()
        ds, flat, _ = _dataset(self, X, n_train=0)
        mean, var, _ = self.model_.predict_dataset(ds, self.predict_particles, self.seed)
        mean = _layout(mean, flat)
        return (mean, _layout(np.sqrt(var), flat)) if return_std else mean
