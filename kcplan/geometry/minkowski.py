"""The Minkowski difference ``E_b - R E_a`` of two centred ellipsoids.

For a fixed orientation ``R`` the set of translations ``tau`` that keep ``R E_a + tau``
inside ``E_b`` is the Minkowski difference ``K(R) = E_b - R E_a``: convex, centrally
symmetric, non-empty iff ``R E_a`` fits inside ``E_b`` at ``tau = 0``. It is the KC
C-space's slice at ``R`` (paper eq. 5).

Its radial function along a direction ``v`` has a closed form up to a one-dimensional
maximisation. With ``M = diag(1/b) R diag(a) = U S V^T`` and ``d = U^T diag(1/b) v``,
the containment dual (see :mod:`kcplan.geometry.containment`) shows that ``s v`` is in
``K(R)`` iff some ``lam`` in ``[s_1^2, 1]`` has ``lam (1 + s^2 q(lam)) <= 1``,
``q(lam) = sum_i d_i^2 / (lam - s_i^2)``, so

    rho(v)^2 = max_{s_1^2 <= lam <= 1} (1 - lam) / (lam q(lam)).

``lam q(lam)`` is convex on that interval, hence every super-level set of the
objective is an interval: the objective is quasi-concave and golden-section search
finds its maximum. Any ``lam`` gives a point of ``K(R)``, so the result is never
outside the set.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.geometry.ellipsoid import check_pair
from kcplan.geometry.rotations import exp_rotation

__all__ = [
    "radial_extent",
    "centred_margin",
    "sphere_directions",
    "circle_directions",
    "sphere_frames",
]

_GOLDEN = (np.sqrt(5.0) - 1.0) / 2.0


def centred_margin(a: ArrayLike, b: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
    """Largest singular value of ``diag(1/b) R diag(a)``: ``<= 1`` iff ``R E_a`` fits in ``E_b``.

    Parameters
    ----------
    omega : array_like, shape (k, r)
        Exponential coordinates of the orientations.

    Returns
    -------
    ndarray, shape (k,)
    """
    a, b = check_pair(a, b)
    n = a.shape[0]
    R = exp_rotation(np.atleast_2d(omega), n)
    M = R * a[None, None, :] / b[None, :, None]
    return np.linalg.svd(M, compute_uv=False)[:, 0]


def radial_extent(
    a: ArrayLike, b: ArrayLike, omega: ArrayLike, directions: ArrayLike, iterations: int = 64
) -> NDArray[np.float64]:
    """Radial function of ``K(R) = E_b - R E_a`` for each orientation and direction.

    Parameters
    ----------
    a, b : array_like, shape (n,)
        Robot and guard semi-axes.
    omega : array_like, shape (k, r)
        Exponential coordinates of ``k`` orientations.
    directions : array_like, shape (m, n) or (k, m, n)
        Unit directions in the guard frame, shared or one set per orientation.
    iterations : int
        Golden-section steps; the bracket shrinks by 0.618 each step.

    Returns
    -------
    ndarray, shape (k, m)
        The largest ``s`` with ``s * direction`` in ``K(R)`` (0 where ``K(R)`` is empty).
    """
    a, b = check_pair(a, b)
    n = a.shape[0]
    R = exp_rotation(np.atleast_2d(omega), n)
    M = R * a[None, None, :] / b[None, :, None]
    U, s, _ = np.linalg.svd(M)
    s2 = s**2  # (k, n), descending
    D = np.asarray(directions, dtype=float) / b
    pattern = "kji,mj->kmi" if D.ndim == 2 else "kji,kmj->kmi"
    d2 = np.einsum(pattern, U, D) ** 2  # (k, m, n)
    lo = np.broadcast_to(s2[:, :1], d2.shape[:2]).copy()
    hi = np.ones_like(lo)
    empty = lo[:, 0] >= 1.0

    def objective(lam: NDArray) -> NDArray:
        with np.errstate(divide="ignore", invalid="ignore"):
            gap = lam[..., None] - s2[:, None, :]
            q = np.where(d2 > 0, d2 / gap, 0.0).sum(axis=-1)
            f = (1.0 - lam) / (lam * q)
        return np.where(np.isfinite(f) & (f > 0), f, 0.0)

    x1 = hi - _GOLDEN * (hi - lo)
    x2 = lo + _GOLDEN * (hi - lo)
    f1, f2 = objective(x1), objective(x2)
    for _ in range(iterations):
        left = f1 >= f2  # the maximum lies in [lo, x2]
        hi = np.where(left, x2, hi)
        lo = np.where(left, lo, x1)
        p = np.where(left, hi - _GOLDEN * (hi - lo), lo + _GOLDEN * (hi - lo))
        fp = objective(p)
        x1, f1, x2, f2 = (
            np.where(left, p, x2),
            np.where(left, fp, f2),
            np.where(left, x1, p),
            np.where(left, f1, fp),
        )
    best = np.maximum(f1, f2)
    best[empty] = 0.0
    return np.sqrt(best)


def circle_directions(m: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``m`` equally spaced unit vectors in the plane and their weights ``2 pi / m``."""
    phi = (np.arange(m) + 0.5) * (2.0 * np.pi / m)
    return np.stack([np.cos(phi), np.sin(phi)], axis=1), np.full(m, 2.0 * np.pi / m)


