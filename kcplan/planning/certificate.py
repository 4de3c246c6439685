"""Edge certificates with KC guards: the logic of the motion validator, without OMPL.

A guard is the robot's ellipsoid inflated to ``(1 + eps) a`` at some pose on the edge.
If FCL says the robot there has clearance ``d``, the guard is free for every
``eps <= d / max(a)`` (``(1 + eps) E_a`` lies inside ``E_a`` grown by a ball of radius
``eps max(a)``), and every pose whose KC coordinates relative to the guard lie in the
convex lower bound ``P_eps`` keeps the robot inside the free guard. Along an edge the KC
coordinates seen from a pose on it move on a line through the origin
(:class:`kcplan.geometry.pose.Edge`), so one matrix-vector product (the gauge of
``P_eps``) says how far the guard covers the edge in each direction.
"""

from __future__ import annotations

import bisect
import hashlib
import math
import os
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from kcplan.files import atomic_output
from kcplan.geometry import containment as containment_module
from kcplan.geometry import ellipsoid as ellipsoid_module
from kcplan.geometry import rotations as rotations_module
from kcplan.geometry.pose import Edge
from kcplan.kc import convex as convex_module
from kcplan.kc.convex import ConvexLowerBound
from kcplan.world.collision import CollisionWorld

__all__ = ["DEFAULT_LADDER", "GuardLadder", "EdgeCertifier", "polytope_cache_dir"]

DEFAULT_LADDER = {
    2: (0.002, 0.005, 0.01, 0.02, 0.04, 0.08, 0.16, 0.32, 0.64, 1.28),
    3: (0.005, 0.02, 0.08, 0.3),
}
"""Guard inflations built per robot. 2D polytopes cost about 0.15 s each, 3D ones 1 to
3 s (72 vertices, 2048 half-spaces), hence the shorter 3D ladder."""


CACHE_ENV = "KCPLAN_CACHE_DIR"
"""Environment variable naming the polytope cache folder; ``off`` disables the cache.
Default ``$XDG_CACHE_HOME/kcplan`` (``~/.cache/kcplan``)."""


def polytope_cache_dir() -> Path | None:
    """Folder of cached guard polytopes, or None when the cache is off."""
    value = os.environ.get(CACHE_ENV)
    if value == "off":
        return None
    if value:
        return Path(value)
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "kcplan"


@lru_cache(maxsize=1)
def _algorithm_digest() -> str:
    # A cached polytope is only reused by the exact code that built it.
    h = hashlib.sha256()
    for module in (convex_module, containment_module, rotations_module, ellipsoid_module):
        h.update(Path(module.__file__).read_bytes())
    return h.hexdigest()[:16]


@lru_cache(maxsize=64)
def _halfspaces(semi_axes: tuple, inflation: float) -> tuple[np.ndarray, np.ndarray]:
    """``(A, c)`` of ``ConvexLowerBound(a, eps)``: from memory, the disk cache, or built.

    Building costs 0.15 s (2D) to 5 s (3D) per polytope; every ``kcplan plan`` and every
    benchmark run is a new process, so the rows are kept on disk, keyed by ``(a, eps)``
    and a digest of the code that builds them, and written atomically.
    """
    folder = polytope_cache_dir()
    key = hashlib.sha256(repr((semi_axes, inflation, _algorithm_digest())).encode()).hexdigest()
    cached = folder / f"polytope-{key[:24]}.npz" if folder else None
    if cached is not None and cached.is_file():
        try:
            with np.load(cached) as data:
                if str(data["key"]) == key:
                    return data["A"], data["c"]
        except (OSError, ValueError, KeyError):
            pass  # unreadable or foreign file: rebuild and overwrite
    A, c = ConvexLowerBound(np.array(semi_axes), inflation).halfspaces
    if cached is not None:
        try:
            folder.mkdir(parents=True, exist_ok=True)
            with atomic_output(cached) as tmp:
                np.savez(tmp, A=A, c=c, key=key)
        except OSError:
            pass  # a read-only home only costs the rebuild next time
    return A, c


