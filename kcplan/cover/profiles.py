"""Generated CAD-like test parts: a thick ring, a U-channel (made two ways), a T-profile
and a pipe.

Parts made of a few planar faces or with a hole, on which a greedy cutting tree gets
stuck (issue 26): ``scripts/cover_tightness.py`` measures them beside the real meshes and
``tests/test_cover.py`` holds the fit to its targets on them. The channel and the
T-profile are unions of the cells of a rectilinear grid, so their surfaces are the cells'
outer faces (two triangles each, every edge shared by exactly two of them); the ring and
the pipe are :func:`trimesh.creation.annulus`.
"""

from __future__ import annotations

import numpy as np
import trimesh
from numpy.typing import ArrayLike

__all__ = ["PROFILES", "grid_solid", "pipe", "ring", "t_profile", "u_channel", "u_channel_union"]


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


PROFILES = {
    "ring": ring,
    "u_channel": u_channel,
    "u_channel_union": u_channel_union,
    "t_profile": t_profile,
    "pipe": pipe,
}
"""The generated parts by name."""
