"""Estimators in scikit-learn's idiom: ``fit(X, y)`` / ``predict(X)``, ``get_params`` /
``set_params`` (so ``sklearn.base.clone`` works), fitted attributes ending in ``_``, inputs
validated. ``X``: inputs ``(n, T, 7)`` (see :mod:`flapssm`), ``y``: loads ``(n, T, 5)``; both
estimators also need the Euler angles for U_ref and the quasi-steady features, given as
``euler_rad`` ``(n, T, 3)`` to ``fit`` / ``predict`` (or a :class:`flapssm.Dataset` as ``X``).
"""

from __future__ import annotations

import inspect
import os
import tempfile
from typing import Any, Optional

import numpy as np

import flapssm
from ._arrays import as_float_array


class _Params:
    """``get_params`` / ``set_params`` from the constructor's keyword arguments."""

    @classmethod
    def _param_names(cls) -> list:
        sig = inspect.signature(cls.__init__)
        return [p for p in sig.parameters if p != "self"]

    def get_params(self, deep: bool = True) -> dict:
        return {k: getattr(self, k) for k in self._param_names()}

    def set_params(self, **params: Any) -> "_Params":
        names = self._param_names()
        for k, v in params.items():
            if k not in names:
                raise ValueError(f"invalid parameter {k!r} for {type(self).__name__}; valid: {names}")
            setattr(self, k, v)
        return self

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"

    def _check_fitted(self, attr: str) -> None:
        if not hasattr(self, attr):
            raise ValueError(f"this {type(self).__name__} is not fitted yet: call fit first")


def _dataset(X: Any, y: Any, euler_rad: Any, dt_s: float, n_train: Optional[int] = None) -> "flapssm.Dataset":
    if isinstance(X, flapssm.Dataset):
        return X
    if euler_rad is None:
        raise ValueError("euler_rad (n, T, 3) is needed with array inputs (or pass a flapssm.Dataset as X)")
    return flapssm.dataset_from_arrays(euler_rad, X, y, n_train=n_train, dt_s=dt_s)


class LRQSMRegressor(_Params):
    """The LRQSM baseline: elastic net on the quasi-steady features, λ by K-fold CV.

    Fitted attributes: ``model_`` (:class:`flapssm.LRQSM`), ``coef_`` ``(5, n_features)``,
    ``intercept_`` ``(5,)``, ``lambda_`` ``(5,)``."""

    def __init__(self, features: str = "published", l1_ratio: Optional[float] = None,
                 n_folds: Optional[int] = None, dt_s: float = 0.04) -> None:
        self.features = features
        self.l1_ratio = l1_ratio
        self.n_folds = n_folds
        self.dt_s = dt_s

    def fit(self, X: Any, y: Any = None, euler_rad: Any = None) -> "LRQSMRegressor":
        ds = _dataset(X, y, euler_rad, self.dt_s)
        self.model_ = flapssm.LRQSM.fit(ds, self.features, self.l1_ratio, self.n_folds)
        self.coef_ = self.model_.coef_
        self.intercept_ = self.model_.intercept_
        self.lambda_ = self.model_.lambda_
        return self

    def predict(self, X: Any, euler_rad: Any = None) -> np.ndarray:
        """Loads ``(n, T, 5)`` (N, N·mm)."""
        self._check_fitted("model_")
        return self.model_.predict(_dataset(X, None, euler_rad, self.dt_s, n_train=0))


class PRSSMRegressor(_Params):
    """The PR-SSM, trained by :func:`flapssm.train` with the CLI's presets and options.

    ``predict`` returns the mean loads ``(n, T, 5)``; ``predict(..., return_std=True)`` also
    their standard deviations. Fitted attributes: ``model_`` (:class:`flapssm.PRSSM`),
    ``n_state_``. Model files go to ``model_path`` (default: a temporary directory)."""

    def __init__(self, preset: str = "paper", dx: Optional[int] = None, inducing: Optional[int] = None,
                 particles: Optional[int] = None, epochs: Optional[int] = None,
                 iterations: Optional[int] = None, batch: Optional[int] = None, lr: Optional[float] = None,
                 seed: int = 0, val_fraction: float = 0.1, predict_particles: int = 30,
                 model_path: Optional[str] = None, dt_s: float = 0.04) -> None:
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
        self.model_path = model_path
        self.dt_s = dt_s

    def fit(self, X: Any, y: Any = None, euler_rad: Any = None, progress: Any = None) -> "PRSSMRegressor":
        ds = _dataset(X, y, euler_rad, self.dt_s)
        path = self.model_path
        if path is None:
            self._tmp = tempfile.TemporaryDirectory(prefix="flapssm-")
            path = os.path.join(self._tmp.name, "prssm.json")
        self.model_ = flapssm.train(
            ds, path, self.preset, dx=self.dx, inducing=self.inducing, particles=self.particles,
            epochs=self.epochs, iterations=self.iterations, batch=self.batch, lr=self.lr,
            seed=self.seed, val_fraction=self.val_fraction, progress=progress,
        )
        self.n_state_ = self.model_.n_state
        return self

    def predict(self, X: Any, euler_rad: Any = None, return_std: bool = False) -> Any:
        self._check_fitted("model_")
        ds = _dataset(X, None, euler_rad, self.dt_s, n_train=0)
        mean, var, _ = self.model_.predict_dataset(ds, self.predict_particles, self.seed)
        return (mean, np.sqrt(var)) if return_std else mean
