"""Sound covers of a part by K ellipsoids (or K spheres, for comparison).

The fit grows a binary tree of cutting planes (:mod:`kcplan.cover.partition`). Each leaf
is a piece of the part with the smallest ellipsoid that holds the piece's hull points
(Khachiyan's approximation, :func:`kcplan.geometry.enclosing.minimum_volume_ellipsoid`,
then scaled until every point is inside). Starting from the whole part, the fit splits,
one leaf at a time, the piece whose best cut shrinks the union of the ellipsoids most,
until there are ``bodies`` leaves, or until the bodies' total volume is within
``1 + max_excess`` of the part's (the total bounds the union's volume from above), or
until no cut makes the union smaller.

*Candidate cuts* of a piece are planes across the axes of its ellipsoid and of the part's
frame, at seven quantiles of the piece's boundary points along each. A candidate is
scored by the union's volume on a fixed quasi-random sample (the same points for every
candidate, so comparisons are free of sampling noise), with the children fitted to their
clipped boundary points only; the chosen children are then fitted to their full hull
points (cell corners inside the part included), which is what makes the cover sound.

The cover is of the *input's own* surface and solid (no remeshing, no decomposition
library: an approximate convex decomposition such as CoACD remeshes the input and
simplifies its hulls, so its pieces need not cover the part).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull, QhullError
from scipy.stats import qmc

from kcplan.cover.bodies import body_from_ellipsoid, body_holds, body_matrix
from kcplan.cover.partition import Piece
from kcplan.cover.solid import Solid
from kcplan.geometry.enclosing import (
    FLAT_RATIO,
    ellipsoid_axes,
    ellipsoid_volume,
    enclose,
    mahalanobis_sq,
    minimum_volume_ellipsoid,
)
from kcplan.geometry.robot import MAX_BODIES, Body, Robot

__all__ = ["FIT_VERSION", "SHAPES", "Cover", "check_cover", "fit_cover"]

FIT_VERSION = 1
"""Changes whenever the fit would give other bodies for the same input (cache key)."""
SHAPES = ("ellipsoid", "sphere")
CUT_QUANTILES = (0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875)
SEARCH_TOL = 1e-2
"""Khachiyan tolerance while scoring candidate cuts (volume within about 1.5 %)."""
FINAL_TOL = 1e-4
"""Khachiyan tolerance of the bodies kept (volume within about 0.015 % of the MVEE's)."""
SCORE_SAMPLES = 2**15
"""Quasi-random points that score candidate cuts."""


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
    node: dict
    piece: Piece
    points: NDArray  # the piece's hull points (partition.Piece.points), which M holds
    center: NDArray
    M: NDArray
    candidates: list | None = None  # from _candidates(), once computed
    split: tuple | None = None  # (gain, normal, offset) under the current union


def _enclosing(points: NDArray, shape: str, tol: float) -> tuple[NDArray, NDArray]:
    """An ellipsoid (or ball) holding every point, as ``(center, M)``."""
    if shape == "sphere":
        from trimesh.nsphere import minimum_nsphere

        try:
            P = points[ConvexHull(points).vertices]
        except (QhullError, ValueError):
            P = points
        try:
            c, r = minimum_nsphere(P)
        except (QhullError, ValueError):  # a flat set: the ball about its box's centre
            c = 0.5 * (P.min(axis=0) + P.max(axis=0))
            r = np.linalg.norm(P - c, axis=1).max()
        c = np.asarray(c, dtype=float)
        r = max(float(r), FLAT_RATIO * max(float(np.abs(P).max()), 1e-30))
        M = np.eye(len(c)) / r**2
    else:
        c, M = minimum_volume_ellipsoid(points, tol)
    return c, enclose(points, c, M)


def _directions(M: NDArray) -> list[NDArray]:
    """Unit normals of candidate cuts: the ellipsoid's axes, then the frame's axes not
    already (nearly) among them."""
    _, R = ellipsoid_axes(M)
    out = [R[:, k] for k in range(len(M) - 1, -1, -1)]  # longest axis first
    for e in np.eye(len(M)):
        if all(abs(float(e @ d)) < 0.999 for d in out):
            out.append(e)
    return out


class _Scorer:
    """Union volume on a fixed quasi-random sample of the part's bounding box, padded by a
    tenth (what a body has outside the box is added from its exact volume)."""

    def __init__(self, solid: Solid):
        V = solid.boundary.reshape(-1, solid.dimension)
        low, high = V.min(axis=0), V.max(axis=0)
        pad = 0.1 * (high - low)
        low, high = low - pad, high + pad
        u = qmc.Sobol(solid.dimension, seed=0).random(SCORE_SAMPLES)
        self.points = low + u * (high - low)
        self.cell = float(np.prod(high - low)) / SCORE_SAMPLES

    def inside(self, center: NDArray, M: NDArray) -> NDArray[np.bool_]:
        return mahalanobis_sq(self.points, center, M) <= 1.0

    def outside(self, M: NDArray, inside: NDArray[np.bool_]) -> float:
        """Volume of an ellipsoid outside the sampled region (exact volume less the
        sampled part), so that a cut cannot hide volume there."""
        return max(0.0, ellipsoid_volume(M) - float(inside.sum()) * self.cell)


def fit_cover(
    solid: Solid,
    bodies: int | None = None,
    max_excess: float | None = None,
    shape: str = "ellipsoid",
    progress: Callable[[str], None] | None = None,
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

    Returns
    -------
    Cover
        ``cover.worst <= 1``: every hull point of every piece is in its body.
    """
    if shape not in SHAPES:
        raise ValueError(f"shape: expected one of {', '.join(SHAPES)}, got {shape!r}")
    if (bodies is None) == (max_excess is None):
        raise ValueError("expected exactly one of bodies and max_excess")
    if bodies is not None and not 1 <= bodies <= MAX_BODIES:
        raise ValueError(f"bodies: expected 1 to {MAX_BODIES}, got {bodies}")
    if max_excess is not None and not max_excess > 0:
        raise ValueError(f"max_excess: expected a positive number, got {max_excess}")
    start = time.perf_counter()
    target = bodies if bodies is not None else MAX_BODIES
    whole = Piece.whole(solid.boundary)
    points = whole.points(solid.boundary)
    c, M = _enclosing(points, shape, FINAL_TOL)
    root: dict = {}
    leaves = [_Leaf(root, whole, points, c, M)]
    scorer = _Scorer(solid)
    inside = [scorer.inside(c, M)]
    note = ""
    while len(leaves) < target:
        if max_excess is not None:
            total = sum(ellipsoid_volume(leaf.M) for leaf in leaves)
            if total <= (1.0 + max_excess) * solid.volume:
                break
        for k, leaf in enumerate(leaves):
            if leaf.split is None:
                others = np.zeros(len(scorer.points), dtype=bool)
                for j, mask in enumerate(inside):
                    if j != k:
                        others |= mask
                if leaf.candidates is None:
                    leaf.candidates = _candidates(solid, leaf, shape, scorer)
                leaf.split = _best_cut(leaf, scorer, others)
        k = max(range(len(leaves)), key=lambda i: leaves[i].split[0])
        gain, normal, offset = leaves[k].split[:3]
        if gain <= 0:
            note = f"stopped at {len(leaves)} bodies: no cut made the cover smaller"
            break
        leaf = leaves.pop(k)
        inside.pop(k)
        leaf.node["plane"] = [*normal.tolist(), float(offset)]
        for side, sign in (("below", 1.0), ("above", -1.0)):
            piece = leaf.piece.cut(sign * normal, sign * offset)
            points = piece.points(solid.boundary)
            c, M = _enclosing(points, shape, FINAL_TOL)
            leaf.node[side] = {}
            leaves.append(_Leaf(leaf.node[side], piece, points, c, M))
            inside.append(scorer.inside(c, M))
        for other in leaves:  # the union changed: every score is stale
            other.split = None
        if progress is not None:
            progress(f"{len(leaves)} bodies, {time.perf_counter() - start:.1f} s")
    if max_excess is not None and len(leaves) == MAX_BODIES:
        total = sum(ellipsoid_volume(leaf.M) for leaf in leaves)
        if total > (1.0 + max_excess) * solid.volume:
            note = f"stopped at {MAX_BODIES} bodies, the most a robot may have"
    out = []
    for k, leaf in enumerate(leaves):
        leaf.node["body"] = k
        out.append(_sound_body(leaf, shape))
    worst = max(body_holds(body, leaf.points) for body, leaf in zip(out, leaves, strict=True))
    return Cover(solid, tuple(out), root, shape, time.perf_counter() - start, note, worst)


def _candidates(solid: Solid, leaf: _Leaf, shape: str, scorer: _Scorer) -> list[tuple]:
    """Candidate cuts of ``leaf`` as ``(normal, offset, covered, outside)``: the sample
    points the two children's ellipsoids (fitted to their clipped boundary points) hold,
    and their volume outside the sampled region."""
    out = []
    V = leaf.piece.boundary_points
    for normal in _directions(leaf.M):
        for offset in np.unique(np.quantile(V @ normal, CUT_QUANTILES)):
            covered = np.zeros(len(scorer.points), dtype=bool)
            outside = 0.0
            for sign in (1.0, -1.0):
                part = leaf.piece.cut(sign * normal, sign * offset).boundary
                if len(part) == 0:
                    break
                c, M = _enclosing(part.reshape(-1, solid.dimension), shape, SEARCH_TOL)
                inside = scorer.inside(c, M)
                covered |= inside
                outside += scorer.outside(M, inside)
            else:
                out.append((normal, float(offset), covered, outside))
    return out


def _best_cut(leaf: _Leaf, scorer: _Scorer, others: NDArray) -> tuple:
    """The candidate cut of ``leaf`` that leaves the smallest union: ``(gain, normal,
    offset)`` with the gain in volume units (may be negative)."""
    inside = scorer.inside(leaf.center, leaf.M)
    base = int((others | inside).sum()) * scorer.cell + scorer.outside(leaf.M, inside)
    best = (-np.inf, None, None)
    for normal, offset, covered, outside in leaf.candidates:
        gain = base - int((others | covered).sum()) * scorer.cell - outside
        if gain > best[0]:
            best = (gain, normal, offset)
    return best


def _sound_body(leaf: _Leaf, shape: str) -> Body:
    """The leaf's ellipsoid as a body, grown until it holds every hull point of its piece
    as computed from the stored semi-axes and pose."""
    body = body_from_ellipsoid(leaf.center, leaf.M, sphere=shape == "sphere")
    for _ in range(8):
        worst = body_holds(body, leaf.points)
        if worst < 1.0:
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
