"""Sound covers of a part by K ellipsoids (or K spheres, for comparison).

The fit grows a binary tree of cutting planes (:mod:`kcplan.cover.partition`). Each leaf
is a piece of the part with the smallest ellipsoid that holds the piece's hull points
(Khachiyan's approximation, :func:`kcplan.geometry.enclosing.minimum_volume_ellipsoid`,
then scaled until every point is inside). Starting from the whole part, the fit splits,
one leaf at a time, the piece whose best cut shrinks the union of the ellipsoids most,
until there are ``bodies`` leaves, or until the bodies' total volume is within
``1 + max_excess`` of the part's (the total bounds the union's volume from above).

*Candidate cuts* of a piece are planes across the axes of its ellipsoid and of the part's
frame, at seven quantiles along each of the part's curvature measure in the piece's cell
(its edges weighted by their dihedral angles, :mod:`kcplan.cover.features`: where the
shape changes, whatever its triangulation), and the planes of the part's largest planar
faces (coplanar triangles grouped, at most eight that cross the piece). A candidate is
scored by the union's volume on a fixed quasi-random sample (the same points for every
candidate, so comparisons are free of sampling noise), with the children fitted to their
clipped boundary points only; the chosen children are then fitted to their full hull
points (cell corners inside the part included), which is what makes the cover sound.

*Beyond one greedy cut.* When no single cut makes the union smaller, the best three cuts
of each leaf are tried as the first of a *sequence of two* (their children fitted as if
chosen, then the best single cut of any leaf): a ring's half needs its other half cut
too before the union shrinks. The fit stops early only when no such sequence helps, and
says so in :attr:`Cover.note`. The tree is grown twice, once with the candidates above
and once adding *planes through the axes* of the part's ellipsoid (through its centre,
every 30 degrees about each axis: a hole's axis is one of them), and the smaller union
is kept: the extra planes help some parts and mislead the greedy choice on others. A
third tree starts from the part cut into an even number of *equal sectors* about one of
those axes (4, 6, ... up to ``bodies``; the best, if its union is smaller than the
others reached with as many leaves) and is grown from there; a ring or a pipe, whose
first greedy cut makes two flat rings, is cut into sectors this way. *Two more trees*
(:data:`VERTEX_CUTS`) are grown as the first two but with their cuts at quantiles of the
mesh's clipped triangle corners (the fit before :data:`FIT_VERSION` 3; without the
sequences of two cuts, which cost a ring's fit twice its time there), and the smallest
union of all is kept: those cuts follow the triangulation, but as extra trees they can
only make the cover smaller, never larger, than the curvature's trees make it alone; a
greedy tree's outcome is partly luck, and on some CAD meshes theirs is the better one.
Every tree is a tree of planes whose leaves are fitted to their full hull points, so each
is sound.

*Reflex pieces* (:data:`PIECES`, with ``bodies``). A part whose reflex (concave) edges
all lie on a few planes of its faces (:func:`_reflex_planes`: an extruded I, H, T, L, Z
or C section, a U-channel, any union of slabs) is cut along those planes, moved a hair
off their faces, into the pieces with no reflex edge inside, at most ``bodies`` of them,
whose ellipsoids' total volume is the smallest (an exact search over those planes,
:meth:`_Search.pieces`): for a union of ``k <= bodies`` slabs, at most its slabs' own
smallest ellipsoids. That total is then a *ceiling*: that tree is grown by the greedy
cuts that keep its total under it (:meth:`_Search.best_cut_within`), and the cover kept
is the smallest union of the trees whose total is under it. The greedy trees alone got
an I-beam of three slabs 6.0 times its volume from 3 bodies (its slabs 2.72: the first
greedy cut is the best one for two bodies, and a cut in the plane of a flange's inner
face leaves that face in the web's piece) and 4.9 from 4 (issue 58). A part with no such
planes (a curved hollow, a ring) is fitted as without them.

*By how far the cover sticks out* (``max_offset``, 3D). Volume does not see a body that
bulges a centimetre out of a flat face, and a grasp that leaves a finger 9 mm from an
object then collides for the cover (issue 25). With ``max_offset``, the tree is grown
from the whole part by cutting, one leaf at a time, the leaf whose body sticks out most
(sampled, :meth:`kcplan.cover.offset.OffsetMeter.estimate`), until every body is *proved*
to stick out by at most ``max_offset`` (:meth:`kcplan.cover.offset.OffsetMeter.bound`,
every point of the ellipsoid, its inside included), or until ``bodies`` leaves (default
:data:`MAX_OFFSET_BODIES`; :attr:`Cover.note` then says how many bodies still stick out
and by how much, and :attr:`Cover.offset` is the proved bound of what was reached). The
cut of a leaf is the candidate (see :func:`_offset_cut`) whose children stick out least
when that is a real gain, else a k-d tree's cut across its longest axis. The leaves are
fitted as in the volume fit (the smallest ellipsoid of the piece's hull points), so the
cover is sound by the same proof.

The cover is of the *input's own* surface and solid (no remeshing, no decomposition
library: an approximate convex decomposition such as CoACD remeshes the input and
simplifies its hulls, so its pieces need not cover the part).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull, QhullError

from kcplan.cover.bodies import body_from_ellipsoid, body_holds, body_matrix
from kcplan.cover.features import clip_segments, feature_segments, quantiles_along, simplex_normals
from kcplan.cover.partition import Piece, clip_simplices
from kcplan.cover.solid import Solid
from kcplan.geometry.enclosing import (
    FLAT_RATIO,
    convex_hull_vertices,
    ellipsoid_axes,
    ellipsoid_volume,
    enclose,
    frame_norm_sq,
    minimum_volume_ellipsoid,
)
from kcplan.geometry.robot import MAX_BODIES, Body, Robot

__all__ = [
    "FIT_VERSION",
    "MAX_OFFSET_BODIES",
    "OFFSET_FIT_VERSION",
    "SHAPES",
    "Cover",
    "check_cover",
    "fit_cover",
]

FIT_VERSION = 5
"""Changes whenever the fit by volume (``bodies`` or ``max_excess``) would give other
bodies for the same input (cache key). 3: cuts at quantiles of the curvature measure,
not of the mesh's vertices. 4: the vertices' trees as well (:data:`VERTEX_CUTS`). 5: the
reflex pieces' tree and its ceiling (:data:`PIECES`; parts without reflex planes, such
as the Panda's links, are fitted as at 4)."""
OFFSET_FIT_VERSION = 2
"""The same for a ``max_offset`` fit, whose candidate cuts are its own
(:data:`OFFSET_FRACTIONS`)."""
SHAPES = ("ellipsoid", "sphere")
CUT_QUANTILES = (0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875)
UNIQUE_ABOVE = 2000
"""Points made unique before their hull is taken when there are more than this many."""
SEARCH_TOL = 1e-2
"""Khachiyan tolerance while scoring candidate cuts (volume within about 1.5 %)."""
FINAL_TOL = 1e-4
"""Khachiyan tolerance of the bodies kept (volume within about 0.015 % of the MVEE's)."""
SCORE_SAMPLES = 2**15
"""Quasi-random points that score candidate cuts."""
FACE_SHARE = 0.01
"""A plane of the part's faces is a candidate cut when its faces carry this share of the
part's surface (so a curved mesh, whose facets are all small, adds none)."""
FACE_PLANES = 8
"""At most this many face planes per piece, those of the largest faces."""
PLANE_TOL = 1e-6
"""Faces whose unit normals and offsets (over the part's size) agree to this share a plane."""
PENCIL_ANGLES = 6
"""Planes through each axis of the part's ellipsoid, every 180 / this degrees."""
SECTORS = True
"""Also try the part cut into equal sectors about an axis of its ellipsoid."""
VERTEX_CUTS = True
"""Also grow the plain and the pencil trees with cuts at quantiles of the mesh's clipped
triangle corners (the fit before :data:`FIT_VERSION` 3, but never a sequence of two
cuts) and keep the smallest union of all (issue 41). Those cuts follow the triangulation
(a flat face split in many triangles pulls them to it), but as extra trees they can only
make a cover smaller than the curvature's trees make it alone (on the score's sample);
the sector tree is chosen by the curvature's trees alone, as without them. On the UR5's
upper arm they give 1.456 times the part at four bodies against the curvature's 1.511
(``benchmarks/RESULTS.md`` 24.1), in 1.7 times the time of the curvature's trees alone."""
PIECES = True
"""Also cut the part along the planes of its reflex edges (:func:`_reflex_planes`) into
the pieces whose ellipsoids' total volume is smallest (:meth:`_Search.pieces`), keep no
cover whose total exceeds theirs, and grow their tree within it (see the module
docstring; issue 58: a profile made of slabs is then covered by no more than its slabs'
own ellipsoids, whatever its triangulation)."""
CEILING_TRIES = 64
"""At most this many cuts, the smallest unions first, are fitted in
:meth:`_Search.best_cut_within` to find one that keeps the total under the ceiling."""
REFLEX_ANGLE = math.radians(10.0)
"""A reflex edge (corner) whose faces turn by less than this does not count: a nearly
flat crease (the Panda's finger has one of 0.55 degrees, on which the reflex pieces'
ceiling would cost its cover 15 % of union at two bodies), or a facet of a curved hollow
of more than 36 facets a turn."""
REFLEX_PLANES = 8
"""A part whose reflex edges need more planes than this gets no reflex pieces."""
PLANE_SHIFT = 1e-9
"""How far a reflex plane's cut is moved off its faces, over the part's size, beyond the
faces' own spread about the plane (:func:`_reflex_planes`)."""
PIECES_BODIES = 6
"""The exact search of :meth:`_Search.pieces` takes at most this many pieces (it is
exponential in them); the greedy cuts go on from there."""
PIECES_FITS = 400
"""... and fits at most this many distinct pieces, beyond which a piece is not cut."""
PIECES_GAIN = 1e-3
"""More pieces are taken only when their total is smaller by more than this share: a
slab cut in two has the same total (up to Khachiyan's tolerance), and the greedy cuts
that follow make the union smaller with the bodies it leaves."""
LOOKAHEAD = 3
"""When no single cut shrinks the union, this many best cuts of each leaf are tried as
the first of two."""
MAX_OFFSET_BODIES = 32
"""Most bodies a ``max_offset`` fit uses by default (:data:`kcplan.geometry.robot.
MAX_BODIES`, the most a robot may have)."""
OFFSET_TOL = 0.1
"""The offset bound of a body is refined until it is within this share of ``max_offset``
of the attained distance, or proved to be below ``max_offset``."""
OFFSET_SAMPLES = 300
"""Surface points per child ellipsoid when candidate cuts are ranked by their offset."""
OFFSET_PROGRESS = 0.9
"""A ``max_offset`` fit takes its best-ranked cut only when its children stick out at
most this share of what their parent did (else a k-d tree's cut, :func:`_offset_cut`)."""
OFFSET_FRACTIONS = (0.25, 0.375, 0.5, 0.625, 0.75)
"""Where cuts of a ``max_offset`` fit cross a piece, as fractions of its extent along the
cut's normal: balanced cuts only, since a body's offset shrinks with the size of its
piece, and a cut that shaves a sliver off leaves the offset as it was (quantiles of the
boundary points, as the volume fit uses, sit at the ends of a low-poly box)."""


