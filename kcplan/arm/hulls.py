"""A link's own convex geometry: the convex hull of its collision mesh, or of a primitive.

Almost every collision mesh of an arm is convex (the MotionBenchMaker Panda's links all
are, up to the open link6, whose vertices' hull contains it; a mobile manipulator's 22 of
24; ``../shared/docs/design.md`` Sec. 10). Such a link is represented *exactly* by its
hull, one coal convex shape, where an ellipsoid cover needs dozens of bodies and still
sticks out by centimetres. A non-convex link is represented by the hull of its vertices,
which contains it (every point of a triangle is a convex combination of its corners):
sound, and as tight as one convex body can be; where that hull exceeds the link by more
than a mean gap of :data:`MAX_GAP`, the link is cut by planes into pieces, each
represented by its own hull (:func:`hull_pieces`).

The hull is computed by qhull (through trimesh) and then *proved* to hold every vertex of
the mesh: ``delta``, the largest amount by which a mesh vertex lies outside a hull face
(rounding in qhull, ~1e-16 m), is measured, plus a ``slack`` for points known only to
within it (Pinocchio reads meshes in single precision), and where that is positive the
hull is grown
about the mean ``c`` of its vertices (strictly inside it) by ``1 + 2 delta / rho``
(``rho`` the smallest distance from ``c`` to a face plane): each face plane ``n . x <= h``
then moves outward by ``2 delta (h - n . c) / rho >= 2 delta``, so no vertex is outside
any more (the factor 2 leaves room for the growth's own rounding).

A body's frame is centred on the smallest ball around its hull (trimesh's
``minimum_nsphere``), with the axes of the geometry's frame, and its bounding radius is
the largest distance of a hull vertex from that centre. Every speed bound of
:mod:`kcplan.arm.bounds` holds for the ball, hence for the hull inside it.

This module computes hulls of given points (and caches them); it imports neither OMPL nor
FCL.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "CYLINDER_SIDES",
    "HULL_VERSION",
    "MAX_GAP",
    "MAX_PIECES",
    "BodyHull",
    "box_hull",
    "cached_hull_pieces",
    "cylinder_hull",
    "hull_pieces",
    "points_hull",
]

HULL_VERSION = 2
"""Bumped whenever :func:`hull_pieces` would compute other hulls: the cache's key has it."""

MAX_PIECES = 4
"""Hull pieces a non-convex link is cut into at most (:func:`hull_pieces`)."""

MAX_GAP = 0.0025
"""A closed link is cut while its pieces' hulls exceed it by a mean gap above this, in
metres: the volume they add over the link's, over the area of the link's hull (the mean
thickness of the shell between them). The MBM UR5's upper arm (hull 1.46 times its
volume) has a mean gap of 9.3 mm, its forearm (1.55) 8.0 mm: both are cut; its base
(1.18) 1.4 mm, shoulder and wrists 0.7-1.2 mm and the Robotiq's finger parts (1.6-2.5
times their volume, but 3 cm long) 1.7-2.4 mm stay whole: every piece is a body more,
and a self pair more for each body it may touch. The Panda's links are convex (0 mm)."""

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


