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
them lies in that triangle); in 3D it is computed exactly, as the distance from ``v`` to
the nearest triangle of the inner hull. :func:`bounding_polytopes` returns that number.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import ConvexHull, HalfspaceIntersection

__all__ = [
    "superquadric_level",
    "support_points",
    "unit_normals",
    "bounding_polytopes",
    "BoundingPolytopes",
    "point_triangle_distance",
]


def _exponent(e: float) -> float:
    if not 0.0 < e < 2.0:
        raise ValueError(f"exponent: expected 0 < e < 2 (a smooth convex shape), got {e}")
    return 2.0 / e


def superquadric_level(points: ArrayLike, semi_axes: ArrayLike, e: float) -> NDArray:
    """``sum |x_i / a_i|^{2/e}`` for local points (k, n): <= 1 inside, 1 on the boundary."""
    p = _exponent(e)
    y = np.abs(np.asarray(points, dtype=float) / np.asarray(semi_axes, dtype=float))
    return (y**p).sum(axis=-1)


def support_points(normals: ArrayLike, semi_axes: ArrayLike, e: float) -> tuple[NDArray, NDArray]:
    """Boundary points with the given outward normals, and the support values ``n . x``.

    Parameters
    ----------
    normals : array_like, shape (k, n)
        Unit outward normals (local frame).
    semi_axes : array_like, shape (n,)
    e : float
        Exponent, ``0 < e < 2``.

    Returns
    -------
    points : ndarray, shape (k, n)
    values : ndarray, shape (k,)
    """
    p = _exponent(e)
    q = p / (p - 1.0)
    a = np.asarray(semi_axes, dtype=float)
    m = np.asarray(normals, dtype=float) * a
    mag = np.abs(m)
    # |m|_q with the largest entry factored out: |m_i|^q underflows for q near 1 and tiny m
    top = mag.max(axis=1, keepdims=True)
    r = mag / top
    norm_q = top[:, 0] * (r**q).sum(axis=1) ** (1.0 / q)
    y = np.sign(m) * r ** (q - 1.0) / ((r**q).sum(axis=1, keepdims=True) ** ((q - 1.0) / q))
    return y * a, norm_q


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


def _oriented_faces(hull: ConvexHull) -> NDArray:
    faces = hull.simplices.copy()
    centre = hull.points[hull.vertices].mean(axis=0)
    for f, (i, j, k) in enumerate(faces):
        P = hull.points
        normal = np.cross(P[j] - P[i], P[k] - P[i])
        if normal @ (P[i] - centre) < 0:
            faces[f] = (i, k, j)
    return faces


def bounding_polytopes(semi_axes: ArrayLike, e: float, count: int = 256) -> BoundingPolytopes:
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
    outer = ConvexHull(HalfspaceIntersection(halfspaces, np.zeros(n)).intersections)
    inner = ConvexHull(points)
    inner_faces = _oriented_faces(inner)
    error = float(point_triangle_distance(outer.points, points[inner_faces]).max())
    return BoundingPolytopes(outer.points, points, _oriented_faces(outer), inner_faces, error)


def point_triangle_distance(
    points: ArrayLike, triangles: ArrayLike, chunk: int = 128
) -> NDArray[np.float64]:
    """Distance from each point (k, 3) to the nearest of the triangles (f, 3, 3)."""
    P = np.asarray(points, dtype=float)
    T = np.asarray(triangles, dtype=float)
    A, B, C = T[:, 0], T[:, 1], T[:, 2]
    normal = np.cross(B - A, C - A)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    edges = [(A, B), (B, C), (C, A)]
    out = np.empty(len(P))
    for start in range(0, len(P), chunk):
        p = P[start : start + chunk, None, :]  # (c, 1, 3)
        # inside the prism over the triangle: the plane distance
        plane = np.einsum("cfi,fi->cf", p - A, normal)
        foot = p - plane[..., None] * normal
        inside = np.ones(plane.shape, dtype=bool)
        for U, V in edges:
            inside &= np.einsum("cfi,fi->cf", np.cross(V - U, foot - U), normal) >= 0
        best = np.where(inside, np.abs(plane), np.inf)
        for U, V in edges:  # otherwise the nearest edge point
            d = V - U
            t = np.clip(np.einsum("cfi,fi->cf", p - U, d) / np.einsum("fi,fi->f", d, d), 0, 1)
            gap = np.linalg.norm(p - (U + t[..., None] * d), axis=2)
            best = np.minimum(best, gap)
        out[start : start + chunk] = best.min(axis=1)
    return out
