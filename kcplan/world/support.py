"""Support functions of convex obstacle pieces: ``h_O(n) = max over x in O of n . x``.

A convex obstacle ``O`` lies in the half-space ``{x : n . x <= h_O(n)}`` for every unit
direction ``n``, exactly, whatever ``n`` is. The free-region certificate relies on this:
it takes a direction from FCL's (iterative, approximate) nearest points but the offset of
the separating plane from here, so an inaccurate direction can only weaken a certificate,
never make it wrong.

Pieces are world-frame and in the scenario's dimension (2D obstacles are planar: the
prisms FCL sees are an implementation detail of :mod:`.collision`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from kcplan.world.pointcloud import CLOUD_KINDS

__all__ = [
    "BallSupport",
    "CylinderSupport",
    "EllipsoidSupport",
    "PointsSupport",
    "ascended_separation",
    "box_vertices",
    "piece_supports",
    "separation",
]


class PointsSupport:
    """Convex hull of points (polygon pieces, boxes, convex obstacles):
    ``h(n) = max_i v_i . n``.

    Parameters
    ----------
    vertices : ndarray, shape (m, n)
    """

    __slots__ = ("vertices",)

    def __init__(self, vertices: NDArray):
        self.vertices = np.ascontiguousarray(vertices, dtype=float)

    def __call__(self, direction: NDArray) -> float:
        return float((self.vertices @ direction).max())


class BallSupport:
    """Disc or ball: ``h(n) = c . n + r |n|``."""

    __slots__ = ("center", "radius")

    def __init__(self, center: NDArray, radius: float):
        self.center, self.radius = np.asarray(center, dtype=float), float(radius)

    def __call__(self, direction: NDArray) -> float:
        return float(self.center @ direction) + self.radius * math.sqrt(
            float(direction @ direction)
        )


class EllipsoidSupport:
    """Ellipse or ellipsoid ``{c + R diag(e) u : |u| <= 1}``: ``h(n) = c . n + |diag(e) R^T n|``."""

    __slots__ = ("center", "shape")

    def __init__(self, center: NDArray, rotation: NDArray, extents: NDArray):
        self.center = np.asarray(center, dtype=float)
        self.shape = np.asarray(extents, dtype=float)[:, None] * np.asarray(rotation).T

    def __call__(self, direction: NDArray) -> float:
        return float(self.center @ direction) + float(np.linalg.norm(self.shape @ direction))


class CylinderSupport:
    """Cylinder of radius ``r`` about its axis ``z`` (a unit vector) through ``c``, ``|(x -
    c) . z| <= h``: ``h(n) = c . n + r |n - (n . z) z| + h |n . z|`` (the rim's farthest
    point plus the end cap's)."""

    __slots__ = ("center", "axis", "radius", "half")

    def __init__(self, center: NDArray, rotation: NDArray, radius: float, half: float):
        self.center = np.asarray(center, dtype=float)
        self.axis = np.asarray(rotation, dtype=float)[:, 2]
        self.radius, self.half = float(radius), float(half)

    def __call__(self, direction: NDArray) -> float:
        along = float(self.axis @ direction)
        across = math.sqrt(max(float(direction @ direction) - along * along, 0.0))
        return float(self.center @ direction) + self.radius * across + self.half * abs(along)


def separation(support_a, support_b, direction: NDArray) -> float:
    """A certain lower bound of the distance between two convex sets from their support
    functions and any unit ``direction`` (from ``a`` towards ``b``): for ``x`` in ``a``
    and ``y`` in ``b``, ``|y - x| >= n . (y - x) >= -h_b(-n) - h_a(n)``. Exact at the
    direction of the nearest points, and never too large whatever the direction is, so
    an iterative solver's inaccurate direction can only weaken it (negative: nothing
    known)."""
    return -support_b(-direction) - support_a(direction)


def ascended_separation(
    support_a, support_b, direction: NDArray, target: float, steps: int = 24
) -> tuple[float, NDArray]:
    """:func:`separation` raised by a local search over unit directions from ``direction``.

    ``g(n) = -h_b(-n) - h_a(n)`` is concave (support functions are convex), so when the
    distance is positive its maximum over the unit sphere is the only local one, and a
    pattern search that keeps every improving turn climbs towards it. Every value found
    is :func:`separation` at some unit direction: a certain lower bound whatever the
    search does. Used when FCL's direction is too coarse near contact (an ellipsoid
    0.4 mm from a metre-sized box: FCL said 0.4 mm, its direction's bound 0).

    Parameters
    ----------
    direction : ndarray, shape (n,)
        Unit start direction, from ``a`` towards ``b``.
    target : float
        Stop once the bound reaches it (e.g. FCL's distance less its tolerance).
    steps : int
        Turn sizes tried, halving from 0.05 rad.

    Returns
    -------
    value : float
        The best bound found (length units; negative: nothing known).
    direction : ndarray, shape (n,)
        Its unit direction.
    """
    v = np.asarray(direction, dtype=float)
    v = v / np.linalg.norm(v)
    best = separation(support_a, support_b, v)
    n = len(v)
    turn = 0.05
    for _ in range(steps):
        if best >= target:
            break
        # an orthonormal basis of the tangent plane at v (QR of [v, I])
        basis = np.linalg.qr(np.column_stack([v, np.eye(n)]))[0][:, 1:n]
        improved = True
        while improved and best < target:
            improved = False
            for t in basis.T:
                for sign in (1.0, -1.0):
                    w = v + sign * turn * t
                    w /= np.linalg.norm(w)
                    value = separation(support_a, support_b, w)
                    if value > best:
                        best, v, improved = value, w, True
        turn *= 0.5
    return best, v


def box_vertices(center: NDArray, rotation: NDArray, extents: NDArray) -> NDArray:
    """Corners of a box, shape ``(2**n, n)``; corner ``sum_k 2**(n-1-k) [sign_k > 0]`` has
    the signs of its index's bits (``meshgrid`` order)."""
    n = len(center)
    signs = np.array(np.meshgrid(*[[-1.0, 1.0]] * n, indexing="ij")).reshape(n, -1).T
    return center + (signs * extents) @ rotation.T


def piece_supports(obstacle) -> list:
    """Support functions of an obstacle's convex pieces, in the order
    :class:`kcplan.world.CollisionWorld` registers them; ``None`` for a piece that is
    not convex (a mesh: only its clearance can be used).

    Parameters
    ----------
    obstacle : kcplan.world.Obstacle
    """
    kind, n = obstacle.kind, len(obstacle.center)
    if kind in ("polygon", "box") and n == 2:
        return [PointsSupport(p) for p in obstacle.pieces]
    if kind == "convex":
        return [PointsSupport(obstacle.vertices)]
    if kind == "box":
        return [PointsSupport(box_vertices(obstacle.center, obstacle.rotation, obstacle.extents))]
    if kind in ("circle", "sphere"):
        return [BallSupport(obstacle.center, obstacle.extents[0])]
    if kind in CLOUD_KINDS:
        return [BallSupport(p, obstacle.extents[0]) for p in obstacle.vertices]
    if kind in ("ellipse", "ellipsoid"):
        return [EllipsoidSupport(obstacle.center, obstacle.rotation, obstacle.extents)]
    if kind == "cylinder":  # extents (r, r, h / 2)
        r, half = float(obstacle.extents[0]), float(obstacle.extents[2])
        return [CylinderSupport(obstacle.center, obstacle.rotation, r, half)]
    return [None]