@dataclass(frozen=True, eq=False)
class Cover:
    """A union of bodies that contains a part.

    Attributes
    ----------
    solid : Solid
        The part.
    bodies : tuple of Body
        In the part's frame; body ``k`` holds leaf ``k`` of ``tree``.
    tree : dict
        The cutting tree: ``{"plane": [nx, ny(, nz), offset], "below": node, "above":
        node}`` (below is ``n . x <= offset``) or a leaf ``{"body": k}``.
    shape : str
        ``ellipsoid`` or ``sphere``.
    seconds : float
        Time the fit took.
    note : str
        Why the fit stopped before the requested number of bodies, or empty.
    """

    solid: Solid
    bodies: tuple[Body, ...]
    tree: dict
    shape: str
    seconds: float = 0.0
    note: str = ""
    worst: float = field(default=0.0)
    """The largest ``(x - p)^T M (x - p)`` of any hull point in its body (at most 1)."""
    offset: float = field(default=math.nan)
    """An upper bound of how far the cover sticks out of the part (the largest distance
    from a point of a body to the part, :meth:`kcplan.cover.offset.OffsetMeter.bound`),
    in the part's unit; ``nan`` when the fit did not measure it."""

    @property
    def robot(self) -> Robot:
        return Robot(self.bodies)

    @property
    def volume_bound(self) -> float:
        """The bodies' total volume over the part's: an upper bound of the union's."""
        total = sum(ellipsoid_volume(body_matrix(b)) for b in self.bodies)
        return total / self.solid.volume

    def to_spec(self) -> dict:
        """The ``robot.bodies`` block of the scenario format."""
        spec = Robot(self.bodies).to_spec()
        if "bodies" not in spec:  # one ellipsoid that happens to sit at the origin
            spec = {"bodies": [{"semi_axes": spec["semi_axes"]}]}
        return spec


@dataclass(eq=False)
class _Leaf:
    node: dict  # the leaf's node of the cutting tree
    piece: Piece
    points: NDArray  # the piece's hull points (partition.Piece.points), which M holds
    center: NDArray
    M: NDArray
    inside: NDArray[np.bool_]  # the score sample's points in the ellipsoid
    outside: float  # the ellipsoid's volume outside the sampled region
    candidates: list | None = None  # from _Search.candidates(), once computed
    features: tuple | None = None  # the curvature measure in the cell, once clipped


def _hull_vertices(points: NDArray, unique: bool) -> tuple[NDArray, bool]:
    """The vertices of the points' convex hull and True, or every point and False when
    qhull finds them flat: the only points the smallest ellipsoid or ball around them can
    touch, and where the largest ``(x - c)^T M (x - c)`` lies. A piece's points are its
    clipped triangles' corners, each vertex about six times over; with ``unique``, many
    are first made unique (qhull's time grows with the points it is given, but the order
    of the vertices it returns, which Khachiyan's tie rule follows, changes with them)."""
    if unique and len(points) > UNIQUE_ABOVE:
        points = _without_repeats(points)
    return convex_hull_vertices(points)


def _without_repeats(points: NDArray) -> NDArray:
    """The rows of ``points`` ``(m, n)`` with bit-identical repeats dropped, in their
    first order. Rows are sorted by a hash of their bits and a row is dropped only when it
    equals its predecessor there, so a hash collision keeps both rows (nothing distinct is
    ever dropped; a repeat may stay). Sorting one integer key is a quarter of the time of
    ``np.unique(..., axis=0)``'s lexicographic sort."""
    P = np.ascontiguousarray(points, dtype=np.float64)
    bits = P.view(np.uint64)
    key = np.zeros(len(P), dtype=np.uint64)
    for column, odd in zip(bits.T, _HASH_MULTIPLIERS, strict=False):
        key = (key ^ column) * odd  # wraps modulo 2^64
    order = np.argsort(key, kind="stable")
    keys, rows = key[order], P[order]
    repeat = np.zeros(len(P), dtype=bool)
    repeat[1:] = (keys[1:] == keys[:-1]) & (rows[1:] == rows[:-1]).all(axis=1)
    return P[np.sort(order[~repeat])]


