"""Validated ellipsoid parameters: semi-axes, inflation and guard semi-axes.

An ellipsoid ``E_a`` with semi-axes ``a`` (length units, e.g. metres) is the set
``{R diag(a) u + t : |u| <= 1}``. Its guard is the concentric ``E_b`` with
``b = (1 + inflation) * a`` (the paper's ``E_b = (1 + eps) E_a``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["as_semi_axes", "as_inflation", "guard_semi_axes", "check_pair"]


def as_semi_axes(a: ArrayLike, name: str = "semi_axes") -> NDArray[np.float64]:
    """Return ``a`` as a float array of 2 or 3 positive finite numbers, or raise ValueError."""
    try:
        arr = np.asarray(a, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected 2 or 3 positive numbers, got {a!r}") from None
    if arr.ndim != 1 or arr.shape[0] not in (2, 3):
        raise ValueError(f"{name}: expected 2 or 3 positive numbers, got {np.ndim(arr)}-d {a!r}")
    if not np.all(np.isfinite(arr)) or not np.all(arr > 0):
        raise ValueError(f"{name}: expected 2 or 3 positive finite numbers, got {arr.tolist()}")
    return arr


def as_inflation(eps: float, name: str = "inflation") -> float:
    """Return ``eps`` as a positive finite float, or raise ValueError."""
    try:
        value = float(eps)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a positive number, got {eps!r}") from None
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name}: expected a positive finite number, got {eps!r}")
    return value


def guard_semi_axes(a: ArrayLike, inflation: float) -> NDArray[np.float64]:
    """Semi-axes ``b = (1 + inflation) a`` of the guard ellipsoid."""
    return (1.0 + as_inflation(inflation)) * as_semi_axes(a)


def check_pair(a: ArrayLike, b: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Validate a robot ``a`` and a guard ``b`` of the same dimension.

    ``b`` need not be an inflated copy of ``a`` for the containment margin, but it
    must have the same length and positive entries.
    """
    a_arr = as_semi_axes(a, "a")
    b_arr = as_semi_axes(b, "b")
    if a_arr.shape != b_arr.shape:
        raise ValueError(f"b: expected {a_arr.shape[0]} numbers like a, got {b_arr.shape[0]}")
    return a_arr, b_arr
