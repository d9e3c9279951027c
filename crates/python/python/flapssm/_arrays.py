"""Input validation of arrays: float64, C-contiguous, the expected shape, finite."""

from __future__ import annotations

from typing import Any, Optional, Sequence

import numpy as np


def as_float_array(name: str, value: Any, shape: Sequence[Optional[int]]) -> np.ndarray:
    """``value`` as a C-contiguous float64 array of ``shape`` (None: any length).

    Raises ``TypeError`` for a non-real dtype (strings, objects, complex) and ``ValueError``
    for another shape or a non-finite value, naming ``name`` and the expected shape."""
    arr = np.asarray(value)
    if arr.dtype.kind not in "fiub":
        raise TypeError(f"{name}: dtype {arr.dtype}, expected real numbers (float64)")
    expected = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
    if arr.ndim != len(shape) or any(s is not None and a != s for a, s in zip(arr.shape, shape)):
        raise ValueError(f"{name}: shape {arr.shape}, expected {expected}")
    arr = np.ascontiguousarray(arr, dtype=np.float64)
    if not np.isfinite(arr).all():
        bad = np.argwhere(~np.isfinite(arr))[0]
        raise ValueError(f"{name}: non-finite value at index {tuple(int(i) for i in bad)}")
    return arr
