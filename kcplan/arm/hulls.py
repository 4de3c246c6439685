"""A link's own convex geometry: the convex hull of its collision mesh, or of a primitive.

Almost every collision mesh of an arm is convex (the MotionBenchMaker Panda's links all
are, up to the open link6, whose vertices' hull contains it; a mobile manipulator's 22 of
24; ``../shared/docs/design.md`` Sec. 10). Such a link is represented *exactly* by its
hull, one coal convex shape, where an ellipsoid cover needs dozens of bodies and still
sticks out by centimetres. A non-convex link is represented by the hull of its vertices,
which contains it (every point of a triangle is a convex combination of its corners):
sound, and as tight as one convex body can be.

The hull is computed by qhull (through trimesh) and then *proved* to hold every vertex of
the mesh: ``delta``, the largest amount by which a mesh vertex lies outside a hull face
(rounding in qhull, ~1e-16 m), is measured, and where it is positive the hull is grown
about the mean ``c`` of its vertices (strictly inside it) by ``1 + 2 delta / rho``
(``rho`` the smallest distance from ``c`` to a face plane): each face plane ``n . x <= h``
then moves outward by ``2 delta (h - n . c) / rho >= 2 delta``, so no vertex is outside
any more (the factor 2 leaves room for the growth's own rounding).

A body's frame is centred on the smallest ball around its hull (trimesh's
``minimum_nsphere``), with the axes of the geometry's frame, and its bounding radius is
the largest distance of a hull vertex from that centre. Every speed bound of
:mod:`kcplan.arm.bounds` holds for the ball, hence for the hull inside it.

This module reads meshes; it imports neither OMPL nor FCL.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["CYLINDER_SIDES", "BodyHull", "box_hull", "cylinder_hull", "mesh_hull", "points_hull"]

CYLINDER_SIDES = 32
"""Sides of the prism that stands for a cylinder: its polygon circumscribes the circle
(vertices at ``r / cos(pi / 32)``, 0.48 % out), so the prism contains the cylinder."""


@dataclass(frozen=True, eq=False)
class BodyHull:
    """A convex body in its own frame.

    Attributes
    ----------
    vertices : ndarray, shape (m, 3)
        The hull's vertices, metres, in the body's frame (its centre at the origin).
    triangles : ndarray of int, shape (t, 3)
        The hull's faces, outward (counter-clockwise seen from outside).
    radius : float
        The largest distance of a vertex from the origin, rounded up: the body lies in
        the ball of this radius about its centre.
    offset : float
        How far the hull was grown to hold every vertex of its source (``delta`` of the
        module docstring, metres; 0 for an exact hull).
    """

    vertices: NDArray[np.float64]
    triangles: NDArray[np.int64]
    radius: float
    offset: float = 0.0


def points_hull(points: NDArray[np.float64]) -> tuple[NDArray[np.float64], BodyHull]:
    """The convex hull of ``points`` ``(p, 3)`` (metres, some frame ``F``), proved to hold
    each of them.

    Returns
    -------
    centre : ndarray, shape (3,)
        The body's centre in ``F`` (the smallest ball's).
    hull : BodyHull
        Its vertices about that centre, with the axes of ``F``.

    Raises
    ------
    ValueError
        When the points span no volume (fewer than 4, or all in a plane).
    """
    import trimesh

    points = np.asarray(points, dtype=float).reshape(-1, 3)
    if len(points) < 4 or not np.isfinite(points).all():
        raise ValueError(f"expected at least 4 finite points, got {len(points)}")
    try:
        with np.errstate(divide="ignore", invalid="ignore"):  # a flat set: refused below
            hull = trimesh.convex.convex_hull(points)
            volume = hull.volume
    except Exception as err:  # qhull's errors carry no common type
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise ValueError(f"expected points that span a volume, got: {first}") from None
    if not volume > 0.0:
        raise ValueError("expected points that span a volume, got a flat set")
    centre, _ = trimesh.nsphere.minimum_nsphere(hull.vertices)
    centre = np.asarray(centre, dtype=float)
    vertices = hull.vertices - centre
    normals = hull.face_normals
    heights = np.einsum("ij,ij->i", normals, vertices[hull.faces[:, 0]])
    delta = 0.0  # in blocks: a 130,000-vertex mesh against an 8,000-face hull at once is 8 GB
    block = max(1, 4_000_000 // len(normals))
    for start in range(0, len(points), block):
        local = points[start : start + block] - centre
        delta = max(delta, float((local @ normals.T - heights).max()))
    if delta > 0.0:  # grown about the vertices' mean, strictly inside the hull
        inner = vertices.mean(axis=0)
        rho = float((heights - normals @ inner).min())
        if not rho > 0.0:
            raise ValueError("expected points that span a volume, got a degenerate hull")
        vertices = inner + (vertices - inner) * (1.0 + 2.0 * delta / rho)  # 2: its rounding
    radius = float(np.linalg.norm(vertices, axis=1).max()) * (1.0 + 1e-12)
    hull_out = BodyHull(
        np.ascontiguousarray(vertices), np.asarray(hull.faces, dtype=np.int64), radius, delta
    )
    return centre, hull_out


def mesh_hull(path: str | os.PathLike, scale: float = 1.0) -> tuple[NDArray[np.float64], BodyHull]:
    """:func:`points_hull` of the vertices of the mesh in ``path`` (STL, OBJ, DAE, ...)
    times ``scale``: it contains every triangle of the mesh, open or closed.

    Raises
    ------
    ValueError
        One line naming the file: not readable, or no volume.
    """
    import trimesh

    source = os.fspath(path)
    try:
        mesh = trimesh.load(source, force="mesh", process=False)
        points = np.asarray(mesh.vertices, dtype=float) * float(scale)
    except Exception as err:  # trimesh raises many kinds for a file it cannot read
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise ValueError(f"{source}: expected a readable mesh, got: {first}") from None
    try:
        return points_hull(points)
    except ValueError as err:
        raise ValueError(f"{source}: {err}") from None


def box_hull(half: NDArray[np.float64]) -> tuple[NDArray[np.float64], BodyHull]:
    """The box of half sides ``half`` ``(3,)`` about the origin, exactly."""
    half = np.asarray(half, dtype=float)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    return points_hull(corners)


def cylinder_hull(radius: float, half_length: float) -> tuple[NDArray[np.float64], BodyHull]:
    """A prism of :data:`CYLINDER_SIDES` sides about the cylinder of ``radius`` around the
    z axis, ``|z| <= half_length``: it contains the cylinder (its polygon circumscribes
    the circle)."""
    outer = radius / math.cos(math.pi / CYLINDER_SIDES) * (1.0 + 1e-12)
    angles = 2.0 * math.pi * np.arange(CYLINDER_SIDES) / CYLINDER_SIDES
    ring = np.stack([outer * np.cos(angles), outer * np.sin(angles)], axis=1)
    rims = [np.column_stack([ring, np.full(CYLINDER_SIDES, z)]) for z in (-1.0, 1.0)]
    rims = [rim * [1.0, 1.0, half_length] for rim in rims]
    return points_hull(np.vstack(rims))
