"""Where a part's features lie: the curvature measure of its surface, and its quantiles.

A cover's cutting planes are best placed where the part's shape changes: at a box's
edges, a housing's rim, the fillet between a wall and a base. The *curvature measure* of
a closed triangle mesh says where that is: each edge between two faces carries its
length times the angle between the faces' normals (the discrete total mean curvature,
up to a factor 2), spread evenly along the edge; an outline's corner carries its turning
angle. It is a property of the surface, not of its triangulation: an edge inside a flat
face carries nothing, and an edge split in two carries what it carried before. The fit
(:mod:`kcplan.cover.fit`) takes its candidate cuts at quantiles of this measure along a
direction, so the same part triangulated otherwise (a CAD export, a boolean union) gets
the same candidates, where quantiles of the mesh's vertices would follow its
triangulation (issue 41: a U-channel made by a boolean union of three boxes got 3.48
times its volume at four bodies, the same channel as a grid's faces 2.38).

:func:`quantiles_along` also gives the quantiles of a surface's area, which is as free of
the triangulation, for a piece that holds no features.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.cover.solid import Solid

__all__ = ["clip_segments", "feature_segments", "quantiles_along", "simplex_normals"]


def simplex_normals(simplices: NDArray) -> tuple[NDArray, NDArray]:
    """Normals of simplices and their measures.

    Parameters
    ----------
    simplices : ndarray, shape (k, n, n)
        Triangles in 3D or segments in 2D.

    Returns
    -------
    normals : ndarray, shape (k, n)
        Not unit: a triangle's edge cross product, a segment's direction turned by -90
        degrees (outward for a counter-clockwise outline).
    measures : ndarray, shape (k,)
        Areas (lengths, in 2D).
    """
    d = simplices[:, 1] - simplices[:, 0]
    if simplices.shape[-1] == 3:
        normal = np.cross(d, simplices[:, 2] - simplices[:, 0])
        return normal, 0.5 * np.linalg.norm(normal, axis=1)
    normal = np.stack([d[:, 1], -d[:, 0]], axis=1)
    return normal, np.linalg.norm(normal, axis=1)


def feature_segments(solid: Solid) -> tuple[NDArray, NDArray]:
    """The part's curvature measure as weighted segments (see the module docstring).

    Returns
    -------
    segments : ndarray, shape (m, 2, n)
        A 3D mesh's edges between two faces (trimesh's face adjacency; an edge of a
        non-manifold or open mesh that borders one face only carries nothing); a 2D
        outline's corners, as segments of length zero.
    weights : ndarray, shape (m,)
        Radians: the angle between the two faces' normals (per unit of the edge's
        length), or the outline's turning angle at the corner.
    """
    if solid.dimension == 3:
        import trimesh  # imported where used (kcplan.cover.fit's import cost)

        mesh = trimesh.Trimesh(solid.vertices, solid.faces, process=False)
        segments = np.asarray(mesh.vertices)[mesh.face_adjacency_edges]
        return segments, np.asarray(mesh.face_adjacency_angles, dtype=float)
    edges = solid.boundary  # (k, 2, 2), counter-clockwise: corner i ends edge i - 1
    d = edges[:, 1] - edges[:, 0]
    before = np.roll(d, 1, axis=0)
    turn = np.arctan2(before[:, 0] * d[:, 1] - before[:, 1] * d[:, 0], (before * d).sum(1))
    return np.stack([edges[:, 0], edges[:, 0]], axis=1), np.abs(turn)


def clip_segments(
    segments: NDArray, weights: NDArray, halfspaces: NDArray
) -> tuple[NDArray, NDArray]:
    """The parts of weighted segments inside a convex polytope.

    Parameters
    ----------
    segments : ndarray, shape (m, 2, n)
    weights : ndarray, shape (m,)
        Per unit length; a segment of length zero carries its weight as it is.
    halfspaces : ndarray, shape (h, n + 1)
        The polytope ``{x : A x + b <= 0}`` as rows ``[A, b]`` (qhull's ``equations``).

    Returns
    -------
    segments : ndarray, shape (k, 2, n)
        The parts inside (on the boundary counts as inside).
    measures : ndarray, shape (k,)
        Weight times the length inside, or the weight of a point inside.
    """
    p, q = segments[:, 0], segments[:, 1]
    lo, hi = np.zeros(len(segments)), np.ones(len(segments))
    for row in halfspaces:
        d0, d1 = p @ row[:-1] + row[-1], q @ row[:-1] + row[-1]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = d0 / (d0 - d1)  # where the segment crosses the plane
        lo = np.where((d0 > 0) & (d1 <= 0), np.maximum(lo, t), lo)
        hi = np.where((d0 <= 0) & (d1 > 0), np.minimum(hi, t), hi)
        hi = np.where((d0 > 0) & (d1 > 0), -1.0, hi)
    keep = hi >= lo
    length = np.linalg.norm(q - p, axis=1)
    measure = np.where(length > 0, weights * length * (hi - lo), weights)
    clipped = np.stack([p + lo[:, None] * (q - p), p + hi[:, None] * (q - p)], axis=1)
    return clipped[keep], measure[keep]


def quantiles_along(
    simplices: NDArray, direction: NDArray, levels: ArrayLike, measures: NDArray | None = None
) -> NDArray:
    """Where the planes ``direction . x = t`` leave a share ``levels`` of a measure on
    simplices on their lower side.

    A segment's measure is spread evenly along it; a triangle's, its area, as a tent:
    with its corners at ``a <= b <= c`` along ``direction``, the share below ``t`` is
    ``(t - a)^2 / ((c - a)(b - a))`` up to ``b`` and ``1 - (c - t)^2 / ((c - a)(c - b))``
    after; a simplex across ``direction`` puts all of it at one ``t``. The total below
    ``t`` increases with ``t``; each quantile is found by bisection to ``2^-40`` of the
    simplices' extent along ``direction``.

    Parameters
    ----------
    simplices : ndarray, shape (k, c, n)
        Segments (``c = 2``) or triangles (``c = 3``) in ``n`` dimensions.
    direction : ndarray, shape (n,)
    levels : array_like, shape (m,)
        Shares in ``[0, 1]``.
    measures : ndarray, shape (k,), optional
        The simplices' measures (default: their areas, or lengths: the simplices must
        then be ``n``-cornered, the boundary of an ``n``-dimensional solid).

    Returns
    -------
    ndarray, shape (m,)
    """
    x = np.sort(simplices @ direction, axis=1)  # each simplex's corners along direction
    if measures is None:
        measures = simplex_normals(simplices)[1]
    want = np.asarray(levels, dtype=float) * measures.sum()
    lo, hi = np.full(len(want), x.min()), np.full(len(want), x.max())
    a, c = x[:, :1], x[:, -1:]
    across = c - a > 0  # else a point along direction: a step at a

    def below(t: NDArray) -> NDArray:  # (m,) -> (m,)
        t = t[None, :]
        with np.errstate(divide="ignore", invalid="ignore"):
            if simplices.shape[1] == 3:
                b = x[:, 1:2]
                rise = (np.clip(t, a, b) - a) ** 2 / ((c - a) * (b - a))
                fall = (c - np.clip(t, b, c)) ** 2 / ((c - a) * (c - b))
                share = np.where(t < b, np.nan_to_num(rise), 1.0 - np.nan_to_num(fall))
            else:
                share = np.clip((t - a) / (c - a), 0.0, 1.0)
        share = np.where(across, share, (t >= a).astype(float))
        return measures @ share

    for _ in range(40):
        mid = 0.5 * (lo + hi)
        short = below(mid) < want
        lo, hi = np.where(short, mid, lo), np.where(short, hi, mid)
    return 0.5 * (lo + hi)
