"""Generated CAD-like test parts: a thick ring, a U-channel (made two ways), a T-profile,
a pipe, and the extruded sections I, H, T, L, Z and C as unions of slabs.

Parts made of a few planar faces or with a hole, on which a greedy cutting tree gets
stuck (issue 26): ``scripts/cover_tightness.py`` measures them beside the real meshes and
``tests/test_cover.py`` holds the fit to its targets on them. The channel and the
T-profile are unions of the cells of a rectilinear grid, so their surfaces are the cells'
outer faces (two triangles each, every edge shared by exactly two of them); the ring and
the pipe are :func:`trimesh.creation.annulus`.

The *sections* (:data:`SECTIONS`) are profiles made of ``k`` rectangles extruded along x:
:data:`SECTION_SLABS` holds each one's slabs (boxes that touch but do not overlap), and
:func:`section` makes it as a CAD tool would, the boolean union of boxes that overlap
where the slabs meet (so its faces are triangulated as the union's engine likes), or as
a grid's faces (:func:`slab_grid`). A cover by ``k`` ellipsoids of such a part need be no
larger than its slabs' own smallest ellipsoids (issue 58, item 5).
"""

from __future__ import annotations

from functools import partial

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "PROFILES",
    "SECTIONS",
    "SECTION_SLABS",
    "grid_solid",
    "pipe",
    "ring",
    "section",
    "slab_grid",
    "slab_union",
    "t_profile",
    "u_channel",
    "u_channel_union",
]


