"""Rotations in exponential coordinates and the PCG(n) = SO(n) x R^n pose coordinates.

Conventions (used everywhere in kcplan, see ``docs`` and the design notes):

* A rotation is given by its exponential coordinates ``omega``: a scalar angle
  ``theta`` in 2D (radians, counter-clockwise), a rotation vector ``[w1, w2, w3]``
  in 3D (axis times angle, radians), with ``R = exp(hat(omega))``.
* KC coordinates of a pose are ``xi = [omega, tau]``: ``[theta, x, y]`` in 2D
  (``d = 3``) and ``[w1, w2, w3, x, y, z]`` in 3D (``d = 6``).

Every function takes one vector or a stack of shape ``(k, ...)`` and answers row by row.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "kc_dimension",
    "rotation_dimension",
    "hat",
    "exp_rotation",
    "log_rotation",
    "split_xi",
]


def kc_dimension(n: int) -> int:
    """Number of KC coordinates ``d`` for ellipsoids in R^n: 3 for n = 2, 6 for n = 3."""
    if n not in (2, 3):
        raise ValueError(f"dimension: expected 2 or 3, got {n}")
    return n + rotation_dimension(n)


def rotation_dimension(n: int) -> int:
    """Dimension of SO(n): 1 for n = 2, 3 for n = 3."""
    if n not in (2, 3):
        raise ValueError(f"dimension: expected 2 or 3, got {n}")
    return n * (n - 1) // 2


def hat(omega: ArrayLike, n: int) -> NDArray[np.float64]:
    """Skew-symmetric matrix of exponential coordinates.

    Parameters
    ----------
    omega : array_like, shape (k, r) or (r,)
        ``r = 1`` (n = 2) or ``r = 3`` (n = 3).
    n : int
        Space dimension, 2 or 3.

    Returns
    -------
    ndarray, shape (k, n, n) or (n, n)
        ``hat(omega)`` with ``hat(omega) v = omega x v`` in 3D and ``[[0, -t], [t, 0]]`` in 2D.
    """
    w = np.asarray(omega, dtype=float)
    single = w.ndim == 1
    w = np.atleast_2d(w)
    out = np.zeros((w.shape[0], n, n))
    if n == 2:
        out[:, 0, 1] = -w[:, 0]
        out[:, 1, 0] = w[:, 0]
    else:
        out[:, 0, 1], out[:, 0, 2] = -w[:, 2], w[:, 1]
        out[:, 1, 0], out[:, 1, 2] = w[:, 2], -w[:, 0]
        out[:, 2, 0], out[:, 2, 1] = -w[:, 1], w[:, 0]
    return out[0] if single else out


def exp_rotation(omega: ArrayLike, n: int) -> NDArray[np.float64]:
    """Rotation matrix ``R = exp(hat(omega))`` (Rodrigues' formula in 3D).

    Parameters
    ----------
    omega : array_like, shape (k, r) or (r,)
        Exponential coordinates, radians.
    n : int
        Space dimension, 2 or 3.

    Returns
    -------
    ndarray, shape (k, n, n) or (n, n)
    """
    w = np.asarray(omega, dtype=float)
    single = w.ndim == 1
    w = np.atleast_2d(w)
    if n == 2:
        c, s = np.cos(w[:, 0]), np.sin(w[:, 0])
        out = np.empty((w.shape[0], 2, 2))
        out[:, 0, 0], out[:, 0, 1] = c, -s
        out[:, 1, 0], out[:, 1, 1] = s, c
    else:
        t = np.linalg.norm(w, axis=1)
        small = t < 1e-8
        ts = np.where(small, 1.0, t)
        # sin(t)/t and (1 - cos t)/t^2 with their Taylor series near 0
        a = np.where(small, 1.0 - t**2 / 6.0, np.sin(ts) / ts)
        b = np.where(small, 0.5 - t**2 / 24.0, (1.0 - np.cos(ts)) / ts**2)
        K = hat(w, 3)
        out = np.eye(3) + a[:, None, None] * K + b[:, None, None] * (K @ K)
    return out[0] if single else out


def log_rotation(R: ArrayLike) -> NDArray[np.float64]:
    """Exponential coordinates of rotation matrices (inverse of :func:`exp_rotation`).

    The angle is returned in ``(-pi, pi]`` (2D) or ``[0, pi]`` as the norm of the
    rotation vector (3D).

    Parameters
    ----------
    R : array_like, shape (k, n, n) or (n, n)

    Returns
    -------
    ndarray, shape (k, r) or (r,)
    """
    M = np.asarray(R, dtype=float)
    single = M.ndim == 2
    M = M[None] if single else M
    n = M.shape[-1]
    if n == 2:
        out = np.arctan2(M[:, 1, 0], M[:, 0, 0])[:, None]
    else:
        cos_t = np.clip((np.trace(M, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
        t = np.arccos(cos_t)
        v = np.stack([M[:, 2, 1] - M[:, 1, 2], M[:, 0, 2] - M[:, 2, 0], M[:, 1, 0] - M[:, 0, 1]], 1)
        small = t < 1e-8
        s = np.where(small, 1.0, np.sin(t))
        out = np.where(small[:, None], 0.5 * v, v * (t / (2.0 * s))[:, None])
        near_pi = t > np.pi - 1e-6
        if np.any(near_pi):
            # sin(t) ~ 0: recover the axis from the symmetric part R + I = 2 k k^T.
            for i in np.flatnonzero(near_pi):
                S = (M[i] + np.eye(3)) / 2.0
                j = int(np.argmax(np.diag(S)))
                k = S[:, j] / np.sqrt(S[j, j])
                if np.dot(k, v[i]) < 0:
                    k = -k
                out[i] = k * t[i]
    return out[0] if single else out


def split_xi(xi: ArrayLike, n: int) -> tuple[NDArray[np.float64], NDArray[np.float64], bool]:
    """Split KC coordinates into rotation and translation parts.

    Parameters
    ----------
    xi : array_like, shape (k, d) or (d,)
        KC coordinates ``[omega, tau]``.
    n : int
        Space dimension, 2 or 3.

    Returns
    -------
    omega : ndarray, shape (k, r)
    tau : ndarray, shape (k, n)
    single : bool
        True when ``xi`` was one vector (callers then return scalars).
    """
    x = np.asarray(xi, dtype=float)
    d = kc_dimension(n)
    single = x.ndim == 1
    x = np.atleast_2d(x)
    if x.ndim != 2 or x.shape[1] != d:
        raise ValueError(f"xi: expected shape ({d},) or (k, {d}) for n = {n}, got {np.shape(xi)}")
    r = rotation_dimension(n)
    return x[:, :r], x[:, r:], single