_HASH_MULTIPLIERS = tuple(
    np.uint64(m) for m in (0x9E3779B97F4A7C15, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9)
)


def _enclosing(
    points: NDArray, shape: str, tol: float, unique: bool = False
) -> tuple[NDArray, NDArray]:
    """An ellipsoid (or ball) holding every point, as ``(center, M)`` (``unique``: see
    :func:`_hull_vertices`)."""
    P, hull = _hull_vertices(points, unique)
    if shape == "sphere":
        from trimesh.nsphere import minimum_nsphere

        try:
            c, r = minimum_nsphere(P)
        except (QhullError, ValueError):  # a flat set: the ball about its box's centre
            c = 0.5 * (P.min(axis=0) + P.max(axis=0))
            r = np.linalg.norm(P - c, axis=1).max()
        c = np.asarray(c, dtype=float)
        r = max(float(r), FLAT_RATIO * max(float(np.abs(P).max()), 1e-30))
        M = np.eye(len(c)) / r**2
    else:
        c, M = minimum_volume_ellipsoid(P, tol, hull_vertices=hull)
    return c, enclose(P, c, M)


def _directions(M: NDArray) -> list[NDArray]:
    """Unit normals of candidate cuts: the ellipsoid's axes, then the frame's axes not
    already (nearly) among them."""
    _, R = ellipsoid_axes(M)
    out = [R[:, k] for k in range(len(M) - 1, -1, -1)]  # longest axis first
    for e in np.eye(len(M)):
        if all(abs(float(e @ d)) < 0.999 for d in out):
            out.append(e)
    return out


