"""The part to cover: a closed triangle mesh (3D) or a simple polygon (2D).

Meshes are read with trimesh (STL, OBJ, PLY, OFF, glTF/GLB; a scene's meshes are joined),
outlines from YAML (a list of ``[x, y]``, or ``{vertices: [...]}``) or CSV (``x,y`` rows,
a header line allowed). The solid is the input's own geometry: vertices are merged only
where they are bit-for-bit equal (trimesh's default processing merges within ``1e-8``,
which moves the surface), and faces are only reoriented, never moved. One exception: a
mesh that is open only because some of its corners differ by rounding (exported CAD
parts, whose coordinates near 0 read as ``-1e-17`` in one triangle and ``3e-18`` in the
next) is welded within :data:`WELD_TOLERANCE` of its size; ``Solid.weld`` is how far a
corner moved, and a cover of the welded solid is grown by it (:func:`kcplan.cover.fit_cover`).

Errors are :class:`SolidError` with one line naming the file and what was expected.
"""

from __future__ import annotations

import csv
import hashlib
import io
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml
from numpy.typing import NDArray

from kcplan.files import load_yaml
from kcplan.geometry.polygon import polygon_area, simple_polygon

__all__ = ["MESH_SUFFIXES", "OUTLINE_SUFFIXES", "Solid", "SolidError", "read_solid"]

MESH_SUFFIXES = (".stl", ".obj", ".ply", ".off", ".glb", ".gltf")
OUTLINE_SUFFIXES = (".yaml", ".yml", ".csv")
MAX_SOLID_BYTES = 256 * 2**20
"""Largest input file read, in bytes."""
MAX_OUTLINE_VERTICES = 10_000
WELD_TOLERANCE = 1e-9
"""Corners of an open mesh closer than this times the mesh's size are welded into one."""


class SolidError(ValueError):
    """A part that cannot be covered; ``str(err)`` is ``FILE: expected ..., got ...``."""


@dataclass(frozen=True, eq=False)
class Solid:
    """A closed part in its own frame, in the file's unit times ``scale``.

    Attributes
    ----------
    boundary : ndarray, shape (k, n, n)
        Oriented boundary simplices: outward triangles ``(k, 3, 3)`` or the polygon's
        counter-clockwise edges ``(k, 2, 2)``.
    volume : float
        Volume (area in 2D) of the part.
    vertices : ndarray, shape (v, n)
        For plots: the mesh's vertices or the polygon in order.
    faces : ndarray of int, shape (k, 3) or (0, 3)
        For plots: the mesh's triangles (empty in 2D).
    source : str
        The file it came from.
    digest : str
        SHA-256 of the file's bytes and, for meshes, of the triangles read (the cover
        cache's key; a glTF's buffers may live in other files).
    hull : bool
        True when the part is the convex hull of the file's mesh (``--hull``).
    weld : float
        The largest distance a corner of the file's mesh moved when near corners were
        welded (0 when none were): each point of the file's triangles lies within ``weld``
        of the solid, so a cover of the solid whose bodies grow by ``weld`` covers them.
    """

    boundary: NDArray[np.float64]
    volume: float
    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    source: str
    digest: str
    hull: bool = False
    weld: float = 0.0

    @property
    def dimension(self) -> int:
        return int(self.boundary.shape[-1])

    @property
    def size(self) -> float:
        """The largest side of the part's bounding box."""
        return float(np.ptp(self.vertices, axis=0).max())

    def describe(self) -> str:
        """``hand.stl (200 triangles)`` or ``slot.yaml (12-gon)``."""
        name = Path(self.source).name
        if self.dimension == 2:
            return f"{name} ({len(self.boundary)}-gon)"
        what = "convex hull of " if self.hull else ""
        return f"{what}{name} ({len(self.boundary)} triangles)"


def read_solid(path: str | os.PathLike, scale: float = 1.0, hull: bool = False) -> Solid:
    """Read a part: a mesh by its suffix (:data:`MESH_SUFFIXES`) or a 2D outline
    (:data:`OUTLINE_SUFFIXES`).

    Parameters
    ----------
    path : path-like
    scale : float
        Multiplies every coordinate (e.g. 0.001 for a mesh in millimetres).
    hull : bool
        Cover the convex hull of the mesh instead of the mesh: the documented fallback
        for meshes that are not closed (a superset of any part the mesh bounds).

    Raises
    ------
    SolidError
    """
    source = os.fspath(path)
    p = Path(path)
    if not (np.isfinite(scale) and scale > 0):
        raise SolidError(f"{source}: scale: expected a positive number, got {scale!r}")
    suffix = p.suffix.lower()
    if suffix not in MESH_SUFFIXES + OUTLINE_SUFFIXES:
        raise SolidError(
            f"{source}: expected a mesh ({', '.join(MESH_SUFFIXES)}) or a 2D outline "
            f"({', '.join(OUTLINE_SUFFIXES)}), got {suffix or 'no suffix'!r}"
        )
    try:
        size = p.stat().st_size
        if size > MAX_SOLID_BYTES:
            raise SolidError(f"{source}: expected at most {MAX_SOLID_BYTES} bytes, got {size}")
        data = p.read_bytes()
    except OSError as err:
        raise SolidError(f"{source}: cannot read the file: {err.strerror or err}") from None
    digest = hashlib.sha256(data).hexdigest()
    if suffix in OUTLINE_SUFFIXES:
        if hull:
            raise SolidError(f"{source}: --hull: expected a mesh, got a 2D outline")
        return _outline(source, data, suffix, scale, digest)
    return _mesh(source, suffix, scale, digest, hull)


