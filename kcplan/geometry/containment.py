"""Exact containment margin of one ellipsoid in another.

The robot ``E_a`` at relative pose ``xi = [omega, tau]`` lies inside the
axis-aligned guard ``E_b`` centred at the origin iff (design notes, Sec. 2)

    m(xi) = max_{|u| <= 1} || diag(1/b) (R diag(a) u + tau) ||  <=  1,   R = exp(hat(omega)).

``m`` is a convex quadratic maximised over the unit ball (a trust-region problem).
It is solved exactly here: with the SVD ``M = U S V^T`` of ``M = diag(1/b) R diag(a)``
and ``d = U^T diag(1/b) tau``, Lagrangian duality (tight for trust-region problems
by the S-lemma) gives

    m^2 = min_{mu >= 0} g(mu),   g(mu) = (s_1^2 + mu) (1 + sum_i d_i^2 / (s_1^2 - s_i^2 + mu)),

a convex function of one variable whose stationarity condition is the secular
equation ``sum_i s_i^2 d_i^2 / (s_1^2 - s_i^2 + mu)^2 = 1``. When that sum is <= 1 at
``mu = 0`` (the "hard case", top component of ``d`` zero), the minimum is ``g(0)``.
Every ``g(mu)`` is an upper bound on ``m^2`` (weak duality), so the returned value
errs, if at all, on the side of "not contained".
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.geometry.ellipsoid import check_pair
from kcplan.geometry.rotations import exp_rotation, hat, split_xi

__all__ = [
    "max_affine_norm",
    "containment_margin",
    "first_order_margin",
    "linearised_margin",
    "ray_extent",
]


def _secular_mu(s2: NDArray, w: NDArray, iterations: int = 60) -> NDArray:
    """Root ``mu >= 0`` of ``sum_i w_i / (delta_i + mu)^2 = 1`` (0 when the sum is <= 1 at 0).

    ``s2`` holds squared singular values sorted descending, shape (k, n); ``w = s^2 d^2``.
    Newton's method on the concave increasing ``phi(mu) = 1 - 1 / p(mu)``,
    ``p(mu) = sqrt(sum_i w_i / (delta_i + mu)^2)``, started left of the root, increases
    monotonically to it (Moré and Sorensen, 1983), so every iterate is feasible for the dual.
    """
    delta = s2[:, :1] - s2
    # Lower bound of the root: each term alone must not exceed 1.
    mu = np.maximum(0.0, np.max(np.sqrt(w) - delta, axis=1))
    active = np.ones(mu.shape, dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(iterations):
            den = delta + mu[:, None]
            terms = np.where(w > 0, w / den**2, 0.0)
            p2 = terms.sum(axis=1)
            boundary = p2 <= 1.0
            if np.all(boundary | ~active):
                break
            p = np.sqrt(p2)
            dp2 = -2.0 * np.where(w > 0, w / den**3, 0.0).sum(axis=1)
            # phi = 1 - 1/p, phi' = p'/p^2 = dp2 / (2 p^3)
            phi = 1.0 - 1.0 / p
            dphi = dp2 / (2.0 * p**3)
            step = np.where(active & ~boundary, -phi / dphi, 0.0)
            step = np.where(np.isfinite(step), step, 0.0)
            new = mu + np.maximum(step, 0.0)
            active = new > mu * (1.0 + 1e-15) + 1e-300
            mu = new
    return mu


def max_affine_norm(M: ArrayLike, c: ArrayLike) -> NDArray[np.float64]:
    """Exact ``max_{|u| <= 1} |M u + c|`` for stacks of square matrices.

    Parameters
    ----------
    M : array_like, shape (k, n, n) or (n, n)
    c : array_like, shape (k, n) or (n,)

    Returns
    -------
    ndarray, shape (k,) or scalar
        The maximum, computed through the dual of the trust-region problem (module
        docstring); an upper bound within rounding of the exact value, never below it.
    """
    M = np.asarray(M, dtype=float)
    c = np.asarray(c, dtype=float)
    single = M.ndim == 2
    M = M[None] if single else M
    c = np.atleast_2d(c)
    U, s, _ = np.linalg.svd(M)
    d = np.einsum("kji,kj->ki", U, c)
    s2 = s**2
    mu = _secular_mu(s2, s2 * d**2)
    delta = s2[:, :1] - s2 + mu[:, None]
    d2 = d**2
    # d2 > 0 implies delta > 0 here (mu > 0 whenever the top component is non-zero);
    # the floor only guards against w = s^2 d^2 underflowing while d^2 does not.
    q = np.where(d2 > 0, d2 / np.maximum(delta, np.finfo(float).tiny), 0.0).sum(axis=1)
    value = np.sqrt((s2[:, 0] + mu) * (1.0 + q))
    return value[0] if single else value


def _margin(a: NDArray, b: NDArray, linear: NDArray, tau: NDArray) -> NDArray:
    """``max_{|u|<=1} |diag(1/b)(L diag(a) u + tau)|`` for a stack of matrices ``L``."""
    M = linear * a[None, None, :] / b[None, :, None]
    return max_affine_norm(M, tau / b[None, :])


def _finish(value: NDArray, single: bool) -> NDArray[np.float64] | float:
    return float(value[0]) if single else value


def containment_margin(a: ArrayLike, b: ArrayLike, xi: ArrayLike) -> NDArray[np.float64] | float:
    """Exact containment margin of ``E_a`` at relative pose ``xi`` in the guard ``E_b``.

    Parameters
    ----------
    a, b : array_like, shape (n,)
        Semi-axes of the robot and of the axis-aligned guard at the origin, n = 2 or 3.
    xi : array_like, shape (k, d) or (d,)
        KC coordinates ``[theta, x, y]`` (n = 2) or ``[w1, w2, w3, x, y, z]`` (n = 3).

    Returns
    -------
    float or ndarray, shape (k,)
        ``max_{|u|<=1} ||diag(1/b)(exp(hat(omega)) diag(a) u + tau)||``; ``<= 1`` means
        the robot is inside the guard (boundary touching included).
    """
    a, b = check_pair(a, b)
    n = a.shape[0]
    omega, tau, single = split_xi(xi, n)
    return _finish(_margin(a, b, exp_rotation(omega, n), tau), single)


def linearised_margin(
    a: ArrayLike, b: ArrayLike, alpha: ArrayLike, xi: ArrayLike
) -> NDArray[np.float64] | float:
    """``G(alpha, omega, tau) = max_{|u|<=1} ||B^-1((alpha I + hat(omega)) A u + tau)||``.

    ``A = diag(a)``, ``B = diag(b)``.

    ``G`` is convex and positively homogeneous of degree one in ``(alpha, omega, tau)``;
    ``G(1, omega, tau)`` is the paper's first-order margin and, in 2D,
    ``G(cos t, sin t, tau)`` is the exact margin at angle ``t``. The convex lower bound's
    soundness proof rests on these two facts (see :mod:`kcplan.kc.convex`).

    Parameters
    ----------
    alpha : array_like, shape (k,) or scalar
        Scale of the identity part.
    xi : array_like, shape (k, d) or (d,)
    """
    a, b = check_pair(a, b)
    n = a.shape[0]
    omega, tau, single = split_xi(xi, n)
    al = np.broadcast_to(np.asarray(alpha, dtype=float), (omega.shape[0],))
    linear = al[:, None, None] * np.eye(n)[None] + hat(omega, n).reshape(-1, n, n)
    return _finish(_margin(a, b, linear, tau), single)


def first_order_margin(a: ArrayLike, b: ArrayLike, xi: ArrayLike) -> NDArray[np.float64] | float:
    """The paper's first-order containment margin (eq. 9-11).

    The exact margin with ``exp(hat(omega))`` replaced by ``I + hat(omega)``; its
    sub-level set ``{xi : first_order_margin <= 1}`` is convex. Parameters as in
    :func:`containment_margin`.
    """
    return linearised_margin(a, b, 1.0, xi)


def ray_extent(
    margin,
    directions: ArrayLike,
    level: float = 1.0,
    upper: float | ArrayLike = 1.0,
    iterations: int = 60,
) -> NDArray[np.float64]:
    """Largest ``t >= 0`` with ``margin(t * direction) <= level``, for a convex ``margin``.

    Bisection, vectorised over directions; the returned ``t`` is the lower end of the
    final bracket, so ``margin(t * direction) <= level`` holds for it (it is inside).

    Parameters
    ----------
    margin : callable
        Maps points of shape (k, d) to values of shape (k,); convex along rays from
        the origin, with ``margin(0) < level``.
    directions : array_like, shape (k, d)
    upper : float or array_like, shape (k,)
        Initial guess of the extent; doubled until it is outside.
    """
    D = np.atleast_2d(np.asarray(directions, dtype=float))
    hi = np.broadcast_to(np.asarray(upper, dtype=float), (D.shape[0],)).copy()
    for _ in range(200):
        outside = margin(hi[:, None] * D) > level
        if np.all(outside):
            break
        hi = np.where(outside, hi, 2.0 * hi)
    else:
        raise ValueError("ray_extent: the region is unbounded along some direction")
    lo = np.zeros_like(hi)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        inside = margin(mid[:, None] * D) <= level
        lo = np.where(inside, mid, lo)
        hi = np.where(inside, hi, mid)
    return lo