def _face_planes(boundary: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """The distinct planes of the part's boundary simplices that carry at least
    :data:`FACE_SHARE` of its surface, largest first.

    Returns
    -------
    normals : ndarray, shape (m, n)
        Unit normals, signed so that the largest component is positive.
    offsets : ndarray, shape (m,)
    areas : ndarray, shape (m,)
        Area (length in 2D) of the boundary on each plane.
    """
    _, normals, offsets, total, surface = _plane_groups(boundary)
    order = np.argsort(-total)
    order = order[total[order] >= FACE_SHARE * surface]
    return normals[order], offsets[order], total[order]


def _plane_groups(
    boundary: NDArray, oriented: bool = False
) -> tuple[NDArray, NDArray, NDArray, NDArray, float]:
    """The boundary simplices grouped by the plane they lie in (unit normals and offsets
    over the part's size agreeing to :data:`PLANE_TOL`; with ``oriented``, by their
    outward normals, so that faces on the two sides of one plane are two groups).

    Returns
    -------
    group : ndarray of int, shape (k,)
        Each simplex's plane, -1 for a simplex without area.
    normals : ndarray, shape (g, n)
        The planes' unit normals, signed so that the largest component is positive
        (outward with ``oriented``).
    offsets : ndarray, shape (g,)
    areas : ndarray, shape (g,)
        Area (length in 2D) of the boundary on each plane.
    surface : float
        The whole boundary's area (length).
    """
    n = boundary.shape[-1]
    normal, area = simplex_normals(boundary)
    length = np.linalg.norm(normal, axis=1)
    keep = length > 0
    normal = normal[keep] / length[keep, None]
    if not oriented:
        sign = np.sign(normal[np.arange(len(normal)), np.abs(normal).argmax(axis=1)])
        normal *= sign[:, None]
    offset = np.einsum("ij,ij->i", normal, boundary[keep, 0])
    size = float(np.ptp(boundary.reshape(-1, n), axis=0).max())
    key = np.round(np.column_stack([normal / PLANE_TOL, offset / (PLANE_TOL * size)]))
    _, group = np.unique(key, axis=0, return_inverse=True)
    group = group.reshape(-1)
    weight = area[keep]
    total = np.bincount(group, weight)
    normals = np.stack([np.bincount(group, weight * normal[:, j]) for j in range(n)], axis=1)
    offsets = np.bincount(group, weight * offset) / total
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    every = np.full(len(boundary), -1)
    every[keep] = group
    return every, normals, offsets, total, float(area.sum())


def _reflex_planes(solid: Solid) -> tuple[NDArray, NDArray, NDArray, float]:
    """Cuts along the planes of the part's faces that meet another face at a *reflex*
    (concave) edge (a 2D outline's edges at its reflex corners), if at most
    :data:`REFLEX_PLANES` planes, each carrying :data:`FACE_SHARE` of the part's surface,
    hold every reflex edge whose faces turn by :data:`REFLEX_ANGLE` or more; else none.

    Cutting a polyhedron along the planes through all its reflex edges leaves convex
    pieces: the inner faces of an I-beam's flanges cut it into its flanges and its web,
    and so for any extruded union of slabs. A part with a curved hollow (many small
    facets meeting at small reflex angles) has no such planes, and gets none.

    Each plane is moved off its faces, outwards (along their outward normal) by how far
    their corners lie from it plus :data:`PLANE_SHIFT` of the part's size, so that the
    faces fall on their own solid's side only: a triangle in a cutting plane stays on
    both sides (:func:`kcplan.cover.partition.clip_simplices`, which soundness needs), and
    the flange's inner face would make the web's piece as wide as the flange. The
    flange's piece then holds a sliver of the web as thin as that shift, and with it the
    reflex edges, that close to the cut.

    Returns
    -------
    normals : ndarray, shape (m, n)
        Unit normals, outward of the faces; the planes with the most reflex edge first
        (its length times its angle; the corners' angles in 2D).
    offsets : ndarray, shape (m,)
    edges : ndarray, shape (e, 2, n)
        The reflex edges (a 2D outline's reflex corners, as segments of length zero).
    margin : float
        Twice the largest shift: a reflex edge nearer than this to a cut lies in a sliver.
    """
    boundary = solid.boundary
    group, normals, offsets, total, surface = _plane_groups(boundary, oriented=True)
    if solid.dimension == 3:
        import trimesh  # imported where used: 1.5 s that a plan on a fitted cover never needs

        mesh = trimesh.Trimesh(solid.vertices, solid.faces, process=False)
        pairs = np.asarray(mesh.face_adjacency)  # (a, 2): faces that share an edge
        angle = np.asarray(mesh.face_adjacency_angles, dtype=float)
        edges = np.asarray(mesh.vertices)[mesh.face_adjacency_edges]
        weight = angle * np.linalg.norm(edges[:, 1] - edges[:, 0], axis=1)
        reflex = ~np.asarray(mesh.face_adjacency_convex, dtype=bool) & (angle >= REFLEX_ANGLE)
    else:  # corner i joins edges i - 1 and i of the counter-clockwise outline
        d = boundary[:, 1] - boundary[:, 0]
        before = np.roll(d, 1, axis=0)
        turn = np.arctan2(before[:, 0] * d[:, 1] - before[:, 1] * d[:, 0], (before * d).sum(1))
        pairs = np.column_stack([np.roll(np.arange(len(d)), 1), np.arange(len(d))])
        edges = np.stack([boundary[:, 0], boundary[:, 0]], axis=1)
        weight, reflex = -turn, turn <= -REFLEX_ANGLE  # a clockwise turn
    carried = np.zeros(len(normals))
    for side in (0, 1):
        g = group[pairs[reflex, side]]
        np.add.at(carried, g[g >= 0], weight[reflex][g >= 0])
    keep = np.flatnonzero((carried > 0) & (total >= FACE_SHARE * surface))
    keep = keep[np.argsort(-carried[keep], kind="stable")]
    held = np.isin(group[pairs[reflex]], keep).any(axis=1)  # a face on a kept plane
    if len(keep) > REFLEX_PLANES or not held.all():
        keep = keep[:0]  # not a union of convex pieces that these planes cut apart
    on = group >= 0
    apart = np.einsum("kcn,kn->kc", boundary[on], normals[group[on]])
    apart = np.abs(apart - offsets[group[on]][:, None]).max(axis=1)
    residual = np.zeros(len(normals))
    np.maximum.at(residual, group[on], apart)
    shift = residual[keep] + PLANE_SHIFT * solid.size
    margin = 2.0 * float(shift.max()) if len(keep) else 0.0
    return normals[keep], offsets[keep] + shift, edges[reflex], margin


def _holds_edges(piece: Piece, edges: NDArray, margin: float) -> bool:
    """Whether a stretch of the segments ``edges`` ``(e, 2, n)`` (points, when of length
    zero) lies in the piece's cell farther than ``margin`` from its sides."""
    if len(edges) == 0:
        return False
    try:
        cell = ConvexHull(piece.corners).equations.copy()
    except (QhullError, ValueError):  # a flat cell holds no stretch of an edge
        return False
    cell[:, -1] += margin  # unit normals: the cell shrunk by margin
    _, measures = clip_segments(edges, np.ones(len(edges)), cell)
    return bool((measures > 0.0).any())


def _pencil_normal(R: NDArray, axis: int, angle: float) -> NDArray:
    """The unit normal of the plane through the ellipsoid's axis ``axis`` (columns of
    ``R``; in 2D, the line through the centre) at ``angle`` from the next axis: a point
    at angle ``t`` about the axis lies below the plane when ``sin(t - angle) <= 0``."""
    n = len(R)
    i, j = (0, 1) if n == 2 else ((axis + 1) % 3, (axis + 2) % 3)
    return -np.sin(angle) * R[:, i] + np.cos(angle) * R[:, j]


def _pencils(center: NDArray, R: NDArray) -> tuple[NDArray, NDArray]:
    """Planes through the centre of the part's ellipsoid that contain one of its axes
    (columns of ``R``), at :data:`PENCIL_ANGLES` angles about it (in 2D: lines through the
    centre), as unit ``normals (m, n)`` and ``offsets (m,)``. A ring's hole is on such an
    axis, and the planes through it cut the ring into sectors."""
    out: list[NDArray] = []
    for axis in range(len(R) if len(R) == 3 else 1):
        for t in np.pi * np.arange(PENCIL_ANGLES) / PENCIL_ANGLES:
            normal = _pencil_normal(R, axis, t)
            if all(abs(float(normal @ d)) < 0.999 for d in out):
                out.append(normal)
    normals = np.array(out)
    return normals, normals @ center


def _crossing(V: NDArray, normals: NDArray, offsets: NDArray) -> NDArray[np.bool_]:
    """Which planes have points of ``V`` strictly on both sides (beyond a millionth of
    the points' extent), so that they cut the piece into two pieces with volume."""
    if len(normals) == 0:
        return np.zeros(0, dtype=bool)
    d = V @ normals.T - offsets  # (points, planes)
    margin = 1e-6 * float(np.ptp(V, axis=0).max())
    return (d.min(axis=0) < -margin) & (d.max(axis=0) > margin)


class _Scorer:
    """Union volume on a fixed quasi-random sample of the part's bounding box, padded by a
    tenth (what a body has outside the box is added from its exact volume)."""

    def __init__(self, solid: Solid):
        V = solid.boundary.reshape(-1, solid.dimension)
        low, high = V.min(axis=0), V.max(axis=0)
        pad = 0.1 * (high - low)
        low, high = low - pad, high + pad
        from scipy.stats import qmc  # 0.7 s of imports, needed when fitting only

        u = qmc.Sobol(solid.dimension, seed=0).random(SCORE_SAMPLES)
        u = u[np.argsort(u[:, 0], kind="stable")]  # by x, so a body's slab is a slice
        self.points = low + u * (high - low)
        self.cell = float(np.prod(high - low)) / SCORE_SAMPLES

    def inside(self, center: NDArray, M: NDArray) -> NDArray[np.bool_]:
        """The sample points in the ellipsoid ``(x - c)^T M (x - c) <= 1``; only those in
        its slab along x (half-width ``sqrt((M^-1)_xx)``, padded) are measured."""
        a, R = ellipsoid_axes(M)
        half = float(np.linalg.norm(R[0] * a)) * (1.0 + 1e-6)  # the support along x
        x = self.points[:, 0]
        lo, hi = np.searchsorted(x, [center[0] - half, center[0] + half], side="left")
        out = np.zeros(len(x), dtype=bool)
        out[lo : hi + 1] = frame_norm_sq(self.points[lo : hi + 1] - center, a, R) <= 1.0
        return out

    def outside(self, M: NDArray, inside: NDArray[np.bool_]) -> float:
        """Volume of an ellipsoid outside the sampled region (exact volume less the
        sampled part), so that a cut cannot hide volume there."""
        return max(0.0, ellipsoid_volume(M) - float(inside.sum()) * self.cell)

    def union(self, inside: NDArray[np.bool_], outside: float) -> float:
        """The union's volume from its sampled points and its volume outside."""
        return int(inside.sum()) * self.cell + outside


class _EmptySector(Exception):
    """A sector of :meth:`_Search.sectors` holds nothing of the part."""


class _Search:
    """What the search needs of a part: its fitted leaves and their candidate cuts."""

    def __init__(
        self,
        solid: Solid,
        shape: str,
        pencils: bool,
        features: tuple | None = None,
        cuts: str = "features",
        unique: bool = False,
    ):
        self.solid = solid
        self.shape = shape
        self.cuts = cuts
        """Where cuts cross a leaf (:meth:`offsets`): ``features`` (the part's curvature
        measure) or ``vertices`` (the mesh's triangle corners, :data:`VERTEX_CUTS`)."""
        self.unique = unique
        """Points made unique before their hull (:func:`_hull_vertices`): the fit by
        volume; the fit by offset keeps the order its bundled covers were fitted in
        (:data:`OFFSET_FIT_VERSION`)."""
        self.scorer = _Scorer(solid)
        self.faces = _face_planes(solid.boundary)[:2] if FACE_PLANES else None
        self.root = self.leaf(Piece.whole(solid.boundary))
        self.axes = ellipsoid_axes(self.root.M)[1]
        self.pencils = _pencils(self.root.center, self.axes) if pencils else None
        self.features = features
        """The part's curvature measure (:func:`feature_segments`), on first use (the fit
        by offset takes none); the searches of one fit share it."""
        self.reflex: tuple[NDArray, NDArray, NDArray, float] | None = None
        """The part's reflex planes (:func:`_reflex_planes`), on first use."""
        self.piece_trees: dict[bytes, list[tuple[float, tuple | None]]] = {}
        """The best trees of the pieces :meth:`pieces` met, by their hull's corners."""

    def leaf(self, piece: Piece, points: NDArray | None = None) -> _Leaf:
        """A leaf of the piece, its ellipsoid fitted to its full hull points (``points``,
        if they are known already)."""
        points = piece.points(self.solid.boundary) if points is None else points
        c, M = _enclosing(points, self.shape, FINAL_TOL, self.unique)
        inside = self.scorer.inside(c, M)
        return _Leaf({}, piece, points, c, M, inside, self.scorer.outside(M, inside))

    def children(self, leaf: _Leaf, normal: NDArray, offset: float) -> tuple[_Leaf, _Leaf]:
        """The leaves below and above the plane ``normal . x = offset``."""
        return (
            self.leaf(leaf.piece.cut(normal, offset)),
            self.leaf(leaf.piece.cut(-normal, -offset)),
        )

    def union(self, leaves: list[_Leaf]) -> float:
        """The union's volume of the leaves' ellipsoids (sample estimate)."""
        inside = np.logical_or.reduce([leaf.inside for leaf in leaves])
        return self.scorer.union(inside, sum(leaf.outside for leaf in leaves))

    def sectors(self, axis: int, m: int) -> tuple[dict, list[_Leaf]] | None:
        """The part cut into ``m`` (even) equal sectors about an axis of its ellipsoid by
        planes through the axis (:func:`_pencil_normal`): a fresh tree and its leaves, or
        None when a sector holds nothing of the part."""
        R, center = self.axes, self.root.center

        def split(node: dict, piece: Piece, low: float, high: float, j: int) -> list[_Leaf]:
            """Sectors ``j`` of the angles ``[low, high]`` (at most a half turn apart, or
            the whole turn at the root) of ``piece``, whose tree node is ``node``."""
            if j == 1:
                points = piece.points(self.solid.boundary)
                if len(points) == 0:
                    raise _EmptySector
                leaf = self.leaf(piece, points)
                leaf.node = node
                return [leaf]
            angle = low + (high - low) * (j // 2) / j
            normal = _pencil_normal(R, axis, angle)
            offset = float(normal @ center)
            node |= {"plane": [*normal.tolist(), offset], "below": {}, "above": {}}
            below = split(node["below"], piece.cut(normal, offset), low, angle, j // 2)
            above = piece.cut(-normal, -offset)
            return below + split(node["above"], above, angle, high, j - j // 2)

        root: dict = {}
        try:
            return root, split(root, self.root.piece, -np.pi, np.pi, m)
        except _EmptySector:
            return None

    def pieces(self, most: int) -> tuple[dict, list[_Leaf]] | None:
        """The part cut along its reflex planes (:func:`_reflex_planes`) into pieces with
        no reflex edge inside (but within the planes' shift of a cut: each piece's
        connected parts are convex), at most ``most`` and :data:`PIECES_BODIES` of them,
        whose ellipsoids' total volume is the smallest of any such tree (of the fewest
        pieces within :data:`PIECES_GAIN` of it): a fresh tree and its leaves, or None
        when there is no such tree (no reflex planes, or more pieces needed).

        The search is exact over these planes (dynamic programming: a piece's best tree of
        at most ``m`` leaves is itself, if it holds no reflex edge, or a plane that
        crosses it and the best trees of ``m1`` and ``m - m1`` leaves of its two sides),
        its pieces keyed by their hull's corners, so that a piece reached by cuts in
        another order is fitted once (:attr:`piece_trees`); at most :data:`PIECES_FITS`
        pieces are fitted, and a piece met after that is not cut. The leaves of the tree
        kept are fitted again on their own path's pieces, the points :func:`check_cover`
        derives.

        Parameters
        ----------
        most : int
            The most leaves.

        Returns
        -------
        root : dict
            The tree's root node (leaves' nodes are the leaves' own, as :meth:`sectors`).
        leaves : list of _Leaf
            Their ellipsoids fitted at :data:`FINAL_TOL`.
        """
        if self.reflex is None:
            self.reflex = _reflex_planes(self.solid)
        normals, offsets, edges, margin = self.reflex
        most = min(most, PIECES_BODIES)
        if len(normals) == 0 or most < 2:
            return None
        boundary, size = self.solid.boundary, self.solid.size
        memo = self.piece_trees

        def best(piece: Piece, budget: int) -> list[tuple[float, tuple | None]]:
            """``(total volume, plan)`` of the best tree of at most ``m`` leaves, for ``m``
            from 1 to ``budget`` (an infinite total: none); a plan is None (the piece as
            one leaf) or ``(plane, m1, m2)``."""
            points, _ = _hull_vertices(piece.points(boundary), self.unique)
            key = np.round(points / (PLANE_TOL * size)).astype(np.int64)
            key = key[np.lexsort(key.T[::-1])].tobytes()
            known = memo.get(key)
            if known is not None and (len(known) >= budget or len(memo) >= PIECES_FITS):
                return (known + known[-1:] * budget)[:budget]  # at most m leaves: m + 1 too
            cross = np.flatnonzero(_crossing(piece.boundary_points, normals, offsets))
            volume = math.inf  # a piece that holds a reflex edge is cut
            if not _holds_edges(piece, edges, margin):
                volume = ellipsoid_volume(_enclosing(points, self.shape, FINAL_TOL)[1])
            out: list[tuple[float, tuple | None]] = [(volume, None)] * budget
            memo[key] = out[:1]  # while its cuts are searched (a cut makes it smaller)
            if budget > 1 and len(memo) < PIECES_FITS:
                for i in cross:
                    below = piece.cut(normals[i], offsets[i])
                    above = piece.cut(-normals[i], -offsets[i])
                    low, high = best(below, budget - 1), best(above, budget - 1)
                    for m in range(2, budget + 1):
                        for m1 in range(1, m):
                            total = low[m1 - 1][0] + high[m - m1 - 1][0]
                            if total < out[m - 1][0]:
                                out[m - 1] = (total, (int(i), m1, m - m1))
                for m in range(1, budget):  # fewer leaves when no worse (but for rounding)
                    if out[m - 1][0] <= out[m][0] * (1.0 + 1e-9):
                        out[m] = out[m - 1]
            memo[key] = out
            return out

        def build(node: dict, piece: Piece, m: int) -> list[_Leaf]:
            plan = best(piece, m)[m - 1][1]
            if plan is None:
                leaf = self.leaf(piece)
                leaf.node = node
                return [leaf]
            i, m1, m2 = plan
            normal, offset = normals[i], float(offsets[i])
            node |= {"plane": [*normal.tolist(), offset], "below": {}, "above": {}}
            below = build(node["below"], piece.cut(normal, offset), m1)
            return below + build(node["above"], piece.cut(-normal, -offset), m2)

        whole = self.root.piece
        totals = [total for total, _ in best(whole, most)]
        if not math.isfinite(totals[-1]):
            return None
        fewest = next(
            m for m in range(1, most + 1) if totals[m - 1] <= totals[-1] * (1 + PIECES_GAIN)
        )
        root: dict = {}
        return root, build(root, whole, fewest)

    def planes(self, leaf: _Leaf) -> list[tuple[NDArray, float]]:
        """Candidate cuts of a leaf as ``(normal, offset)``: across its ellipsoid's and the
        frame's axes at :meth:`offsets`, then the part's largest face planes and the
        planes of :func:`_pencils` that cross the piece."""
        V = leaf.piece.boundary_points
        out = [
            (normal, float(offset))
            for normal in _directions(leaf.M)
            for offset in np.unique(self.offsets(leaf, normal))
        ]
        if self.faces is not None:
            normals, offsets = self.faces
            cross = np.flatnonzero(_crossing(V, normals, offsets))[:FACE_PLANES]
            out += [(normals[i], float(offsets[i])) for i in cross]
        if self.pencils is not None:
            normals, offsets = self.pencils
            cross = np.flatnonzero(_crossing(V, normals, offsets))
            out += [(normals[i], float(offsets[i])) for i in cross]
        return out

    def offsets(self, leaf: _Leaf, normal: NDArray) -> NDArray:
        """Where cuts across ``normal`` may cross ``leaf``: the quantiles
        :data:`CUT_QUANTILES` of the part's curvature measure in the leaf's cell
        (:mod:`kcplan.cover.features`), or of its surface's area there when the cell
        holds no feature; of the clipped triangles' corners with ``cuts="vertices"``."""
        if self.cuts == "vertices":
            return np.quantile(leaf.piece.boundary_points @ normal, CUT_QUANTILES)
        if self.features is None:
            self.features = feature_segments(self.solid)
        if leaf.features is None:
            try:
                cell = ConvexHull(leaf.piece.corners).equations
            except (QhullError, ValueError):  # a flat cell: no feature is inside it
                cell = None
            leaf.features = (
                clip_segments(*self.features, cell)
                if cell is not None
                else (np.zeros((0, 2, self.solid.dimension)), np.zeros(0))
            )
        segments, measures = leaf.features
        if measures.sum() > 0.0:
            return quantiles_along(segments, normal, CUT_QUANTILES, measures)
        return quantiles_along(leaf.piece.boundary, normal, CUT_QUANTILES)

    def candidates(self, leaf: _Leaf) -> list[tuple]:
        """Candidate cuts of ``leaf`` as ``(normal, offset, covered, outside)``: the sample
        points the two children's ellipsoids (fitted to their clipped boundary points)
        hold, and their volume outside the sampled region."""
        if leaf.candidates is not None:
            return leaf.candidates
        out = []
        n = self.solid.dimension
        for normal, offset in self.planes(leaf):
            covered = np.zeros(len(self.scorer.points), dtype=bool)
            outside = 0.0
            for sign in (1.0, -1.0):  # the children's boundaries (their cells not needed)
                part = clip_simplices(leaf.piece.boundary, sign * normal, sign * offset)
                if len(part) == 0:
                    break
                c, M = _enclosing(part.reshape(-1, n), self.shape, SEARCH_TOL, self.unique)
                inside = self.scorer.inside(c, M)
                covered |= inside
                outside += self.scorer.outside(M, inside)
            else:
                out.append((normal, offset, covered, outside))
        leaf.candidates = out
        return out

    def ranked_cuts(self, leaves: list[_Leaf], k: int) -> list[tuple[float, NDArray, float]]:
        """The candidate cuts of ``leaves[k]`` as ``(union volume, normal, offset)``, the
        smallest union first."""
        rest = np.zeros(len(self.scorer.points), dtype=bool)
        outside = 0.0
        for j, other in enumerate(leaves):
            if j != k:
                rest |= other.inside
                outside += other.outside
        out = [
            (self.scorer.union(rest | covered, outside + extra), normal, offset)
            for normal, offset, covered, extra in self.candidates(leaves[k])
        ]
        return sorted(out, key=lambda cut: cut[0])

    def best_cut(self, leaves: list[_Leaf]) -> tuple[float, int, NDArray, float]:
        """The single cut of any leaf that leaves the smallest union: ``(union volume,
        leaf index, normal, offset)``."""
        best = (np.inf, -1, None, 0.0)
        for k in range(len(leaves)):
            cuts = self.ranked_cuts(leaves, k)
            if cuts and cuts[0][0] < best[0]:
                best = (cuts[0][0], k, cuts[0][1], cuts[0][2])
        return best

    def best_pair(self, leaves: list[_Leaf]) -> tuple[float, int, NDArray, float, tuple]:
        """The best sequence of two cuts, the first among the :data:`LOOKAHEAD` best cuts
        of each leaf (its children fitted as if chosen), the second any single cut of the
        leaves then: ``(union volume after both, leaf index, normal, offset, children)``
        of the first."""
        best = (np.inf, -1, None, 0.0, ())
        for k in range(len(leaves)):
            for _, normal, offset in self.ranked_cuts(leaves, k)[:LOOKAHEAD]:
                children = self.children(leaves[k], normal, offset)
                after = [*leaves[:k], *leaves[k + 1 :], *children]
                union = self.best_cut(after)[0]
                if union < best[0]:
                    best = (union, k, normal, offset, children)
        return best

    def best_cut_within(
        self, leaves: list[_Leaf], union: float, most: float
    ) -> tuple[float, int, NDArray, float, tuple] | None:
        """The cut of any leaf that leaves the smallest union below ``union`` among those
        that leave the bodies' total volume at most ``most`` (each fitted as if chosen, in
        order of union, at most :data:`CEILING_TRIES` of them): ``(union volume, leaf
        index, normal, offset, children)``, or None."""
        total = _total(leaves)
        cuts = [
            (cut[0], k, j, cut[1], cut[2])
            for k in range(len(leaves))
            for j, cut in enumerate(self.ranked_cuts(leaves, k))
        ]
        cuts.sort(key=lambda cut: cut[:3])
        for estimate, k, _, normal, offset in cuts[:CEILING_TRIES]:
            if not estimate < union:
                break
            children = self.children(leaves[k], normal, offset)
            after = total - ellipsoid_volume(leaves[k].M)
            if after + sum(ellipsoid_volume(child.M) for child in children) <= most:
                return estimate, k, normal, offset, children
        return None


def fit_cover(
    solid: Solid,
    bodies: int | None = None,
    max_excess: float | None = None,
    shape: str = "ellipsoid",
    progress: Callable[[str], None] | None = None,
    max_offset: float | None = None,
) -> Cover:
    """Cover a part by at most ``bodies`` ellipsoids (see the module docstring).

    Parameters
    ----------
    solid : Solid
    bodies : int, optional
        Number of bodies, 1 to :data:`kcplan.geometry.robot.MAX_BODIES`.
    max_excess : float, optional
        Instead of ``bodies``: stop at the first cover whose bodies' total volume is at
        most ``(1 + max_excess)`` times the part's (or at ``MAX_BODIES`` bodies).
    shape : str
        ``ellipsoid`` (default) or ``sphere``.
    progress : callable, optional
        Called with one line per body added.
    max_offset : float, optional
        Instead of ``max_excess``, and with ``bodies`` as the most bodies (default
        :data:`MAX_OFFSET_BODIES`): cut until no body sticks out of the part by more than
        this (part's unit; proved, :mod:`kcplan.cover.offset`), splitting the body that
        sticks out most (see the module docstring). When the most bodies are not enough,
        :attr:`Cover.note` says so and by how much the cover still sticks out.

    Returns
    -------
    Cover
        ``cover.worst <= 1``: every hull point of every piece is in its body.
        ``cover.offset`` bounds how far it sticks out (``nan`` when not measured).
    """
    if shape not in SHAPES:
        raise ValueError(f"shape: expected one of {', '.join(SHAPES)}, got {shape!r}")
    if max_offset is not None:
        if max_excess is not None:
            raise ValueError("expected at most one of max_excess and max_offset")
        if not (isinstance(max_offset, (int, float)) and max_offset > 0):
            raise ValueError(f"max_offset: expected a positive number, got {max_offset}")
        if solid.dimension != 3:
            raise ValueError(f"max_offset: expected a 3D part, got a {solid.dimension}D one")
        if bodies is not None and not 1 <= bodies <= MAX_BODIES:
            raise ValueError(f"bodies: expected 1 to {MAX_BODIES}, got {bodies}")
        return _fit_offset(solid, bodies or MAX_OFFSET_BODIES, float(max_offset), shape, progress)
    if (bodies is None) == (max_excess is None):
        raise ValueError("expected exactly one of bodies and max_excess")
    if bodies is not None and not 1 <= bodies <= MAX_BODIES:
        raise ValueError(f"bodies: expected 1 to {MAX_BODIES}, got {bodies}")
    if max_excess is not None and not max_excess > 0:
        raise ValueError(f"max_excess: expected a positive number, got {max_excess}")
    start = time.perf_counter()
    features = feature_segments(solid)  # for every search: a property of the part
    cuts = ("features", "vertices")[: 1 + bool(VERTEX_CUTS)]
    kinds = [(c, p) for c in cuts for p in (False, True)[: 1 + bool(PENCIL_ANGLES)]]
    searches = [_Search(solid, shape, p, features, c, unique=True) for c, p in kinds]
    target = bodies if bodies is not None else MAX_BODIES

    def reporter(label: str) -> Callable[[int], None]:
        def report(count: int) -> None:
            if progress is not None:
                progress(f"{label}: {count} bodies, {time.perf_counter() - start:.1f} s")

        return report

    cut_names = {"features": "curvature's cuts", "vertices": "vertices' cuts"}
    names = {(c, p): cut_names[c] + " and pencils" * p for c, p in kinds}
    growths = [
        _grow(s, s.root.node, [s.root], target, max_excess, reporter(names[kind]))
        for kind, s in zip(kinds, searches, strict=True)
    ]
    if bodies is not None and SECTORS:
        # the curvature's own trees decide, as they would alone: a tree of the vertices'
        # cuts may only make the cover smaller (VERTEX_CUTS)
        own = [k for k, kind in enumerate(kinds) if kind[0] == "features"]
        search = searches[own[-1]]
        sectors = _best_sectors(search, bodies, [growths[k] for k in own])
        if sectors is not None:
            growths.append(_grow(search, *sectors, bodies, None, reporter("sectors")))
    ceiling = math.inf
    if bodies is not None and PIECES:
        pieces = searches[0].pieces(bodies)
        if pieces is not None:
            # with a little room for rounding: the other trees' pieces fit as well
            ceiling = _total(pieces[1]) * (1.0 + 1e-9)
            report = reporter("reflex pieces")
            growths.append(_grow(searches[0], *pieces, bodies, None, report, ceiling))
    if max_excess is None:
        # the smallest union of the trees whose bodies' total (the bound that
        # Cover.volume_bound reports) is at most the reflex pieces' own: the pieces' tree
        # is one of them, so a part made of a few slabs is never looser than they are
        growth = min((g for g in growths if g.total <= ceiling), key=lambda g: g.union)
    else:  # the fewest bodies within the bound, then the smallest union
        growth = min(growths, key=lambda g: (len(g.leaves), g.union))
        if len(growth.leaves) == MAX_BODIES and growth.total > (1.0 + max_excess) * solid.volume:
            growth.note = f"stopped at {MAX_BODIES} bodies, the most a robot may have"
    out = []
    for k, leaf in enumerate(growth.leaves):
        leaf.node["body"] = k
        out.append(_sound_body(leaf, shape, solid.weld))
    worst = max(
        body_holds(body, leaf.points) for body, leaf in zip(out, growth.leaves, strict=True)
    )
    seconds = time.perf_counter() - start
    return Cover(solid, tuple(out), growth.root, shape, seconds, growth.note, worst)


@dataclass(eq=False)
class _Growth:
    """A cutting tree grown by :func:`_grow`."""

    root: dict
    leaves: list[_Leaf]
    note: str  # why it stopped before the number of bodies asked for, or empty
    trail: dict[int, float]  # the union's volume (sample estimate) at each leaf count

    @property
    def union(self) -> float:
        return self.trail[len(self.leaves)]

    @property
    def total(self) -> float:
        """The leaves' ellipsoids' total volume."""
        return _total(self.leaves)


def _total(leaves: list[_Leaf]) -> float:
    """The total volume of the leaves' ellipsoids (the bound :attr:`Cover.volume_bound`
    reports)."""
    return sum(ellipsoid_volume(leaf.M) for leaf in leaves)


def _grow(
    search: _Search,
    root: dict,
    leaves: list[_Leaf],
    target: int,
    max_excess: float | None,
    report: Callable[[int], None],
    ceiling: float = math.inf,
) -> _Growth:
    """Cut the leaves of the tree ``root``, one cut at a time, until there are ``target``
    of them (see the module docstring), or until the bodies' total volume is within
    ``1 + max_excess`` of the part's; with a finite ``ceiling``, only by cuts that leave
    the total at most that (:meth:`_Search.best_cut_within`; no sequences of two). The
    leaves' tree nodes get planes and children."""
    growth = _Growth(root, list(leaves), "", {len(leaves): search.union(leaves)})
    leaves = growth.leaves
    while len(leaves) < target:
        if max_excess is not None:
            if _total(leaves) <= (1.0 + max_excess) * search.solid.volume:
                break
        if math.isfinite(ceiling):
            found = search.best_cut_within(leaves, growth.union, ceiling)
            if found is None:
                why = "no cut made the cover smaller within the reflex pieces' total"
                growth.note = _stopped(len(leaves), why)
                break
            union, k, normal, offset, children = found
        elif (cut := search.best_cut(leaves))[0] < growth.union:
            union, k, normal, offset = cut
            children = search.children(leaves[k], normal, offset)
        elif len(leaves) + 2 > target or not LOOKAHEAD or search.cuts == "vertices":
            growth.note = _stopped(len(leaves), "no cut made the cover smaller")
            break
        else:
            union, k, normal, offset, children = search.best_pair(leaves)
            if not union < growth.union:
                why = "no sequence of two cuts made the cover smaller"
                growth.note = _stopped(len(leaves), why)
                break
        leaf = leaves.pop(k)
        leaf.node |= {"plane": [*normal.tolist(), float(offset)]}
        leaf.node |= {"below": children[0].node, "above": children[1].node}
        leaves += children
        growth.trail[len(leaves)] = search.union(leaves)
        report(len(leaves))
    return growth


def _fit_offset(
    solid: Solid, most: int, max_offset: float, shape: str, progress: Callable[[str], None] | None
) -> Cover:
    """Cut until every body sticks out of the part by at most ``max_offset`` (proved by
    :meth:`OffsetMeter.bound`), or until ``most`` bodies (see :func:`fit_cover`)."""
    from kcplan.cover.offset import OffsetMeter

    start = time.perf_counter()
    tol = OFFSET_TOL * max_offset
    meter = OffsetMeter(solid, min(solid.size / 100.0, 0.5 * tol))
    search = _Search(solid, shape, pencils=False)
    leaves = [search.root]
    # leaf -> (its body, its offset bound); keyed by the leaf itself (hashed by identity),
    # not id(leaf): a cut leaf's id may be given to a new child once the leaf is freed
    bounds: dict[_Leaf, tuple[Body, object]] = {}
    note = ""
    while True:
        for leaf in leaves:
            if leaf not in bounds:
                body = _sound_body(leaf, shape, solid.weld)
                bounds[leaf] = (body, meter.bound(body, tol, below=max_offset))
        over = [k for k, leaf in enumerate(leaves) if bounds[leaf][1].high > max_offset]
        if not over:
            break
        if len(leaves) >= most:
            for leaf in (leaves[k] for k in over):  # the value, not just "above"
                body = bounds[leaf][0]
                # to a tenth of the value: a tight bound of a large offset costs minutes
                coarse = max(tol, 0.1 * bounds[leaf][1].low)
                bounds[leaf] = (body, meter.bound(body, coarse))
            worst = max(bounds[leaf][1].high for leaf in leaves)
            note = (
                f"stopped at {most} bodies, the most asked for: {len(over)} still stick out "
                f"by more than {max_offset:.4g} (up to {worst:.4g})"
            )
            break
        k = max(over, key=lambda j: meter.estimate(bounds[leaves[j]][0]))
        normal, offset = _offset_cut(search, meter, leaves[k], shape)
        leaf = leaves.pop(k)
        children = search.children(leaf, normal, offset)
        leaf.node |= {"plane": [*normal.tolist(), float(offset)]}
        leaf.node |= {"below": children[0].node, "above": children[1].node}
        leaves += children
        if progress is not None:
            progress(f"offset: {len(leaves)} bodies, {time.perf_counter() - start:.1f} s")
    out = []
    for k, leaf in enumerate(leaves):
        leaf.node["body"] = k
        out.append(bounds[leaf][0])
    worst = max(body_holds(body, leaf.points) for body, leaf in zip(out, leaves, strict=True))
    # measured from the welded solid; the file's triangles are within solid.weld of it
    offset_high = max(bounds[leaf][1].high for leaf in leaves) + solid.weld
    seconds = time.perf_counter() - start
    return Cover(solid, tuple(out), search.root.node, shape, seconds, note, worst, offset_high)


def _offset_cut(search: _Search, meter, leaf: _Leaf, shape: str) -> tuple[NDArray, float]:
    """The cut of ``leaf``, a piece whose body sticks out too far: among planes across the
    direction in which it sticks out most and across its ellipsoid's axes (at
    :data:`OFFSET_FRACTIONS` of the piece's extent), the one whose two children stick out
    least (the larger of their sampled offsets, then their sum; each child's ellipsoid
    fitted to its hull's corners at the search tolerance), when that is at most
    :data:`OFFSET_PROGRESS` of the leaf's own; else the plane across the ellipsoid's
    longest axis through the middle of the piece (a k-d tree's cut, which always makes the
    pieces smaller: a box-like piece needs two cuts before its offset drops, and the
    greedy choice alone then slices it into slabs that all stick out as far)."""
    own, n = meter.witness(_sound_body(leaf, shape, search.solid.weld), OFFSET_SAMPLES)
    V = leaf.piece.boundary_points
    axes = _directions(leaf.M)
    planes = [
        (normal, float(offset))
        for normal in ([n] if n.any() else []) + axes
        for offset in _spread(V @ normal)
    ]
    best, best_key = None, (np.inf, np.inf)
    for normal, offset in planes:
        if not _crossing(V, normal[None], np.array([offset]))[0]:
            continue  # a child without volume
        estimates = []
        for sign in (1.0, -1.0):
            piece = leaf.piece.cut(sign * normal, sign * offset)
            points = piece.points(search.solid.boundary)
            if len(piece.boundary) == 0 or len(points) == 0:
                break
            c, M = _enclosing(points, shape, SEARCH_TOL)  # on the points' hull vertices
            body = body_from_ellipsoid(c, M, sphere=shape == "sphere")
            estimates.append(meter.estimate(body, OFFSET_SAMPLES))
        else:
            key = (max(estimates), sum(estimates))
            if key < best_key:
                best, best_key = (normal, offset), key
    if best is not None and best_key[0] <= OFFSET_PROGRESS * own:
        return best
    longest = axes[0]
    x = V @ longest
    return longest, 0.5 * (float(x.min()) + float(x.max()))


def _spread(x: NDArray) -> NDArray:
    """Points at :data:`OFFSET_FRACTIONS` of the range of ``x``."""
    low, high = float(x.min()), float(x.max())
    return low + (high - low) * np.asarray(OFFSET_FRACTIONS)


def _stopped(count: int, why: str) -> str:
    """``stopped at 2 bodies: WHY`` (the note of a cover with fewer bodies than asked)."""
    return f"stopped at {count} bod{'y' if count == 1 else 'ies'}: {why}"


def _best_sectors(
    search: _Search, bodies: int, growths: list[_Growth]
) -> tuple[dict, list[_Leaf]] | None:
    """The part cut into an even number ``m`` (4 to ``bodies``) of equal sectors about
    one axis of its ellipsoid (:meth:`_Search.sectors`), the ``m`` and axis whose union
    is smallest, if that is smaller than any union the cut-by-cut ``growths`` reached
    with at most ``m`` leaves; else None."""
    best, best_union = None, np.inf
    for m in range(4, bodies + 1, 2):
        reached = min(u for g in growths for count, u in g.trail.items() if count <= m)
        for axis in range(search.solid.dimension if search.solid.dimension == 3 else 1):
            sectors = search.sectors(axis, m)
            if sectors is None:
                continue
            union = search.union(sectors[1])
            if union < min(best_union, reached):
                best, best_union = sectors, union
    return best


def _sound_body(leaf: _Leaf, shape: str, weld: float) -> Body:
    """The leaf's ellipsoid as a body, grown until it holds every hull point of its piece
    as computed from the stored semi-axes and pose, then by ``weld`` (``Solid.weld``).

    Scaling the semi-axes by ``s = 1 + w / a_min`` covers every point within ``w`` of the
    body: for a unit ``u`` in the body's frame the scaled body's support function is
    ``s |diag(a) u| >= |diag(a) u| + (w / a_min) a_min``, the support function of the body
    swept by a ball of radius ``w``. (Adding ``w`` to each semi-axis would not do:
    ``|diag(a + w) u| <= |diag(a) u| + w``, equal only along an axis.)
    """
    body = body_from_ellipsoid(leaf.center, leaf.M, sphere=shape == "sphere")
    for _ in range(8):
        worst = body_holds(body, leaf.points)
        if worst < 1.0:
            if weld > 0.0:
                grow = 1.0 + weld / body.semi_axes.min()
                body = Body(body.semi_axes * (grow * (1.0 + 1e-12)), body.pose)
            return body
        body = Body(body.semi_axes * np.sqrt(worst) * (1.0 + 1e-9), body.pose)
    raise RuntimeError("a body could not be made to hold its piece")  # pragma: no cover


def check_cover(solid: Solid, tree: dict, bodies: list[Body] | tuple[Body, ...]) -> float:
    """Re-derive every leaf's piece from the tree and return the largest
    ``(x - p)^T M (x - p)`` of its hull points in its body (at most 1 for a sound cover).

    Raises
    ------
    ValueError
        When the tree is malformed or does not use every body exactly once.
    """
    seen: list[int] = []
    worst = 0.0
    n = solid.dimension
    stack = [(tree, Piece.whole(solid.boundary))]
    while stack:
        node, piece = stack.pop()
        if not isinstance(node, dict):
            raise ValueError("tree: expected nested mappings")
        if "body" in node and "plane" not in node:
            k = node["body"]
            if not isinstance(k, int) or not 0 <= k < len(bodies) or k in seen:
                raise ValueError(f"tree: body {k!r} is not a new index below {len(bodies)}")
            seen.append(k)
            points = piece.points(solid.boundary)
            if len(points):
                worst = max(worst, body_holds(bodies[k], points))
            continue
        plane = np.asarray(node.get("plane"), dtype=float)
        if plane.shape != (n + 1,) or not np.isfinite(plane).all():
            raise ValueError(f"tree: plane: expected {n + 1} finite numbers")
        normal, offset = plane[:n], float(plane[n])
        stack.append((node.get("below"), piece.cut(normal, offset)))
        stack.append((node.get("above"), piece.cut(-normal, -offset)))
    if sorted(seen) != list(range(len(bodies))):
        raise ValueError(f"tree: expected leaves for bodies 0..{len(bodies) - 1}, got {seen}")
    return worst
