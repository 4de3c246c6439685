"""Triangle meshes for 3D obstacles: STL (binary or ASCII) and Wavefront OBJ files, and
the triangulated convex hull of a point set (``convex`` obstacles).

Only what FCL needs is read: vertex positions and triangles (OBJ polygons are fanned into
triangles; normals, texture coordinates and materials are ignored). Errors are raised as
``ValueError`` with a message that says what was expected, for the scenario loader to
prefix with the file and field.
"""

from __future__ import annotations

import os
import struct

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull, QhullError

from kcplan.files import atomic_output

__all__ = ["MAX_MESH_BYTES", "MAX_MESH_TRIANGLES", "convex_hull", "read_mesh", "write_stl"]

MAX_MESH_BYTES = 256 * 2**20
"""Largest mesh file read, in bytes (a guard against exhausting memory)."""
MAX_MESH_TRIANGLES = 2_000_000
"""Largest number of triangles accepted in one mesh."""


def read_mesh(path: str | os.PathLike) -> tuple[NDArray[np.float64], NDArray[np.int32]]:
    """Read a triangle mesh.

    Parameters
    ----------
    path : path-like
        An ``.stl`` (binary or ASCII) or ``.obj`` file.

    Returns
    -------
    vertices : ndarray, shape (v, 3)
    triangles : ndarray of int32, shape (t, 3)
        Indices into ``vertices``.
    """
    size = os.path.getsize(path)
    if size > MAX_MESH_BYTES:
        raise ValueError(f"expected a mesh file of at most {MAX_MESH_BYTES} bytes, got {size}")
    suffix = os.fspath(path).lower().rsplit(".", 1)[-1]
    with open(path, "rb") as fh:
        data = fh.read()
    if suffix == "stl":
        vertices, triangles = _parse_stl(data)
    elif suffix == "obj":
        vertices, triangles = _parse_obj(data)
    else:
        raise ValueError(f"expected a .stl or .obj mesh file, got '.{suffix}'")
    if len(triangles) == 0:
        raise ValueError("expected a mesh with at least one triangle, got none")
    if len(triangles) > MAX_MESH_TRIANGLES:
        raise ValueError(f"expected at most {MAX_MESH_TRIANGLES} triangles, got {len(triangles)}")
    if not np.isfinite(vertices).all():
        raise ValueError("expected finite vertex coordinates, got NaN or infinity")
    if triangles.min() < 0 or triangles.max() >= len(vertices):
        raise ValueError("expected triangle indices within the vertex list")
    return vertices, triangles


def _parse_stl(data: bytes) -> tuple[NDArray, NDArray]:
    if len(data) >= 84:
        (count,) = struct.unpack_from("<I", data, 80)
        if len(data) == 84 + 50 * count:  # binary: the size determines the format exactly
            rec = np.frombuffer(
                data,
                dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")]),
                count=count,
                offset=84,
            )
            corners = rec["v"].reshape(-1, 3).astype(float)
            return _merge_corners(corners)
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError:
        raise ValueError("expected a binary or ASCII STL file, got unreadable data") from None
    if not text.lstrip().startswith("solid"):
        raise ValueError("expected a binary or ASCII STL file, got neither")
    corners = []
    for line in text.splitlines():
        words = line.split()
        if words[:1] == ["vertex"]:
            try:
                corners.append([float(w) for w in words[1:4]])
            except ValueError:
                raise ValueError(f"expected 'vertex x y z', got {line.strip()!r}") from None
    if len(corners) % 3:
        raise ValueError("expected 3 vertices per STL facet")
    return _merge_corners(np.array(corners, dtype=float).reshape(-1, 3))


def _merge_corners(corners: NDArray) -> tuple[NDArray, NDArray]:
    vertices, index = np.unique(corners, axis=0, return_inverse=True)
    return vertices, index.reshape(-1, 3).astype(np.int32)


def _parse_obj(data: bytes) -> tuple[NDArray, NDArray]:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError("expected a text OBJ file, got binary data") from None
    vertices, triangles = [], []
    for number, line in enumerate(text.splitlines(), 1):
        words = line.split()
        try:
            if words[:1] == ["v"]:
                vertices.append([float(w) for w in words[1:4]])
            elif words[:1] == ["f"]:
                idx = [int(w.split("/")[0]) for w in words[1:]]
                idx = [i - 1 if i > 0 else len(vertices) + i for i in idx]
                triangles += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
        except (ValueError, IndexError):
            raise ValueError(
                f"expected a valid OBJ line, got line {number}: {line.strip()!r}"
            ) from None
    return np.array(vertices, dtype=float).reshape(-1, 3), np.array(triangles, np.int32).reshape(
        -1, 3
    )


def write_stl(path: str | os.PathLike, vertices: NDArray, triangles: NDArray) -> None:
    """Write a binary STL file atomically (float32 coordinates, as the format stores)."""
    corners = np.asarray(vertices, dtype="<f4")[np.asarray(triangles)]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    rec = np.zeros(
        len(corners), dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    )
    rec["n"], rec["v"] = normals, corners
    with atomic_output(path) as tmp, open(tmp, "wb") as fh:
        fh.write(b"kcplan binary STL".ljust(80, b" "))
        fh.write(struct.pack("<I", len(rec)))
        fh.write(rec.tobytes())


def convex_hull(points: NDArray) -> tuple[NDArray[np.float64], NDArray[np.int32]]:
    """The convex hull of 3D points as its vertices ``(v, 3)`` and outward-oriented
    triangles ``(t, 3)`` indexing them.

    Raises
    ------
    ValueError
        When the points do not span a solid (fewer than 4, or all in one plane).
    """
    P = np.asarray(points, dtype=float)
    try:
        hull = ConvexHull(P)
    except (QhullError, ValueError):
        raise ValueError("expected points spanning a solid (not all in one plane)") from None
    faces = hull.simplices.copy()
    A, B, C = (P[faces[:, k]] for k in range(3))
    inward = np.einsum("fi,fi->f", np.cross(B - A, C - A), hull.equations[:, :3]) < 0
    faces[inward] = faces[inward][:, [0, 2, 1]]
    # keep only the hull's vertices, renumbered
    used, faces = np.unique(faces, return_inverse=True)
    return P[used], faces.reshape(-1, 3).astype(np.int32)