def _mesh(source: str, suffix: str, scale: float, digest: str, hull: bool) -> Solid:
    import trimesh

    try:
        # from the path, not the bytes: a .gltf's buffers may lie beside it
        loaded = trimesh.load(source, force="mesh", process=False)
    except Exception as err:  # trimesh raises many kinds on malformed files
        reason = str(err).splitlines()[0][:120] if str(err) else type(err).__name__
        raise SolidError(f"{source}: expected a readable {suffix} mesh, got: {reason}") from None
    V = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=float)
    F = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.int64)
    if len(F) == 0 or V.ndim != 2 or V.shape[1] != 3:
        raise SolidError(f"{source}: expected a mesh with triangles, got none")
    if not np.isfinite(V).all():
        raise SolidError(f"{source}: expected finite vertex coordinates, got NaN or infinity")
    # merge bit-identical vertices only, so edges are shared without moving the surface
    V, index = np.unique(V * scale, axis=0, return_inverse=True)
    F = index.reshape(-1)[F]
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])]
    mesh = trimesh.Trimesh(V, F, process=False)
    weld = 0.0
    if not hull and not mesh.is_watertight:
        welded = _welded(V, F, WELD_TOLERANCE * float(np.ptp(V, axis=0).max()))
        if welded is not None and welded[0].is_watertight:
            mesh, weld = welded
    if hull:
        try:
            mesh = mesh.convex_hull
        except Exception:
            raise SolidError(f"{source}: expected a mesh spanning a solid, got a flat one") from (
                None
            )
    elif not mesh.is_watertight:
        _, counts = np.unique(mesh.edges_sorted, axis=0, return_counts=True)
        open_edges, shared = int((counts == 1).sum()), int((counts > 2).sum())
        raise SolidError(
            f"{source}: expected a closed (watertight) mesh, got one with {open_edges} open "
            f"edges and {shared} edges shared by more than two triangles; "
            "pass --hull to cover its convex hull instead"
        )
    if not mesh.is_winding_consistent:
        trimesh.repair.fix_winding(mesh)  # reorders corners only
    with np.errstate(invalid="ignore", divide="ignore"):  # trimesh divides by a 0 volume
        volume = float(mesh.volume)
    if volume < 0:
        mesh.invert()
        volume = -volume
    if not volume > 1e-12 * mesh.extents.max() ** 3:
        raise SolidError(f"{source}: expected a mesh with volume, got volume {volume:.3g}")
    triangles = mesh.vertices[mesh.faces]
    # the geometry too: a .gltf's buffers live in other files than the one hashed
    digest = hashlib.sha256(digest.encode() + triangles.tobytes()).hexdigest()
    return Solid(
        triangles, volume, mesh.vertices.copy(), mesh.faces.copy(), source, digest, hull, weld
    )


def _welded(V: NDArray, F: NDArray, tolerance: float):
    """``(mesh, moved)``: the mesh with corners closer than ``tolerance`` merged into the
    first of their cluster, and the largest distance a corner moved; ``None`` when no
    corners are that close or when a triangle would lose a corner (its points would then
    not be within ``moved`` of the welded surface)."""
    import trimesh
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pairs = cKDTree(V).query_pairs(tolerance, output_type="ndarray")
    if len(pairs) == 0:
        return None
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(V),) * 2)
    _, label = connected_components(graph, directed=False)
    first = np.full(label.max() + 1, len(V))
    np.minimum.at(first, label, np.arange(len(V)))
    target = first[label]  # each corner's representative, a corner of the file
    G = target[F]
    if ((G[:, 0] == G[:, 1]) | (G[:, 1] == G[:, 2]) | (G[:, 0] == G[:, 2])).any():
        return None
    moved = float(np.linalg.norm(V - V[target], axis=1).max())
    kept, index = np.unique(target, return_inverse=True)
    return trimesh.Trimesh(V[kept], index[F], process=False), moved


def _outline(source: str, data: bytes, suffix: str, scale: float, digest: str) -> Solid:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise SolidError(f"{source}: expected a text outline, got binary data") from None
    if suffix == ".csv":
        rows = [r for r in csv.reader(io.StringIO(text)) if r and any(c.strip() for c in r)]
        if rows and not _is_number(rows[0][0]):
            rows = rows[1:]  # a header line
        values = rows
    else:
        try:
            values = load_yaml(text)
        except yaml.YAMLError:
            raise SolidError(f"{source}: expected a YAML list of [x, y] vertices") from None
        if isinstance(values, dict) and set(values) == {"vertices"}:
            values = values["vertices"]
    try:
        P = np.array(values, dtype=float)
    except (TypeError, ValueError):
        P = np.zeros((0, 0))
    if P.ndim != 2 or P.shape[1] != 2 or not 3 <= len(P) <= MAX_OUTLINE_VERTICES:
        raise SolidError(
            f"{source}: vertices: expected 3 to {MAX_OUTLINE_VERTICES} points [x, y] "
            "(a YAML list, {vertices: [...]}, or CSV rows x,y)"
        )
    if not np.isfinite(P).all():
        raise SolidError(f"{source}: vertices: expected finite numbers, got NaN or infinity")
    try:
        polygon = simple_polygon(P * scale)
    except ValueError as err:
        raise SolidError(f"{source}: vertices: {err}") from None
    edges = np.stack([polygon, np.roll(polygon, -1, axis=0)], axis=1)
    return Solid(edges, polygon_area(polygon), polygon, np.zeros((0, 3), np.int64), source, digest)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True
