r"""Polygons and polytopes that bound superellipses and superquadrics from outside or inside.

HRM's maps use the superellipse ``|x/a|^{2/e} + |y/b|^{2/e} <= 1`` (2D) and the
superquadric with equal exponents ``|x/a|^{2/e} + |y/b|^{2/e} + |z/c|^{2/e} <= 1`` (3D);
``e = 1`` is the ellipse/ellipsoid, ``e = 0.1`` an almost-box. For ``0 < e < 2`` the
shape is convex: the unit ball of the p-norm ``p = 2/e`` stretched by ``a``.

Support points. The boundary point with outward normal ``n`` maximises ``n . x``; with
``y = x / a`` and ``m = a * n`` this is ``max m . y`` over ``|y|_p <= 1``, whose value is
the dual norm ``|m|_q`` (``1/p + 1/q = 1``, ``p > 1``), attained at
``y_i = sign(m_i) |m_i|^{q-1} / |m|_q^{q-1}`` (Hoelder's equality case).

Outer approximation: the intersection of the tangent half-spaces ``n_k . x <= |m_k|_q``
at support points ``x_k`` for many normals contains the shape (each half-space does).
Inner approximation: the convex hull of the ``x_k`` lies inside (convexity).
Error bound: the shape lies between the two, so both are within
``max_v dist(v, inner)`` of it (``v`` over the outer polytope's vertices: the distance to
a convex set is a convex function, so its maximum over the outer polytope is at a vertex).
In 2D, ``dist(v, inner)`` is at most the distance from the corner ``v`` of two
consecutive tangent lines to the chord between their support points (the arc between
them lies in that triangle); in 3D it is bounded by the distance from ``v`` to
the nearest of the inner hull's triangles whose planes it lies farthest outside of (a
subset: an upper bound of the distance). :func:`bounding_polytopes` returns that number.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import HalfspaceIntersection

from kcplan.world.mesh import convex_hull

__all__ = [
    "superquadric_level",
    "support_points",
    "unit_normals",
    "bounding_polytopes",
    "BoundingPolytopes",
    "point_triangle_distance",
    "hull_distance_bound",
]


def _exponent(e: float) -> float:
    if not 0.0 < e < 2.0:
        raise ValueError(f"exponent: expected 0 < e < 2 (a smooth convex shape), got {e}")
    return 2.0 / e


def _exponents(e: float | tuple[float, float], n: int) -> tuple[float, float]:
    """``(p1, p2) = (2 / e1, 2 / e2)``: one exponent ``e`` means ``e1 = e2 = e``."""
    e1, e2 = (e, e) if np.ndim(e) == 0 else tuple(e)
    if n == 2 and e1 != e2:
        raise ValueError(f"exponent: a superellipse has one exponent, got {e1}, {e2}")
    return _exponent(e1), _exponent(e2)


def superquadric_level(
    points: ArrayLike, semi_axes: ArrayLike, e: float | tuple[float, float]
) -> NDArray:
    """``(|x/a|^{p2} + |y/b|^{p2})^{p1/p2} + |z/c|^{p1}`` (``p = 2/e``) for local points
    ``(k, n)``: <= 1 inside, 1 on the boundary (2D: ``|x/a|^p + |y/b|^p``)."""
    y = np.abs(np.asarray(points, dtype=float) / np.asarray(semi_axes, dtype=float))
    p1, p2 = _exponents(e, y.shape[-1])
    if y.shape[-1] == 2:
        return (y**p1).sum(axis=-1)
    return ((y[..., :2] ** p2).sum(axis=-1)) ** (p1 / p2) + y[..., 2] ** p1


def _holder(m: NDArray, p: float) -> tuple[NDArray, NDArray]:
    """For rows ``m`` (k, d): the point ``y`` of the unit ``p``-norm ball maximising
    ``m . y`` and the maximum, the dual norm ``|m|_q`` (zero rows: ``y = 0``)."""
    q = p / (p - 1.0)
    mag = np.abs(m)
    # |m|_q with the largest entry factored out: |m_i|^q underflows for q near 1 and tiny m
    top = mag.max(axis=1, keepdims=True)
    safe = np.where(top > 0.0, top, 1.0)
    r = mag / safe
    total = (r**q).sum(axis=1, keepdims=True)
    y = np.sign(m) * r ** (q - 1.0) / np.where(total > 0.0, total, 1.0) ** ((q - 1.0) / q)
    return y, top[:, 0] * total[:, 0] ** (1.0 / q)


def support_points(
    normals: ArrayLike, semi_axes: ArrayLike, e: float | tuple[float, float]
) -> tuple[NDArray, NDArray]:
    """Boundary points with the given outward normals, and the support values ``n . x``.

    Parameters
    ----------
    normals : array_like, shape (k, n)
        Unit outward normals (local frame).
    semi_axes : array_like, shape (n,)
    e : float or (float, float)
        Exponent ``0 < e < 2``, or in 3D Barr's pair ``(e1, e2)`` (``e1`` between the
        z axis and the xy plane, ``e2`` within the xy plane; HRM's column order).

    Returns
    -------
    points : ndarray, shape (k, n)
    values : ndarray, shape (k,)

    Notes
    -----
    With two exponents the shape is ``{(r u, z) : u in the p2-ball of (a, b),
    (r, z / c) in the p1-ball}``; for a fixed ``r`` the best ``u`` gives
    ``r M`` with ``M = |(a n_x, b n_y)|_{q2}``, leaving the 2D problem
    ``max r M + (z / c) c n_z`` over the p1-ball, whose value is
    ``|(M, c n_z)|_{q1}`` (both steps Hoelder's equality case).
    """
    a = np.asarray(semi_axes, dtype=float)
    N = np.asarray(normals, dtype=float)
    p1, p2 = _exponents(e, len(a))
    if len(a) == 2 or p1 == p2:
        y, values = _holder(N * a, p1)
        return y * a, values
    y_xy, M = _holder(N[:, :2] * a[:2], p2)
    rz, values = _holder(np.column_stack([M, a[2] * N[:, 2]]), p1)
    points = np.column_stack([rz[:, :1] * y_xy * a[:2], rz[:, 1] * a[2]])
    return points, values


def unit_normals(n: int, count: int) -> NDArray[np.float64]:
    """``count`` unit vectors spread over the circle (n = 2) or sphere (Fibonacci, n = 3),
    always including the coordinate axes (the flat faces of an almost-box)."""
    if n == 2:
        t = np.linspace(0.0, 2.0 * np.pi, 4 * math.ceil(count / 4), endpoint=False)
        return np.column_stack([np.cos(t), np.sin(t)])
    i = np.arange(count) + 0.5
    z = 1.0 - 2.0 * i / count
    t = np.pi * (1.0 + 5.0**0.5) * i
    r = np.sqrt(1.0 - z * z)
    fib = np.column_stack([r * np.cos(t), r * np.sin(t), z])
    return np.vstack([np.eye(3), -np.eye(3), fib])


class BoundingPolytopes:
    """Outer and inner convex polytopes of one superquadric, in its local frame.

    Attributes
    ----------
    outer : ndarray, shape (m, n)
        Vertices of the circumscribed polytope (contains the shape); in 2D in
        counter-clockwise order.
    inner : ndarray, shape (k, n)
        Vertices of the inscribed polytope (support points; inside the shape); in 2D in
        counter-clockwise order.
    inner_faces, outer_faces : ndarray, shape (f, 3) or None
        Triangles of the 3D hulls (outward orientation), None in 2D.
    error : float
        Upper bound of the distance between each polytope and the shape (same length
        unit as the semi-axes).
    """

    def __init__(self, outer, inner, outer_faces, inner_faces, error):
        self.outer, self.inner = outer, inner
        self.outer_faces, self.inner_faces = outer_faces, inner_faces
        self.error = error


def bounding_polytopes(
    semi_axes: ArrayLike, e: float | tuple[float, float], count: int = 256
) -> BoundingPolytopes:
    """Circumscribed and inscribed polytopes of a superellipse/superquadric (local frame).

    ``count`` normals (2D: rounded up to a multiple of 4; 3D: plus the 6 axis normals).
    The error bound shrinks roughly as ``1 / count`` in 2D and ``1 / sqrt(count)`` in 3D.
    """
    a = np.asarray(semi_axes, dtype=float)
    n = len(a)
    normals = unit_normals(n, count)
    points, values = support_points(normals, a, e)
    halfspaces = np.column_stack([normals, -values])  # n . x - h <= 0
    if n == 2:
        # consecutive normals are counter-clockwise: corners of consecutive tangent lines
        nxt = np.roll(np.arange(len(normals)), -1)
        N = np.stack([normals, normals[nxt]], axis=1)  # (k, 2, 2)
        corners = np.linalg.solve(N, np.column_stack([values, values[nxt]])[..., None])[..., 0]
        chord = points[nxt] - points
        rel = corners - points
        height = np.abs(chord[:, 0] * rel[:, 1] - chord[:, 1] * rel[:, 0])
        error = float((height / np.linalg.norm(chord, axis=1)).max())
        return BoundingPolytopes(corners, points, None, None, error)
    outer, outer_faces = convex_hull(HalfspaceIntersection(halfspaces, np.zeros(n)).intersections)
    inner, inner_faces = convex_hull(points)
    error = float(hull_distance_bound(outer, inner, inner_faces).max())
    return BoundingPolytopes(outer, inner, outer_faces, inner_faces, error)


def point_triangle_distance(
    points: ArrayLike, triangles: ArrayLike, chunk: int = 128
) -> NDArray[np.float64]:
    """Distance from each point (k, 3) to the nearest of the triangles (f, 3, 3)."""
    P = np.asarray(points, dtype=float)
    T = np.asarray(triangles, dtype=float)
    out = np.empty(len(P))
    for start in range(0, len(P), chunk):
        p = P[start : start + chunk, None, :]  # (c, 1, 3) against (1, f, 3)
        out[start : start + chunk] = _triangle_distances(p, T[None]).min(axis=1)
    return out


def hull_distance_bound(
    points: ArrayLike, vertices: ArrayLike, faces: ArrayLike, candidates: int = 16
) -> NDArray[np.float64]:
    """An upper bound of the distance from each point (k, 3) to a closed convex
    triangulated surface: the distance to the nearest of the ``candidates`` triangles
    whose planes the point lies farthest outside of (a subset of the triangles, so never
    below the true distance; for a point outside the hull the nearest face is among the
    faces it sees, and in practice among these, at a fraction of
    :func:`point_triangle_distance`'s cost)."""
    P = np.asarray(points, dtype=float)
    V = np.asarray(vertices, dtype=float)
    T = V[np.asarray(faces)]
    normal = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    height = P @ normal.T - np.einsum("fi,fi->f", normal, T[:, 0])  # (k, f)
    k = min(candidates, len(T))
    best = np.argpartition(-height, k - 1, axis=1)[:, :k]
    return _triangle_distances(P[:, None, :], T[best]).min(axis=1)


def _triangle_distances(p: NDArray, T: NDArray) -> NDArray[np.float64]:
    """Distances between points ``p`` (..., 3) and triangles ``T`` (..., 3, 3),
    broadcast against each other."""
    A, B, C = T[..., 0, :], T[..., 1, :], T[..., 2, :]
    normal = np.cross(B - A, C - A)
    normal = normal / np.linalg.norm(normal, axis=-1, keepdims=True)
    # inside the prism over the triangle: the plane distance
    plane = np.einsum("...i,...i->...", p - A, normal)
    foot = p - plane[..., None] * normal
    inside = np.ones(plane.shape, dtype=bool)
    for U, V in ((A, B), (B, C), (C, A)):
        inside &= np.einsum("...i,...i->...", np.cross(V - U, foot - U), normal) >= 0
    best = np.where(inside, np.abs(plane), np.inf)
    for U, V in ((A, B), (B, C), (C, A)):  # otherwise the nearest edge point
        d = V - U
        t = np.einsum("...i,...i->...", p - U, d) / np.einsum("...i,...i->...", d, d)
        gap = np.linalg.norm(p - (U + np.clip(t, 0, 1)[..., None] * d), axis=-1)
        best = np.minimum(best, gap)
    return best