class GuardLadder:
    """Convex lower bounds of one robot for an increasing list of guard inflations.

    Polytopes depend only on ``(a, eps)``, never on the guard's pose, so they are built
    once and shared: in memory per process, and on disk across processes (see
    :func:`polytope_cache_dir`; set ``KCPLAN_CACHE_DIR=off`` to always rebuild).

    Parameters
    ----------
    semi_axes : array_like, shape (n,)
    inflations : sequence of float, optional
        Increasing guard inflations; default :data:`DEFAULT_LADDER`.
    """

    def __init__(self, semi_axes: ArrayLike, inflations: Sequence[float] | None = None):
        a = np.asarray(semi_axes, dtype=float)
        n = len(a)
        levels = tuple(sorted(float(e) for e in (inflations or DEFAULT_LADDER[n])))
        self.semi_axes, self.inflations = a, np.array(levels)
        rows = [_halfspaces(tuple(a.tolist()), e) for e in levels]
        # rows scaled to A_i / c_i (c > 0: the origin is interior), so the gauge needs
        # only a matrix-vector product and two reductions
        self._scaled = [A / c[:, None] for A, c in rows]
        self._levels = levels
        self.scale = float(a.max())

    def level_for(self, clearance: float) -> int:
        """Index of the largest inflation a guard with this clearance allows, or -1."""
        return bisect.bisect_right(self._levels, clearance / self.scale) - 1

    def reach(self, level: int, direction: np.ndarray) -> tuple[float, float]:
        """How far ``P_eps = {xi : A xi <= c}`` extends along ``+direction`` and
        ``-direction``: ``1 / max_i (A_i d / c_i)`` and ``1 / max_i (-A_i d / c_i)``
        (``inf`` where no row bounds that side)."""
        proj = self._scaled[level] @ direction
        top, bottom = float(proj.max()), float(proj.min())
        return (1.0 / top if top > 0.0 else math.inf, -1.0 / bottom if bottom < 0.0 else math.inf)