def points_hull(
    points: NDArray[np.float64], slack: float = 0.0
) -> tuple[NDArray[np.float64], BodyHull]:
    """The convex hull of ``points`` ``(p, 3)`` (metres, some frame ``F``), proved to hold
    each of them, and every point within ``slack`` (metres) of one: points known to
    that precision only (a mesh Pinocchio read through assimp in single precision).

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
    try:
        centre = np.asarray(trimesh.nsphere.minimum_nsphere(hull.vertices)[0], dtype=float)
    except Exception:  # qhull inside it, on a nearly flat hull: any interior centre serves
        centre = np.asarray(hull.vertices, dtype=float).mean(axis=0)
    vertices = hull.vertices - centre
    # the faces' planes from their own corners: trimesh merges points closer than its
    # tolerance, which can leave triangles with a repeated corner (no face) and report
    # the normal of a thin face rounded (a merged point outside its true plane would
    # pass); the proof below needs the true planes of the faces that remain
    faces = np.asarray(hull.faces, dtype=np.int64)
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])
                  & (faces[:, 0] != faces[:, 2])]  # fmt: skip
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    normals = np.cross(b - a, c - a)
    lengths = np.linalg.norm(normals, axis=1)
    faces, normals = faces[lengths > 0], normals[lengths > 0] / lengths[lengths > 0, None]
    heights = np.einsum("ij,ij->i", normals, vertices[faces[:, 0]])
    delta = float(slack)  # in blocks: 130,000 vertices against 8,000 faces at once is 8 GB
    block = max(1, 4_000_000 // len(normals))
    for start in range(0, len(points), block):
        local = points[start : start + block] - centre
        delta = max(delta, float((local @ normals.T - heights).max()) + slack)
    if delta > 0.0:  # grown about the vertices' mean, strictly inside the hull
        inner = vertices.mean(axis=0)
        rho = float((heights - normals @ inner).min())
        if not rho > 0.0:
            raise ValueError("expected points that span a volume, got a degenerate hull")
        vertices = inner + (vertices - inner) * (1.0 + 2.0 * delta / rho)  # 2: its rounding
    radius = float(np.linalg.norm(vertices, axis=1).max()) * (1.0 + 1e-12)
    hull_out = BodyHull(np.ascontiguousarray(vertices), faces, radius, delta)
    return centre, hull_out


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


def hull_pieces(
    vertices: NDArray[np.float64],
    triangles: NDArray[np.int64],
    max_pieces: int = MAX_PIECES,
    max_gap: float = MAX_GAP,
    slack: float = 0.0,
) -> list[tuple[NDArray[np.float64], BodyHull]]:
    """A link's mesh as :func:`points_hull` pieces whose union contains it: one hull for an
    open mesh or one whose hull's mean gap to it (:data:`MAX_GAP`) is at most ``max_gap``
    (metres), else the fewest pieces (up to ``max_pieces``) whose hulls' mean gap is.

    Each cut is a plane across one piece, chosen among planes normal to the piece's
    principal axes (at 1/8 to 7/8 of its extent) and among the pieces as the one that
    takes the most hull volume away. Why the union contains the link: a plane splits the
    solid ``S`` bounded by a piece of surface into ``S+`` and ``S-``; the boundary of
    ``S+`` is the surface on its side and the section, a planar region whose boundary is
    the cut's polyline, whose points are vertices of the sliced surface (trimesh's
    ``slice_plane`` adds them). So ``S+`` lies in the hull of the vertices of the surface
    on its side, which :func:`points_hull` holds; and every point of ``S`` is in ``S+``
    or ``S-``. The vertices of the link are checked to lie in the union as well.

    Parameters
    ----------
    vertices : ndarray, shape (v, 3)
    triangles : ndarray of int, shape (t, 3)
    slack : float
        How far (metres) the true vertices may lie from these (:func:`points_hull`).

    Returns
    -------
    list of (centre, BodyHull)
        As :func:`points_hull` returns them, centres in the mesh's frame.
    """
    import trimesh

    mesh = trimesh.Trimesh(np.asarray(vertices, float), np.asarray(triangles), process=True)
    if not (mesh.is_volume and mesh.volume > 0.0) or max_pieces < 2:
        return [points_hull(np.asarray(vertices, dtype=float), slack)]  # open: its hull holds it
    goal = mesh.volume + max_gap * mesh.convex_hull.area  # the hulls' volume to get under
    # pieces as surfaces (vertices, triangles): after a cut only their vertices matter
    pieces = [(np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces))]
    volumes = [_hull_volume(pieces[0][0])]
    cuts: list = [None]
    while len(pieces) < max_pieces and sum(volumes) > goal:
        for k, piece in enumerate(pieces):
            if cuts[k] is None:
                cuts[k] = _best_cut(*piece) or ([], np.inf)
        gains = [volumes[k] - cuts[k][1] for k in range(len(pieces))]
        k = int(np.argmax(gains))
        if not gains[k] > 0.0:  # no plane takes hull volume away
            break
        halves, _ = cuts[k]
        pieces[k : k + 1] = halves
        volumes[k : k + 1] = [_hull_volume(h[0]) for h in halves]
        cuts[k : k + 1] = [None, None]
    out = [points_hull(points, slack) for points, _ in pieces]
    if len(out) > 1:  # the proof's premise, checked: each vertex of the link in a piece
        _check_cover(np.asarray(vertices, dtype=float), out)
    return out


def _hull_volume(points: NDArray[np.float64]) -> float:
    """The volume of the points' hull (0 for a flat set)."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        return float(ConvexHull(points).volume)
    except (QhullError, ValueError):
        return 0.0


