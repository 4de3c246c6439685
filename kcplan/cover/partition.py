"""Pieces of a solid cut by planes, and the points whose hull contains each piece.

The cover of a solid ``S`` (:mod:`kcplan.cover.fit`) cuts space by a binary tree of
planes into convex cells ``V`` and encloses each piece ``S ∩ V`` in one ellipsoid. The
enclosure is sound because of this fact, which this module computes:

    Every vertex of the polyhedron ``S ∩ V`` is (a) a vertex of a boundary simplex of
    ``S`` inside ``V``, (b) a point where a simplex edge crosses a facet of ``V``, (c) a
    point where a simplex meets an edge of ``V``, or (d) a vertex of ``V`` in ``S``.

Clipping every boundary simplex by the halfspaces of ``V`` in turn yields polygons
whose vertices are exactly the points of kinds (a)-(c); the cell's own corners that lie
in ``S`` (winding number, :mod:`kcplan.geometry.winding`) are kind (d). A bounded set
lies in the convex hull of its vertices, the hull of a point set lies in every ellipsoid
(convex) that holds the points, and the pieces of all leaves make up ``S``. So an
ellipsoid that holds a piece's :attr:`Piece.points` holds the piece, and one such
ellipsoid per leaf covers ``S``.

Clipping here is exact-sided: a point is kept when ``n . x <= o`` without a tolerance
band (trimesh's ``slice_faces_plane`` snaps points within ``1e-8`` of the plane, which
can drop a thin sliver from both sides). The new points are computed in floating point,
within a few ulps of the true crossings; the cover's relative margin of ``1e-9``
(:func:`kcplan.geometry.enclosing.enclose`) absorbs that for any ellipsoid whose
shortest semi-axis is above ``1e-6`` of the part's size.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from kcplan.geometry.enclosing import convex_hull_vertices
from kcplan.geometry.winding import winding_numbers

__all__ = ["Piece", "clip_simplices", "clip_points"]

INSIDE_WINDING = 0.25
"""Cell corners whose winding number exceeds this in magnitude count as inside the solid.
Inside is 1 and outside 0; erring towards inside only adds points, which is always sound.
A corner exactly on the boundary may read either way, and needs no test: it is a corner
of the clipped simplex it lies on, so clipping supplies it."""


def clip_simplices(simplices: NDArray, normal: NDArray, offset: float) -> NDArray:
    """The parts of segments ``(k, 2, 2)`` or triangles ``(k, 3, 3)`` in the closed
    halfspace ``normal . x <= offset``, as simplices of the same kind.

    A triangle with one corner inside becomes one triangle, with two corners inside a
    quadrilateral split into two triangles; a segment with one end inside is shortened.
    """
    S = np.asarray(simplices, dtype=float)
    if len(S) == 0:
        return S
    d = S @ normal - offset  # (k, corners), <= 0 inside
    inside = d <= 0.0
    count = inside.sum(axis=1)
    corners = S.shape[1]
    parts = [S[count == corners]]
    for keep in range(1, corners):
        sel = count == keep
        if not sel.any():
            continue
        T, D, keeps = S[sel], d[sel], inside[sel]
        # roll each simplex so that its inside corners come first (in cyclic order)
        if corners == 2:
            first = np.where(keeps[:, 0], 0, 1)
        elif keep == 1:
            first = np.argmax(keeps, axis=1)
        else:
            first = np.argmin(keeps, axis=1) + 1  # the corner after the outside one
        order = (first[:, None] + np.arange(corners)[None, :]) % corners
        T = np.take_along_axis(T, order[:, :, None], axis=1)
        D = np.take_along_axis(D, order, axis=1)

        def cross(i: int, j: int, T=T, D=D) -> NDArray:
            """Where edge ``i -> j`` (``i`` inside, ``j`` outside) meets the plane."""
            t = D[:, i] / (D[:, i] - D[:, j])
            return T[:, i] + t[:, None] * (T[:, j] - T[:, i])

        if corners == 2:
            parts.append(np.stack([T[:, 0], cross(0, 1)], axis=1))
        elif keep == 1:
            parts.append(np.stack([T[:, 0], cross(0, 1), cross(0, 2)], axis=1))
        else:  # corners 0 and 1 inside, 2 outside: the quadrilateral 0, 1, x12, x02
            x12, x02 = cross(1, 2), cross(0, 2)
            parts.append(np.stack([T[:, 0], T[:, 1], x12], axis=1))
            parts.append(np.stack([T[:, 0], x12, x02], axis=1))
    return np.concatenate(parts)


def clip_points(corners: NDArray, normal: NDArray, offset: float) -> NDArray:
    """The corners of a convex polytope ``conv(corners)`` cut by ``normal . x <= offset``.

    Every corner of the cut polytope is a kept corner or a crossing of an edge, and every
    edge joins two corners, so the crossings of all corner pairs include them; the hull
    then drops the chords' crossings, which are not corners.
    """
    d = corners @ normal - offset
    keep, drop = corners[d <= 0.0], corners[d > 0.0]
    di, dj = d[d <= 0.0], d[d > 0.0]
    t = di[:, None] / (di[:, None] - dj[None, :])
    crossings = keep[:, None, :] + t[:, :, None] * (drop[None, :, :] - keep[:, None, :])
    points = np.concatenate([keep, crossings.reshape(-1, corners.shape[1])])
    return convex_hull_vertices(points)[0]  # a flat remainder: every point (sound)


@dataclass(frozen=True, eq=False)
class Piece:
    """The part of a solid in one convex cell of the cutting tree.

    Attributes
    ----------
    boundary : ndarray, shape (k, n, n)
        The solid's boundary simplices clipped to the cell.
    corners : ndarray, shape (c, n)
        Corners of the cell, a convex polytope inside the solid's padded bounding box.
    """

    boundary: NDArray[np.float64]
    corners: NDArray[np.float64]

    @classmethod
    def whole(cls, simplices: NDArray) -> Piece:
        """The whole solid in its bounding box, padded by a tenth on every side."""
        V = simplices.reshape(-1, simplices.shape[-1])
        low, high = V.min(axis=0), V.max(axis=0)
        pad = 0.1 * (high - low) + 1e-9 * max(float(np.abs(V).max()), 1.0)
        n = V.shape[1]
        grid = np.array(np.meshgrid(*[[0.0, 1.0]] * n, indexing="ij")).reshape(n, -1).T
        return cls(simplices, (low - pad) + grid * (high - low + 2 * pad))

    def cut(self, normal: NDArray, offset: float) -> Piece:
        """The part of this piece in the halfspace ``normal . x <= offset``."""
        return Piece(
            clip_simplices(self.boundary, normal, offset),
            clip_points(self.corners, normal, offset),
        )

    @property
    def boundary_points(self) -> NDArray[np.float64]:
        """Corners of the clipped boundary simplices, ``(m, n)``: kinds (a)-(c)."""
        return self.boundary.reshape(-1, self.boundary.shape[-1])

    def points(self, solid_boundary: NDArray) -> NDArray[np.float64]:
        """Points whose convex hull contains the piece (see the module docstring).

        Parameters
        ----------
        solid_boundary : ndarray, shape (k, n, n)
            The whole solid's boundary, for the winding numbers of the cell's corners.
        """
        w = winding_numbers(self.corners, solid_boundary)
        inside = self.corners[np.abs(w) > INSIDE_WINDING]
        return np.concatenate([self.boundary_points, inside])