class EdgeCertifier:
    """Prove edges collision-free with midpoint KC guards, or reject them.

    ``world`` is anything with ``in_collision(pose) -> bool`` and
    ``safe_clearance(pose) -> float`` (a distance from the robot to the obstacles that is
    never an overestimate); :class:`kcplan.world.CollisionWorld` is one.

    ``check(p1, p2)`` follows OMPL's ``MotionValidator`` contract: ``p1`` is assumed
    valid, ``p2`` is not. It first rejects a colliding ``p2`` with one collision query.
    Then it places a guard at the midpoint of the uncovered stretch ``[s0, s1]`` of the
    edge, takes one clearance query there, picks the largest ladder inflation that
    clearance allows, and removes the stretch the guard covers; what is left on either
    side is certified the same way (this is the "bisection" fallback, with each split
    placed where the previous guard's reach ends). A zero clearance is a collision, a
    clearance below the smallest ladder level or more than ``max_guards`` guards means
    "not proven": both reject the edge. With ``fallback="discrete"``, an edge the first
    guard does not cover is instead sampled at ``resolution`` (in units of ``s``) with
    collision queries, as OMPL's discrete validator does; that mode is not exact.

    Far from obstacles a guard's clearance ``d`` alone covers more: no robot point moves
    more than ``sweep_speed * |ds|`` (:meth:`Edge.sweep_speed`), so the stretch
    ``|s - m| < d / sweep_speed`` is free too. A guard whose ball covers its whole stretch
    needs no gauge; otherwise it covers the larger of the two stretches on each side
    (``ball_certified`` counts guards where the ball won); the KC polytope wins near
    obstacles and for rotations, the ball in open space.

    Counters (``counters`` dict): ``edges`` checked, ``certified_one_guard``,
    ``guards`` (clearance queries), ``bisection_nodes`` (guards after the first),
    ``collision_queries``, ``rejected``, ``rejected_end_state``, ``not_proven``,
    ``ball_certified``.

    Not thread-safe (one FCL robot object is reused).
    """

    def __init__(
        self,
        world: CollisionWorld,
        semi_axes: ArrayLike | None = None,
        ladder: GuardLadder | None = None,
        fallback: str = "bisection",
        max_guards: int = 256,
    ):
        if fallback not in ("bisection", "discrete"):
            raise ValueError(f"fallback: expected 'bisection' or 'discrete', got {fallback!r}")
        self.world = world
        a = np.asarray(world.semi_axes if semi_axes is None else semi_axes, dtype=float)
        self.ladder = ladder or GuardLadder(a)
        self.fallback = fallback
        self.max_guards = int(max_guards)
        self.n = len(a)
        self.counters = dict.fromkeys(
            (
                "edges",
                "certified_one_guard",
                "guards",
                "bisection_nodes",
                "collision_queries",
                "rejected",
                "rejected_end_state",
                "not_proven",
                "ball_certified",
            ),
            0,
        )
        self.guard_log: list[tuple[np.ndarray, float]] | None = None  # (pose, eps) if enabled

    def check(self, pose1: ArrayLike, pose2: ArrayLike, resolution: float = 0.01) -> bool:
        """True when the whole edge ``pose1 -> pose2`` is proven free (see class docs)."""
        c = self.counters
        c["edges"] += 1
        c["collision_queries"] += 1
        if self.world.in_collision(pose2):
            c["rejected"] += 1
            c["rejected_end_state"] += 1
            return False
        edge = Edge(pose1, pose2, self.n)
        speed = edge.sweep_speed(self.ladder.scale) * (1.0 + 1e-9)
        pending = [(0.0, 1.0)]
        guards = 0
        while pending:
            s0, s1 = pending.pop()
            m = 0.5 * (s0 + s1)
            pose = edge.pose(m)
            d = self.world.safe_clearance(pose)
            guards += 1
            level = self.ladder.level_for(d)
            # the clearance ball alone: no robot point moves more than speed * |s - m|
            ball = d / speed if speed > 0.0 else math.inf
            if m - ball <= s0 and m + ball >= s1:  # covers the stretch: no gauge needed
                c["ball_certified"] += 1
                c["certified_one_guard"] += guards == 1
                if self.guard_log is not None:
                    eps = self.ladder.inflations[level] if level >= 0 else d / self.ladder.scale
                    self.guard_log.append((pose, float(eps)))
                continue
            if level < 0 and guards == 1 and d > 0.0 and self.fallback == "discrete":
                return self._sample(edge, resolution, m, m)
            if level < 0:  # touching (d = 0) or too close to prove anything
                c["guards"] += guards
                c["bisection_nodes"] += guards - 1
                c["rejected"] += 1
                c["not_proven"] += d > 0.0
                return False
            if self.guard_log is not None:
                self.guard_log.append((pose, float(self.ladder.inflations[level])))
            plus, minus = self.ladder.reach(level, edge.direction(m))
            # far from obstacles the clearance ball covers more than the top guard
            if ball > min(plus, minus):
                c["ball_certified"] += 1
            lo, hi = m - max(minus, ball), m + max(plus, ball)
            if guards == 1 and lo <= s0 and hi >= s1:
                c["certified_one_guard"] += 1
            if guards == 1 and self.fallback == "discrete" and (lo > s0 or hi < s1):
                return self._sample(edge, resolution, lo, hi)
            if guards >= self.max_guards and (lo > s0 or hi < s1):
                c["guards"] += guards
                c["bisection_nodes"] += guards - 1
                c["rejected"] += 1
                c["not_proven"] += 1
                return False
            if lo > s0:
                pending.append((s0, lo))
            if hi < s1:
                pending.append((hi, s1))
        c["guards"] += guards
        c["bisection_nodes"] += guards - 1
        return True

    def _sample(self, edge: Edge, resolution: float, lo: float, hi: float) -> bool:
        c = self.counters
        c["guards"] += 1
        steps = max(1, math.ceil(1.0 / resolution))
        for i in range(1, steps):
            s = i / steps
            if lo <= s <= hi:
                continue  # covered by the midpoint guard
            c["collision_queries"] += 1
            if self.world.in_collision(edge.pose(s)):
                c["rejected"] += 1
                return False
        return True