def sphere_directions(m: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Product quadrature on the unit sphere: Gauss-Legendre in ``z`` times ``2m`` azimuths.

    Returns ``(directions (2 m^2, 3), weights (2 m^2,))`` with weights summing to ``4 pi``.
    """
    z, wz = np.polynomial.legendre.leggauss(m)
    phi = (np.arange(2 * m) + 0.5) * (np.pi / m)
    Z, P = np.meshgrid(z, phi, indexing="ij")
    rho = np.sqrt(1.0 - Z**2)
    dirs = np.stack([rho * np.cos(P), rho * np.sin(P), Z], axis=-1).reshape(-1, 3)
    weights = (wz[:, None] * np.full(2 * m, np.pi / m)[None, :]).reshape(-1)
    return dirs, weights


def sphere_frames(
    a: ArrayLike, b: ArrayLike, omega: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Closed-form axes of ``E_b - R E_a`` after shrinking the robot to a ball (paper Sec. 5).

    ``T = R diag(a / r) R^T`` with ``r = min(a)`` maps the ball of radius ``r`` onto
    ``R E_a``; ``T^{-1} E_b`` is an ellipsoid with semi-axes ``b'`` along the columns of
    ``V``; its inner parallel body at distance ``r`` (the shrunk Minkowski difference)
    reaches ``d_i*`` along axis ``i`` (eq. 19, with the critical radius of eq. 28):

        d_i* = min(b'_i - r, min_{j : r > b'_j^2 / b'_i} sqrt((b'_i^2 - b'_j^2)(1 - r^2 / b'_j^2))).

    The second form is the distance from an axis point to the ellipsoid when its
    nearest boundary point leaves the axis (in the plane of axes i and j).

    Parameters
    ----------
    omega : array_like, shape (k, r)

    Returns
    -------
    T : ndarray, shape (k, n, n)
    V : ndarray, shape (k, n, n)
        Orthonormal axes of ``T^{-1} E_b`` (columns).
    d : ndarray, shape (k, n)
        ``d_i*``; all zero where ``R E_a`` does not fit in ``E_b``.
    """
    a, b = check_pair(a, b)
    n = a.shape[0]
    R = exp_rotation(np.atleast_2d(omega), n).reshape(-1, n, n)
    r = float(a.min())
    T = np.einsum("kij,j,klj->kil", R, a / r, R)
    # x in T^-1 E_b  iff  x^T (T B^-2 T) x <= 1
    evals, V = np.linalg.eigh(np.einsum("kij,j,kjl->kil", T, b**-2.0, T))
    bp = evals**-0.5
    d = bp - r
    for i in range(n):
        for j in range(n):
            if i != j:
                critical = r > bp[:, j] ** 2 / bp[:, i]  # eq. 28
                with np.errstate(invalid="ignore"):
                    alt = np.sqrt((bp[:, i] ** 2 - bp[:, j] ** 2) * (1.0 - r**2 / bp[:, j] ** 2))
                d[:, i] = np.where(critical & np.isfinite(alt), np.minimum(d[:, i], alt), d[:, i])
    d[np.any(bp <= r, axis=1)] = 0.0
    return T, V, np.maximum(d, 0.0)
