"""Ellipsoids that enclose point sets: the minimum-volume one, and exact enclosure.

An ellipsoid here is a centre ``c`` (shape ``(n,)``) and a symmetric positive-definite
*shape matrix* ``M`` (shape ``(n, n)``): ``E = {x : (x - c)^T M (x - c) <= 1}``. Its
semi-axes are ``1 / sqrt(eig(M))`` along the eigenvectors of ``M``.

:func:`minimum_volume_ellipsoid` is Khachiyan's first-order algorithm for the minimum-
volume enclosing ellipsoid (MVEE; Khachiyan, "Rounding of polytopes in the real number
model of computation", Math. Oper. Res. 21, 1996; in the form of Todd and Yildirim, "On
Khachiyan's algorithm for the computation of minimum-volume enclosing ellipsoids",
Discrete Appl. Math. 155, 2007, with their away steps and Kumar and Yildirim's start;
each step changes ``V(u) = Q diag(u) Q^T`` by rank one, so its inverse and every
``g_i = q_i^T V(u)^-1 q_i`` follow by Sherman and Morrison's formula in O(m n)).
The compiled kernel runs the same iteration (``kcplan/_kernel/enclosing.hpp``, the default
:data:`BACKEND`); :func:`khachiyan_weights` is its Python twin.
It is an *approximation*: the ellipsoid it returns need
not contain every point. :func:`enclose` makes containment exact by scaling about the
centre, which is what a sound cover needs; the approximation then only costs volume, at
most a factor ``(1 + tol)^(n/2)`` over the optimum.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import ConvexHull, QhullError

__all__ = [
    "ellipsoid_axes",
    "convex_hull_vertices",
    "ellipsoid_volume",
    "enclose",
    "frame_norm_sq",
    "khachiyan_weights",
    "mahalanobis_sq",
    "minimum_volume_ellipsoid",
]

REFRESH = 64
"""Khachiyan's iteration updates ``V(u)^-1`` and every ``g`` by rank one per step and
computes them afresh after this many steps, and before it stops (the stopping test is on
fresh values)."""

TIE = 1e-9
"""Values of ``g`` within this share of the largest (smallest) tie for Khachiyan's step
towards (away from) a point: the first of them is taken."""

BACKEND = "kernel"
"""Who runs Khachiyan's iteration when :func:`minimum_volume_ellipsoid` is not told:
``"kernel"`` (compiled) or ``"python"`` (:func:`khachiyan_weights`; the ablation of
``scripts/fit_time.py``). Both take the same steps."""

FLAT_RATIO = 1e-6
"""Point sets whose thinnest principal spread is below this fraction of the widest are
treated as flat (Khachiyan's iteration needs a full-dimensional set)."""


def mahalanobis_sq(points: ArrayLike, center: ArrayLike, M: ArrayLike) -> NDArray[np.float64]:
    """``(x - c)^T M (x - c)`` of every point, shape ``(m,)``: at most 1 inside ``E``.

    Computed as ``|diag(1/a) R^T (x - c)|^2`` in the ellipsoid's own frame: the product
    with ``M`` itself cancels badly when ``M`` is ill-conditioned (an error of 1e-8 at an
    axis ratio of 1e-6), the frame's rotation does not (about ``eps a_max / a_min``).
    """
    X = np.asarray(points, dtype=float) - np.asarray(center, dtype=float)
    a, R = ellipsoid_axes(M)
    return frame_norm_sq(X, a, R)


def frame_norm_sq(X: ArrayLike, a: ArrayLike, R: ArrayLike) -> NDArray[np.float64]:
    """``|diag(1/a) R^T x|^2`` of every row ``x`` of ``X`` ``(m, n)``: at most 1 for the
    points of the ellipsoid with semi-axes ``a`` and orientation ``R`` about the origin."""
    Y = (np.asarray(X, dtype=float) @ np.asarray(R, dtype=float)) / np.asarray(a, dtype=float)
    return np.einsum("mi,mi->m", Y, Y)


def ellipsoid_volume(M: ArrayLike) -> float:
    """Volume (area in 2D) of ``E``: ``omega_n / sqrt(det M)``."""
    M = np.asarray(M, dtype=float)
    unit = np.pi if len(M) == 2 else 4.0 * np.pi / 3.0
    return float(unit / np.sqrt(np.linalg.det(M)))


def ellipsoid_axes(M: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Semi-axes ``(n,)`` and a rotation ``R`` ``(n, n)`` (``det R = +1``) with
    ``M = R diag(1 / a^2) R^T``; the axes are in increasing order of length."""
    w, R = np.linalg.eigh(np.asarray(M, dtype=float))
    a = 1.0 / np.sqrt(w)
    order = np.argsort(a)
    a, R = a[order], R[:, order]
    if np.linalg.det(R) < 0:
        R[:, 0] = -R[:, 0]
    return a, R


def _flat_ellipsoid(P: NDArray) -> tuple[NDArray, NDArray]:
    """An ellipsoid around the principal box of a (nearly) flat point set, with the thin
    axes given a thickness of :data:`FLAT_RATIO` of the widest (enclose() finishes it)."""
    c = 0.5 * (P.min(axis=0) + P.max(axis=0))
    _, _, Vt = np.linalg.svd(P - c)  # full: a basis even for fewer points than n
    local = (P - c) @ Vt.T
    mid = 0.5 * (local.min(axis=0) + local.max(axis=0))
    half = 0.5 * np.ptp(local, axis=0)
    half = np.maximum(half, FLAT_RATIO * max(float(half.max()), float(np.abs(P).max()), 1e-30))
    c = c + mid @ Vt
    a = np.sqrt(len(c)) * half  # the box's corners lie on this ellipsoid
    return c, Vt.T @ np.diag(1.0 / a**2) @ Vt


def convex_hull_vertices(points: ArrayLike) -> tuple[NDArray[np.float64], bool]:
    """The vertices of the points' convex hull, in the points' order (qhull's), and True;
    or every point and False when qhull cannot take them (a flat set, too few points).

    Parameters
    ----------
    points : array_like, shape (m, n)

    Returns
    -------
    vertices : ndarray, shape (k, n)
    full : bool
    """
    P = np.asarray(points, dtype=float)
    try:
        return P[ConvexHull(P).vertices], True
    except (QhullError, ValueError):
        return P, False


def minimum_volume_ellipsoid(
    points: ArrayLike,
    tol: float = 1e-3,
    max_iterations: int = 20_000,
    backend: str | None = None,
    hull_vertices: bool = False,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Approximate minimum-volume ellipsoid around points (Khachiyan's algorithm).

    Parameters
    ----------
    points : array_like, shape (m, n)
        ``n`` is 2 or 3; at least one point.
    tol : float
        Stop when every point ``x`` has ``(x - c)^T M (x - c) <= (1 + tol)`` in the
        iteration's scale (Todd and Yildirim's ``epsilon``).
    max_iterations : int
        Safety limit; the result is still an ellipsoid near the points.
    backend : {"kernel", "python"}, optional
        Who runs the iteration: the compiled kernel (``kcplan/_kernel/enclosing.hpp``,
        the same steps without numpy's per-call cost on a few hundred points) or this
        module's loop (:func:`khachiyan_weights`, its twin and reference); default
        :data:`BACKEND`.
    hull_vertices : bool
        The points are the vertices of their convex hull already (as
        ``points[ConvexHull(points).vertices]``): qhull is not run again.

    Returns
    -------
    center : ndarray, shape (n,)
    M : ndarray, shape (n, n)
        Not guaranteed to contain every point: pass the result through :func:`enclose`.
    """
    backend = BACKEND if backend is None else backend
    if backend not in ("kernel", "python"):
        raise ValueError(f"backend: expected 'kernel' or 'python', got {backend!r}")
    P = np.asarray(points, dtype=float)
    if P.ndim != 2 or len(P) == 0 or P.shape[1] not in (2, 3):
        raise ValueError(f"points: expected an (m, 2) or (m, 3) array, got shape {P.shape}")
    n = P.shape[1]
    spread = np.linalg.svd(P - P.mean(axis=0), compute_uv=False)
    if len(P) <= n or spread[-1] <= FLAT_RATIO * max(float(spread[0]), 1e-300):
        return _flat_ellipsoid(P)
    if not hull_vertices:  # only hull vertices can touch the MVEE
        P, full = convex_hull_vertices(P)
        if not full:
            return _flat_ellipsoid(P)
    origin = P.mean(axis=0)
    X = P - origin
    if backend == "kernel":
        from kcplan._kernel import _core  # below every Python layer: no import circle

        u = np.asarray(
            _core.khachiyan_weights(np.ascontiguousarray(X), tol, max_iterations, REFRESH, TIE)
        )
    else:
        u = khachiyan_weights(X, tol, max_iterations)
    c = X.T @ u
    S = (X.T * u) @ X - np.outer(c, c)
    try:
        return c + origin, np.linalg.inv(S) / n
    except np.linalg.LinAlgError:  # pragma: no cover - the support collapsed
        return _flat_ellipsoid(P)


def khachiyan_weights(X: ArrayLike, tol: float, max_iterations: int) -> NDArray[np.float64]:
    """Khachiyan's weights ``u`` ``(m,)`` (summing to 1) of the minimum-volume ellipsoid
    around the rows of ``X`` ``(m, n)``, full-dimensional points (best: the hull's
    vertices, centred); the ellipsoid is ``c = X^T u``, ``M = (X^T diag(u) X - c c^T)^-1
    / n``.

    Todd and Yildirim's form with away steps and Kumar and Yildirim's start (module
    docstring), rank-one updates refreshed every :data:`REFRESH` steps, ties broken by
    :data:`TIE`; stops when every ``g_l / (n + 1) - 1 <= tol`` on fresh values or after
    ``max_iterations`` steps. The twin of the kernel's ``khachiyan_weights``
    (``kcplan/_kernel/enclosing.hpp``), which takes the same steps.
    """
    X = np.asarray(X, dtype=float)
    n = X.shape[1]
    Q = np.vstack([X.T, np.ones(len(X))])  # lifted points, (n + 1, m)
    # Kumar and Yildirim's start: the extreme points along each axis
    u = np.zeros(len(X))
    u[np.unique(np.concatenate([X.argmin(axis=0), X.argmax(axis=0)]))] = 1.0
    u = 0.9 * u / u.sum() + 0.1 / len(X)  # every point keeps weight: V starts regular
    d = n + 1

    def fresh_values() -> tuple[NDArray, NDArray]:  # V(u)^-1 and g_i = q_i^T V(u)^-1 q_i
        V_inv = np.linalg.inv((Q * u) @ Q.T)
        return V_inv, np.einsum("im,im->m", Q, V_inv @ Q)

    V_inv, g = fresh_values()
    rows = np.ascontiguousarray(Q.T)  # the lifted points as rows, (m, n + 1)
    barred = np.zeros(len(X))  # +inf where u_l = 0: no away step from those
    below = np.empty(len(X))
    fresh = 0  # rank-one updates since g was computed afresh
    for _ in range(max_iterations):
        # the first of near ties (within TIE of the extreme): the steps then do not
        # depend on rounding, of the updates or of the platform (symmetric parts, such
        # as a pipe's rings of vertices, tie everywhere)
        top = g.max()
        j = int((g >= top - TIE * abs(top)).argmax())
        np.add(g, barred, out=below)
        low = below.min()
        k = int((below <= low + TIE * abs(low)).argmax())
        grow, shrink = g[j] / d - 1.0, 1.0 - g[k] / d
        if grow <= tol:
            if fresh == 0:
                break
            fresh = REFRESH  # the test on updated g: confirm it on g computed afresh
        elif grow >= shrink:  # Khachiyan's step towards the worst point
            i, step = j, (g[j] - d) / (d * (g[j] - 1.0))
            u *= 1.0 - step
            u[j] += step
            barred[j] = 0.0  # back in the support, if it had been dropped
        else:  # Todd and Yildirim's away step from the weakest support point
            i = k
            step = -min((d - g[k]) / (d * (g[k] - 1.0)), u[k] / (1.0 - u[k]))
            u *= 1.0 - step
            u[k] += step
            if u[k] <= 0.0:  # dropped from the support
                u[k], barred[k] = 0.0, np.inf
        if fresh >= REFRESH:  # bound the updates' rounding drift
            V_inv, g = fresh_values()
            fresh = 0
            continue
        # V(u) became (1 - step) V + step q_i q_i^T: Sherman and Morrison's update of its
        # inverse and of every g, O(m n) instead of a new inverse and O(m n^2)
        w = V_inv @ rows[i]
        h = rows @ w  # q_l^T V^-1 q_i for every l
        scale = step / (1.0 - step + step * g[i])
        keep = 1.0 / (1.0 - step)
        V_inv = (V_inv - (scale * w)[:, None] * w) * keep
        h *= h
        h *= scale
        g -= h
        g *= keep
        fresh += 1
    return u


def enclose(
    points: ArrayLike, center: ArrayLike, M: ArrayLike, margin: float = 1e-9
) -> NDArray[np.float64]:
    """Scale ``E`` about its centre so that every point lies inside with room to spare.

    Returns ``M / s^2`` with ``s = sqrt(max (x - c)^T M (x - c)) (1 + margin)``: every
    point then has ``(x - c)^T M' (x - c) <= (1 + margin)^-2``, which leaves room for
    rounding in later conversions (to semi-axes and a quaternion) and in the points
    themselves (see :mod:`kcplan.cover.partition`).
    """
    M = np.asarray(M, dtype=float)
    worst = float(mahalanobis_sq(points, center, M).max())
    if worst == 0.0:  # every point at the centre: E already holds them, with any size
        return M.copy()
    return M / (worst * (1.0 + margin) ** 2)