def _best_cut(points: NDArray[np.float64], faces: NDArray[np.int64]) -> tuple[list, float] | None:
    """The two halves ``(vertices, triangles)`` of a surface across the plane of least
    total hull volume (see :func:`hull_pieces`), and that volume; None when no plane cuts
    it (trimesh's ``slice_faces_plane`` keeps the side ``n . (x - origin) >= 0`` and adds
    the vertices where the plane crosses an edge)."""
    from trimesh.intersections import slice_faces_plane

    centre = points.mean(axis=0)
    _, _, axes = np.linalg.svd(points - centre, full_matrices=False)
    best = None
    for normal in axes:
        heights = (points - centre) @ normal
        for fraction in np.arange(1, 8) / 8.0:
            origin = centre + normal * (heights.min() + fraction * np.ptp(heights))
            halves = []
            for sign in (1.0, -1.0):
                V, F = slice_faces_plane(points, faces, sign * normal, origin)[:2]
                used = np.unique(F)  # only the vertices of the kept side's triangles
                if len(used) < 4:
                    break
                remap = np.zeros(len(V), dtype=np.int64)
                remap[used] = np.arange(len(used))
                halves.append((np.asarray(V, dtype=float)[used], remap[F]))
            if len(halves) < 2:
                continue
            volume = sum(_hull_volume(h[0]) for h in halves)
            if best is None or volume < best[1]:
                best = (halves, volume)
    return best


def _check_cover(points: NDArray[np.float64], pieces: list) -> None:
    """Raise ValueError unless every point lies in some piece's hull."""
    inside = np.zeros(len(points), dtype=bool)
    for centre, hull in pieces:
        a, b, c = (hull.vertices[hull.triangles[:, i]] for i in range(3))
        n = np.cross(b - a, c - a)
        n /= np.linalg.norm(n, axis=1)[:, None]
        h = np.einsum("ij,ij->i", n, a)
        inside |= ((points - centre) @ n.T - h <= 0.0).all(axis=1)
    if not inside.all():
        raise ValueError(f"{int((~inside).sum())} vertices outside every hull piece")


def cached_hull_pieces(
    vertices: NDArray[np.float64], triangles: NDArray[np.int64], slack: float = 0.0
) -> tuple[list[tuple[NDArray[np.float64], BodyHull]], bool]:
    """:func:`hull_pieces` of a mesh, kept in the per-user cache of covers
    (:func:`kcplan.cover.cache.cache_folder`, subfolder ``hulls``), keyed by the mesh's
    exact numbers, ``slack``, :data:`MAX_PIECES`, :data:`MAX_GAP` and
    :data:`HULL_VERSION`: a large mesh's hull (the UR5's force sensor, 21,758 vertices:
    about 2 s) is proved once per machine. Also returns whether it came from the cache. A
    cache that cannot be read or written is skipped."""
    import hashlib

    from kcplan.cover.cache import cache_folder
    from kcplan.files import atomic_output

    vertices = np.ascontiguousarray(vertices, dtype=float)
    triangles = np.ascontiguousarray(triangles, dtype=np.int64)
    digest = hashlib.sha256(vertices.tobytes() + triangles.tobytes())
    digest.update(repr((float(slack), MAX_PIECES, MAX_GAP, HULL_VERSION)).encode())
    path = cache_folder() / "hulls" / f"{digest.hexdigest()}.npz"
    try:
        with np.load(path) as data:
            count = int(data["count"])
            return [
                (data[f"centre{k}"], BodyHull(data[f"vertices{k}"], data[f"triangles{k}"],
                                              float(data[f"radius{k}"]), float(data[f"offset{k}"])))
                for k in range(count)
            ], True  # fmt: skip
    except (OSError, KeyError, ValueError):
        pass
    pieces = hull_pieces(vertices, triangles, slack=slack)
    arrays: dict = {"count": len(pieces)}
    for k, (centre, hull) in enumerate(pieces):
        arrays |= {f"centre{k}": centre, f"vertices{k}": hull.vertices,
                   f"triangles{k}": hull.triangles, f"radius{k}": hull.radius,
                   f"offset{k}": hull.offset}  # fmt: skip
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_output(path) as tmp, open(tmp, "wb") as f:
            np.savez(f, **arrays)
    except OSError:
        pass
    return pieces, False