def grid_solid(edges: tuple[ArrayLike, ArrayLike, ArrayLike], filled: ArrayLike) -> trimesh.Trimesh:
    """The union of the filled cells of a rectilinear grid as a closed, outward mesh.

    Parameters
    ----------
    edges : three arrays
        The grid's cell boundaries along x, y and z (increasing), of lengths ``nx + 1``,
        ``ny + 1``, ``nz + 1``.
    filled : array of bool, shape (nx, ny, nz)
        Which cells belong to the part (no two filled cells may touch along an edge only).
    """
    grid = [np.asarray(e, dtype=float) for e in edges]
    full = np.pad(np.asarray(filled, dtype=bool), 1)
    triangles = []
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        lower = np.moveaxis(full, a, 0)
        change = lower[:-1] != lower[1:]  # (face index along a, cells along the others)
        for i, first, second in zip(*np.nonzero(change), strict=True):
            # np.moveaxis keeps the other two axes in increasing order; unpadded cells
            cell = dict(zip(sorted((b, c)), (first - 1, second - 1), strict=True))
            j, k = cell[b], cell[c]
            quad = []
            for db, dc in ((0, 0), (1, 0), (1, 1), (0, 1)):  # counter-clockwise: normal +a
                p = np.empty(3)
                p[a], p[b], p[c] = grid[a][i], grid[b][j + db], grid[c][k + dc]
                quad.append(p)
            if not lower[i, first, second]:  # the filled cell is above the face: normal -a
                quad.reverse()
            triangles += [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
    T = np.array(triangles)
    mesh = trimesh.Trimesh(T.reshape(-1, 3), np.arange(3 * len(T)).reshape(-1, 3))
    mesh.merge_vertices()
    return mesh


def ring() -> trimesh.Trimesh:
    """A thick ring: inner radius 0.25, outer 0.45, height 0.3 (256 triangles)."""
    return trimesh.creation.annulus(r_min=0.25, r_max=0.45, height=0.3, sections=32)


def pipe() -> trimesh.Trimesh:
    """A thin-walled pipe: radii 0.2 and 0.25, length 1 along z (256 triangles)."""
    return trimesh.creation.annulus(r_min=0.2, r_max=0.25, height=1.0, sections=32)


def u_channel() -> trimesh.Trimesh:
    """A U-channel 0.6 long (x): two walls 0.08 x 0.3 at y = +-0.26 on a base 0.6 wide
    and 0.06 thick at z = -0.12."""
    edges = ([-0.3, 0.3], [-0.3, -0.22, 0.22, 0.3], [-0.15, -0.09, 0.15])
    filled = [[[True, True], [True, False], [True, True]]]
    return grid_solid(edges, filled)


def u_channel_union() -> trimesh.Trimesh:
    """The same U-channel as :func:`u_channel`, made as a CAD tool would: the boolean
    union of its three boxes (trimesh's manifold3d engine; ``pip install manifold3d``,
    part of kcplan's ``dev`` extra). The solid is the same to float32 rounding, its faces
    are triangulated otherwise (48 triangles against 44)."""
    base = trimesh.creation.box((0.6, 0.6, 0.06))
    base.apply_translation((0.0, 0.0, -0.12))
    walls = []
    for y in (0.26, -0.26):
        wall = trimesh.creation.box((0.6, 0.08, 0.3))
        wall.apply_translation((0.0, y, 0.0))
        walls.append(wall)
    return trimesh.boolean.union([base, *walls], engine="manifold")


def t_profile() -> trimesh.Trimesh:
    """A T-profile 0.8 long (x): a flange 0.5 x 0.06 on top of a web 0.06 x 0.4."""
    edges = ([-0.4, 0.4], [-0.25, -0.03, 0.03, 0.25], [-0.2, 0.14, 0.2])
    filled = [[[False, True], [True, True], [False, True]]]
    return grid_solid(edges, filled)


def _slabs(length: float, *rectangles: tuple[float, float, float, float]) -> NDArray:
    """Slabs ``(k, 2, 3)`` (low and high corners) of rectangles ``(y0, y1, z0, z1)`` of a
    profile, extruded over ``-length / 2 <= x <= length / 2``."""
    R = np.asarray(rectangles, dtype=float)
    half = np.full(len(R), 0.5 * length)
    low = np.column_stack([-half, R[:, 0], R[:, 2]])
    high = np.column_stack([half, R[:, 1], R[:, 3]])
    return np.stack([low, high], axis=1)


SECTION_SLABS: dict[str, NDArray] = {
    # an I-beam: flanges 0.4 x 0.05 above and below a web 0.04 x 0.4
    "i": _slabs(0.8, (-0.2, 0.2, 0.2, 0.25), (-0.02, 0.02, -0.2, 0.2), (-0.2, 0.2, -0.25, -0.2)),
    # an H: two uprights 0.06 x 0.5 joined at mid-height by a bar 0.38 x 0.05
    "h": _slabs(
        0.8, (-0.25, -0.19, -0.25, 0.25), (-0.19, 0.19, -0.025, 0.025), (0.19, 0.25, -0.25, 0.25)
    ),
    # a T: a flange 0.5 x 0.06 on a web 0.06 x 0.34 (the proportions of t_profile)
    "t": _slabs(0.8, (-0.25, 0.25, 0.14, 0.2), (-0.03, 0.03, -0.2, 0.14)),
    # an unequal angle: a leg 0.4 x 0.05 and, at its end, one 0.05 x 0.25 above it
    "l": _slabs(0.8, (-0.2, 0.2, -0.15, -0.1), (-0.2, -0.15, -0.1, 0.15)),
    # a Z: flanges 0.2 x 0.05 to either side of a web 0.05 x 0.4
    "z": _slabs(
        0.8, (-0.025, 0.2, 0.2, 0.25), (-0.025, 0.025, -0.2, 0.2), (-0.2, 0.025, -0.25, -0.2)
    ),
    # a C: flanges 0.2 x 0.05 on the same side of a web 0.05 x 0.4
    "c": _slabs(
        0.8, (-0.1, 0.15, 0.2, 0.25), (-0.15, -0.1, -0.25, 0.25), (-0.1, 0.15, -0.25, -0.2)
    ),
}
"""The slabs of each section, ``(k, 2, 3)``: the low and high corners of ``k`` boxes that
touch but do not overlap and whose union is the section, metres."""
SECTIONS = tuple(SECTION_SLABS)


def slab_union(slabs: ArrayLike, overlap: float = 0.0) -> trimesh.Trimesh:
    """The boolean union of boxes (trimesh's manifold3d engine, as :func:`u_channel_union`).

    Parameters
    ----------
    slabs : array_like, shape (k, 2, 3)
        Low and high corners of each box.
    overlap : float
        How far a box reaches into a slab whose face it touches over the whole of its own
        face (at most that slab's thickness), as a CAD model's boxes overlap: the union
        is the same, its triangles are not.
    """
    S = np.asarray(slabs, dtype=float)
    boxes = []
    for i, (a, b) in enumerate(S):
        a, b = a.copy(), b.copy()
        for j, (c, d) in enumerate(S):
            for axis in range(3):
                across = [k for k in range(3) if k != axis]
                inside = (c[across] <= a[across]).all() and (b[across] <= d[across]).all()
                if j == i or not inside:
                    continue
                if c[axis] == S[i, 1, axis]:  # j lies beyond the high face
                    b[axis] = S[i, 1, axis] + min(overlap, d[axis] - c[axis])
                if d[axis] == S[i, 0, axis]:  # beyond the low face
                    a[axis] = S[i, 0, axis] - min(overlap, d[axis] - c[axis])
        box = trimesh.creation.box(b - a)
        box.apply_translation(0.5 * (a + b))
        boxes.append(box)
    return trimesh.boolean.union(boxes, engine="manifold")


def slab_grid(slabs: ArrayLike) -> trimesh.Trimesh:
    """The union of axis-aligned boxes ``(k, 2, 3)`` as a grid's faces (:func:`grid_solid`
    on the grid of their corners)."""
    S = np.asarray(slabs, dtype=float)
    edges = [np.unique(S[:, :, a]) for a in range(3)]
    mid = np.meshgrid(*[0.5 * (e[1:] + e[:-1]) for e in edges], indexing="ij")
    centre = np.stack(mid, axis=-1)  # (nx, ny, nz, 3): each cell's centre
    filled = np.zeros(centre.shape[:3], dtype=bool)
    for a, b in S:
        filled |= ((centre > a) & (centre < b)).all(axis=-1)
    return grid_solid(tuple(edges), filled)


def section(name: str, union: bool = True) -> trimesh.Trimesh:
    """The section ``name`` (one of :data:`SECTIONS`) as the boolean union of its boxes
    grown by 0.02 into their neighbours (:func:`slab_union`), or as a grid's faces."""
    slabs = SECTION_SLABS[name]
    return slab_union(slabs, overlap=0.02) if union else slab_grid(slabs)


PROFILES = {
    "ring": ring,
    "u_channel": u_channel,
    "u_channel_union": u_channel_union,
    "t_profile": t_profile,
    "pipe": pipe,
    **{f"{name}_section": partial(section, name) for name in SECTIONS},
}
"""The generated parts by name."""
