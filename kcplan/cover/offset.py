"""How far a cover sticks out of its part: the largest distance from a point of the
cover to the part.

A cover that holds a gripper's finger may still stick out of it by centimetres, and a
grasp that leaves the finger a few millimetres from an object is then invalid for the
covered robot (issue 25: MotionBenchMaker's goals leave the Panda's hand and fingers
9-32 mm from the objects). Volume does not see this; the offset does.

Two measures:

*A bound* (:func:`offset_bound`, :class:`OffsetMeter`): for a body ``E`` and the part
``S``, an interval ``[low, high]`` that provably holds ``max_{x in E} dist(x, S)``
(every point of the ellipsoid, its inside included: a small object inside a cavity the
body spans collides with the body too). The proof has three pieces.

1. *Distance from surface samples.* The part's boundary triangles are sampled on a
   barycentric grid fine enough that every point of every triangle lies within ``h`` of
   a sample. (A point ``p`` of triangle ``ABC`` sees the three sides under angles that
   sum to 360 degrees, so one, say ``APB``, is at least 120 degrees, and then ``|AB|^2
   >= |PA|^2 + |PB|^2 + |PA| |PB| >= 3 min(|PA|, |PB|)^2``: every point is within
   ``longest side / sqrt(3)`` of a corner. A triangle cut into ``n^2`` similar ones of
   sides ``1/n`` as long has its grid within ``longest / (n sqrt(3)) <= h`` of every
   point.) With ``d(y)`` the distance from ``y`` to the nearest sample (a k-d tree,
   exact), ``dist(y, boundary) <= d(y) <= dist(y, boundary) + h``.
2. *Lipschitz.* ``dist(., S)`` changes by at most ``|x - y|`` between ``x`` and ``y``. For
   a box cell of the body's frame with centre ``y`` and half diagonal ``r``, every
   ``x`` of the cell has ``dist(x, S) <= d(y) + r`` (the boundary is part of ``S``),
   and, when ``y`` is inside ``S`` (winding number above 1/2), ``dist(x, S) <= max(0,
   r - (d(y) - h))`` (the ball of radius ``d(y) - h`` about ``y`` lies in ``S``).
   Whether a cell meets ``E`` is exact: the cell's point nearest the centre in the
   body's own metric is the clamp of 0 to the cell, coordinate by coordinate.
3. *Branch and bound.* Cells that meet ``E`` are halved until their bound is below what
   is asked (``below``), or below the best *attained* distance plus ``tol``: a cell
   centre inside ``E`` and outside ``S`` attains at least ``d(y) - h``, which is
   ``low``. ``high`` is the largest bound of any cell that was left.

The one floating-point caveat: a centre's side of the boundary is read from its winding
number, exact up to rounding for points not within rounding of a triangle; a centre
that close to the surface has ``d(y) - h < r`` and takes the first bound, which needs
no side.

*A sampled estimate* (:func:`cover_offsets`): points on every body's surface, those
outside the part (winding number below 1/2, :func:`kcplan.geometry.winding.
winding_numbers`), and their distance to the part's boundary triangles
(``trimesh.triangles.closest_point``). The true offset is at least the estimate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree
from trimesh.triangles import closest_point

from kcplan.cover.bodies import body_rotation
from kcplan.cover.solid import Solid
from kcplan.geometry.robot import Body
from kcplan.geometry.winding import winding_numbers

__all__ = ["OffsetBound", "OffsetMeter", "cover_offsets", "offset_bound"]

_PAIRS = 2**20
"""Point-triangle pairs measured at once (bounds the temporary arrays)."""
MAX_SURFACE_SAMPLES = 1_000_000
"""At most this many surface samples; ``h`` grows to stay below it."""
MAX_CELLS = 400_000
"""Cells alive at once in the branch and bound; beyond, the coarsest bound is reported."""


@dataclass(frozen=True)
class OffsetBound:
    """``low <= max_{x in body} dist(x, part) <= high``, in the part's unit.

    ``cells`` is how many cells the branch and bound measured (its cost).
    """

    low: float
    high: float
    cells: int


def _steps(triangles: NDArray, h: float) -> NDArray[np.int64]:
    """Grid steps per side of each triangle, so that its grid is within ``h`` of it."""
    sides = np.linalg.norm(triangles - np.roll(triangles, 1, axis=1), axis=2).max(axis=1)
    return np.maximum(1, np.ceil(sides / (math.sqrt(3.0) * h))).astype(np.int64)


def _grid_count(triangles: NDArray, h: float) -> int:
    n = _steps(triangles, h)
    return int(((n + 1) * (n + 2) // 2).sum())


def _grid_points(triangles: NDArray, h: float) -> NDArray[np.float64]:
    """Points on every triangle, each point of the triangle within ``h`` of one (module
    docstring, piece 1), shape ``(m, 3)``."""
    steps = _steps(triangles, h)
    out = []
    for n in np.unique(steps):
        T = triangles[steps == n]
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        w = np.stack([i[keep], j[keep], n - i[keep] - j[keep]], axis=1) / n  # (g, 3)
        out.append(np.einsum("gk,tkd->tgd", w, T).reshape(-1, 3))
    return np.concatenate(out)


class OffsetMeter:
    """What :func:`offset_bound` needs of one part, built once: its boundary sampled
    within ``h`` (module docstring, piece 1) in a k-d tree.

    Parameters
    ----------
    solid : Solid
        A 3D part.
    h : float, optional
        Sample spacing bound, in the part's unit (default: a 1000th of the part's size,
        coarser when the samples would exceed :data:`MAX_SURFACE_SAMPLES`).
    """

    def __init__(self, solid: Solid, h: float | None = None):
        if solid.dimension != 3:
            raise ValueError(f"solid: expected a 3D part, got {solid.dimension}D")
        self.solid = solid
        self.triangles = np.asarray(solid.boundary, dtype=float)
        h = solid.size / 1000.0 if h is None else float(h)
        count = _grid_count(self.triangles, h)
        if count > MAX_SURFACE_SAMPLES:  # the count falls like 1 / h^2
            h *= math.sqrt(count / MAX_SURFACE_SAMPLES)
        self.h = h
        self.tree = cKDTree(_grid_points(self.triangles, h))
        # estimates need no fine grid, and a fine one makes far queries slow
        self.coarse_h = max(h, solid.size / 200.0)
        self.coarse = cKDTree(_grid_points(self.triangles, self.coarse_h))

    def inside(self, points: NDArray) -> NDArray[np.bool_]:
        """Whether each point is inside the part (winding number above 1/2)."""
        if len(points) == 0:
            return np.zeros(0, dtype=bool)
        return winding_numbers(points, self.triangles) > 0.5

    def estimate(self, body: Body, samples: int = 300, seed: int = 0) -> float:
        """A sampled estimate (at most the true offset, up to the coarse spacing) of how
        far the body sticks out: the largest distance to the part of ``samples`` points on
        its surface outside the part (cheap; ranks candidates, proves nothing)."""
        return self.witness(body, samples, seed)[0]

    def witness(
        self, body: Body, samples: int = 300, seed: int = 0
    ) -> tuple[float, NDArray[np.float64]]:
        """:meth:`estimate` and the unit direction from the part's nearest sample to the
        surface point that attains it (zeros when the body is inside)."""
        points = _surface(body, samples, np.random.default_rng(seed))
        d, index = self.coarse.query(points)
        far = d > self.coarse_h  # nearer than the spacing is as good as on the surface
        outside = np.zeros(len(points), dtype=bool)
        outside[far] = ~self.inside(points[far])
        if not outside.any():
            return float(d.max()) if not far.any() else 0.0, np.zeros(3)
        k = np.flatnonzero(outside)[np.argmax(d[outside])]
        direction = points[k] - self.coarse.data[index[k]]
        return float(d[k]), direction / max(float(np.linalg.norm(direction)), 1e-300)

    def bound(
        self, body: Body, tol: float, below: float | None = None, max_cells: int = MAX_CELLS
    ) -> OffsetBound:
        """Bound ``max_{x in body} dist(x, part)`` (module docstring, pieces 2-3).

        Parameters
        ----------
        body : Body
            In the part's frame.
        tol : float
            Stop refining when the bound is within ``tol`` of the attained distance
            (part's unit; the result's ``high - low`` is about ``tol + h``).
        below : float, optional
            Stop as soon as the offset is proved to be at most this (``high <= below``)
            or more than this (``low > below``); cheaper than the value.
        max_cells : int
            Cells alive at once, beyond which refinement stops (``high`` stays sound).
        """
        a = np.asarray(body.semi_axes, dtype=float)
        R, c = body_rotation(body), np.asarray(body.position, dtype=float)
        lo, hi = -a[None, :], a[None, :]
        low, high, measured = 0.0, 0.0, 0
        floor = 0.25 * max(tol, self.h)  # cells below this half diagonal are not split
        while len(lo):
            # keep the cells that meet the body: their point nearest its centre in its metric
            near = np.clip(0.0, lo, hi)
            meets = ((near / a) ** 2).sum(axis=1) <= 1.0
            lo, hi = lo[meets], hi[meets]
            y = 0.5 * (lo + hi)
            r = 0.5 * np.linalg.norm(hi - lo, axis=1)
            world = c + y @ R.T
            d, _ = self.tree.query(world)
            measured += len(y)
            upper = d + r
            cutoff = max(low + tol, -np.inf if below is None else below)
            open_ = upper > cutoff
            inside = np.zeros(len(y), dtype=bool)
            inside[open_] = self.inside(world[open_])
            upper[inside] = np.maximum(0.0, r[inside] - (d[inside] - self.h))
            in_body = ((y / a) ** 2).sum(axis=1) <= 1.0
            attained = np.where(in_body & ~inside, d - self.h, 0.0)
            low = max(low, float(attained.max(initial=0.0)))
            if below is not None and low > below:
                return OffsetBound(low, max(high, float(upper.max())), measured)
            cutoff = max(low + tol, -np.inf if below is None else below)
            split = (upper > cutoff) & (r > floor)
            if len(lo) * 8 > max_cells:
                split[:] = False
            high = max(high, float(upper[~split].max(initial=0.0)))
            lo, hi = _halve(lo[split], hi[split])
        return OffsetBound(low, max(high, low), measured)


def _halve(lo: NDArray, hi: NDArray) -> tuple[NDArray, NDArray]:
    """Every cell cut in two across each side at least half its longest (2, 4 or 8
    cells per cell), so that cells stay within an aspect ratio of 2."""
    side = hi - lo
    cut = side >= 0.5 * side.max(axis=1, keepdims=True)
    for axis in range(3):
        rows = cut[:, axis]
        mid = 0.5 * (lo[rows, axis] + hi[rows, axis])
        lo2, hi2 = lo[rows].copy(), hi[rows].copy()
        hi = hi.copy()
        hi[rows, axis] = mid
        lo2[:, axis] = mid
        lo, hi = np.concatenate([lo, lo2]), np.concatenate([hi, hi2])
        cut = np.concatenate([cut, cut[rows]])
    return lo, hi


def offset_bound(solid: Solid, body: Body, tol: float | None = None) -> OffsetBound:
    """``low <= max_{x in body} dist(x, solid) <= high`` (module docstring), within about
    ``tol`` (default a 1000th of the part's size) plus the sample spacing."""
    meter = OffsetMeter(solid)
    return meter.bound(body, solid.size / 1000.0 if tol is None else tol)


def _surface(body: Body, samples: int, rng: np.random.Generator) -> NDArray[np.float64]:
    u = rng.normal(size=(samples, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return (u * body.semi_axes) @ body_rotation(body).T + body.position


def _distances(points: NDArray[np.float64], triangles: NDArray[np.float64]) -> NDArray:
    """Distance from each point to the nearest of the triangles, shape ``(len(points),)``."""
    out = np.full(len(points), np.inf)
    per = max(1, _PAIRS // len(triangles))
    for start in range(0, len(points), per):
        P = points[start : start + per]
        pairs_t = np.repeat(triangles[None], len(P), axis=0).reshape(-1, 3, 3)
        pairs_p = np.repeat(P, len(triangles), axis=0)
        d = np.linalg.norm(closest_point(pairs_t, pairs_p) - pairs_p, axis=1)
        out[start : start + per] = d.reshape(len(P), len(triangles)).min(axis=1)
    return out


def cover_offsets(
    solid: Solid, bodies: tuple[Body, ...] | list[Body], samples: int = 400, seed: int = 0
) -> NDArray[np.float64]:
    """How far each body sticks out of the part (3D), estimated from ``samples`` points
    on its surface: shape ``(len(bodies),)``, in the part's unit (0 for a body inside).
    A lower estimate (see :func:`offset_bound` for a bound).

    Raises
    ------
    ValueError
        For a 2D part (outlines are not measured).
    """
    if solid.dimension != 3:
        raise ValueError(f"solid: expected a 3D part, got {solid.dimension}D")
    rng = np.random.default_rng(seed)
    triangles = np.asarray(solid.boundary, dtype=float)
    out = np.zeros(len(bodies))
    for k, body in enumerate(bodies):
        points = _surface(body, samples, rng)
        outside = points[winding_numbers(points, triangles) < 0.5]
        if len(outside):
            out[k] = float(_distances(outside, triangles).max())
    return out
