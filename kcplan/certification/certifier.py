"""The edge certifier: where certificates, guards, the guard cache and rejection meet.

This module holds the one piece of logic that combines certificates
(:mod:`kcplan.certification.certificates`) into a decision about an OMPL edge; it does not
import OMPL (:class:`kcplan.planning.validator.KCMotionValidator` is the thin adapter).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike

from kcplan.certification.certificates import (
    CERTIFICATE_NAMES,
    ClearanceBall,
    FreeRegionPlanes,
    KCPolytope,
)
from kcplan.certification.domain import PoseDomain
from kcplan.certification.guard import Guard, GuardCache
from kcplan.certification.ladder import GuardLadder
from kcplan.geometry.pose import Edge, pose_size
from kcplan.geometry.robot import Robot
from kcplan.world.occupancy import CoreOccupancy

__all__ = [
    "CERTIFICATE_SETS",
    "advance",
    "COUNTER_NAMES",
    "DEFAULT_PROBES",
    "EdgeCertifier",
    "check_certificates",
    "probe_points",
]

CERTIFICATE_SETS = {
    "ca": ("ball",),
    "kc-paper": ("polytope",),
    "kc": ("region",),
    "kc-lever": ("region-lever",),
}
"""The certificate sets of the ablation planners (``ca-*``, ``kc-*-paper``, ``kc-*``,
``kc-*-lever``).
``region`` includes a rotation-aware clearance ball per obstacle piece, so ``rotation``
adds nothing to it; added to it, ``polytope`` won at most 0.001 % of the certified edge
parameter on the six narrow passages (``benchmarks/RESULTS.md``, section 0.1), so it is
left out."""

COUNTER_NAMES = (
    "edges",
    "rejected",
    "rejected_end_state",
    "rejected_sweep",
    "rejected_occupancy",
    "rejected_probe",
    "rejected_guard",
    "not_proven",
    "certified_by_endpoints",
    "certified_one_guard",
    "guards",
    "endpoint_guards",
    "cached_guards",
    "bisection_nodes",
    "collision_queries",
    "occupancy_rejections",
    "occupancy_queries",
    "probes",
    "probed_edges",
    "screened_edges",  # screen() calls (a lazy planner's tree edges; their probes: probes)
)

MAX_SCREEN_PROBES = 64
"""Probes of one :meth:`EdgeCertifier.screen` at most (the kernel's ``kMaxScreenProbes``)."""
DEFAULT_PROBES = 3
"""Collision probes per edge before its guards (step 3). Chosen by the ablation of
``benchmarks/RESULTS.md`` section 10 (``kc-rrtconnect-noprobe``: none)."""
PROBE_WARMUP, PROBE_ODDS, PROBE_EVERY = 64, 5, 16
"""The probes' schedule: every edge that reaches step 3's probes is probed while fewer
than ``PROBE_WARMUP`` were, or while at least one probed edge in ``PROBE_ODDS`` was
rejected by a probe; otherwise only every ``PROBE_EVERY``-th, so that the rate stays
measured. A probe costs a collision query on every edge it does not reject, and a
guard costs several (a region query meets every piece near the robot): on HRM's maze
about half the probed edges are rejected, on the narrow passages of the suite 1 %."""
LEARN_WARMUP, LEARN_ODDS, LEARN_EVERY = 256, 2, 8
"""The occupancy grid's learning schedule: the cell of every colliding state is tested
(one ball query) while fewer than ``LEARN_WARMUP`` cells were, or while the grid rejects
at least one state or edge per ``LEARN_ODDS`` tested cells; otherwise at every
``LEARN_EVERY``-th colliding state. A ball query costs about half a collision query of
the robot, and a blocked cell saves one each time it rejects: on HRM's maze the grid
rejects about 0.66 per tested cell, on its cluttered map 0.19 (RESULTS 12.1)."""


class PayingSchedule:
    """A piece of work asked while it pays: on each of the first ``warmup`` tries, and
    while at least one try in ``odds`` paid off; otherwise on every ``every``-th, so that
    the rate stays measured (C++ twin: ``PayingSchedule`` in ``certifier.hpp``)."""

    def __init__(self, warmup: int, odds: int, every: int):
        self.warmup, self.odds, self.every = warmup, odds, every
        self._skips = 0

    def ask(self, tried: int, paid: int) -> bool:
        """Whether to do the work now, after ``tried`` tries of which ``paid`` paid off."""
        if tried < self.warmup or paid * self.odds >= tried:
            return True
        self._skips += 1
        return self._skips % self.every == 0


class EdgeCertifier:
    """Prove edges collision-free with guards and certificates, or reject them.

    ``check(p1, p2)`` follows OMPL's ``MotionValidator`` contract: ``p1`` is assumed
    valid, ``p2`` is not. The edge is decided as follows, each step only when the
    previous ones leave part of it open:

    1. ``p2``: skipped when the cache knows it valid; else the edge is rejected with no
       query when its centre passes through a cell the occupancy grid knows blocked
       (``occupancy``, see step 3), then one collision query at ``p2``, and a colliding
       ``p2`` rejects the edge.
    2. Endpoint guards from the cache cover ``[0, lo]`` (guard at ``p1``) and
       ``[hi, 1]`` (guard at ``p2``); ``lo >= hi`` certifies the edge with no query.
    3. Cheap rejection. The robot contains the ball of radius ``min(a)`` about its
       centre, so the edge collides if its centre passes through a cell the occupancy
       grid knows blocked (no query; done in step 1 unless ``p2`` was cached), or
       (``sweep_test``) if the capsule swept by that ball over ``[lo, hi]`` meets an
       obstacle (one collision query). Then ``probes`` collision queries at the bisection
       points 1/2, 1/4, 3/4, 1/8, ... of ``[lo, hi]`` (:func:`probe_points`): a colliding
       pose proves the edge not free (``rejected_probe``) at a collision query's price,
       before any guard is paid for; asked while probes reject often enough
       (:data:`PROBE_ODDS`, :meth:`_probing`).
    4. Missing endpoint guards are measured and cached (a state the planner keeps is
       never queried twice).
    5. Advancement: a guard at the middle of each open stretch, removing what it covers,
       until nothing is open (certified), a guard touches an obstacle or cannot make
       progress (rejected), or ``max_guards`` guards were placed ("not proven", rejected).

    Every guard is measured once (a clearance query, or a region query when the
    ``region`` certificate is on) and every certificate reports its reach from it; the
    largest reach on each side wins (the certificates' union is an interval around the
    guard). ``covered`` sums, per certificate, the stretches of edge parameter it won.

    With ``fallback="discrete"`` the stretch left open after step 4 is sampled at
    ``resolution`` (in units of ``s``) with collision queries, as OMPL's discrete
    validator does; that mode is not exact.

    Parameters
    ----------
    world : object
        ``in_collision(pose)`` and ``safe_body_clearances(pose)`` (one number per body;
        ``safe_clearance(pose)`` suffices for one body), ``robot`` unless given; for ``region``
        also ``free_regions(pose, horizon)`` and ``clearance_atol``; for ``sweep_test``
        ``sweep_core_collides(t1, t2, radius)``: :class:`kcplan.world.CollisionWorld`.
    robot : Robot or array_like, optional
        Default ``world.robot``; semi-axes ``(n,)`` mean one body at the origin.
    certificates : sequence of str, optional
        Names from :data:`kcplan.certification.certificates.CERTIFICATE_NAMES`; default
        ``CERTIFICATE_SETS["kc"]``, or ``("rotation",)`` for a world without region
        queries.
    ladder : GuardLadder, optional
        For ``polytope``; built on demand.
    horizon : float, optional
        Region horizon ``H`` in length units; default the largest semi-axis of any body.
    fallback : {"bisection", "discrete"}
    max_guards : int
        Guards per edge after the endpoints before "not proven".
    sweep_test : bool, optional
        Step 3 (default: when the world has ``sweep_core_collides``).
    occupancy : bool, optional
        Reject states whose origin lies in a cell of :class:`CoreOccupancy` proven
        blocked for every orientation, with no query; a cell is tested (one query) the
        first time a state in it collides, on the schedule of ``learn_schedule``
        (default: when the world has ``ball_collides`` and ``scenario``).
    probes : int
        Collision probes per edge in step 3 (0: none).
    learn_schedule : bool
        Test the grid cells of colliding states only while the grid pays
        (:data:`LEARN_ODDS`, :meth:`_learning`); False: every one (the ablation).

    Steps 1 and 3 use the robot's core, the ball of radius
    :attr:`kcplan.geometry.robot.Robot.core_radius` about its origin; a robot whose
    bodies do not cover its origin has none, and those tests are off.
    cache : GuardCache, optional
        Shared with the state validity checker (see :meth:`state_valid`).

    Poses outside :attr:`domain` (:class:`kcplan.certification.domain.PoseDomain`: not
    finite, or outside the scenario's bounds by more than the scene's size) are never
    free and cost no query.

    Not thread-safe (the world reuses one FCL robot object). Its compiled twin, with the
    same steps and counters, is :class:`kcplan.certification.kernel.KernelCertifier`.
    """

    backend = "python"

    def __init__(
        self,
        world,
        robot: Robot | ArrayLike | None = None,
        certificates: Sequence[str] | None = None,
        ladder: GuardLadder | None = None,
        horizon: float | None = None,
        fallback: str = "bisection",
        max_guards: int = 64,
        sweep_test: bool | None = None,
        cache: GuardCache | None = None,
        occupancy: bool | None = None,
        probes: int = DEFAULT_PROBES,
        learn_schedule: bool = True,
    ):
        regions = hasattr(world, "free_regions")
        if certificates is None:
            certificates = CERTIFICATE_SETS["kc"] if regions else ("rotation",)
        robot = Robot.of(world.robot if robot is None else robot)
        core = robot.core_radius > 0.0
        sweep_test = core and _supported(world, "sweep_test", sweep_test, "sweep_core_collides")
        occupancy = core and _supported(world, "occupancy", occupancy, "ball_collides", "scenario")
        check_certificates(certificates, robot, regions, fallback)
        if hasattr(world, "safe_body_clearances"):
            self._body_clearances = world.safe_body_clearances
        elif len(robot) == 1:  # a one-body world may offer safe_clearance alone
            self._body_clearances = lambda pose: (world.safe_clearance(pose),)
        else:
            raise ValueError(
                f"world: a robot of {len(robot)} bodies needs safe_body_clearances(pose)"
            )
        self.world = world
        self.robot, self.n = robot, robot.dimension
        self.core_radius = robot.core_radius
        bounds = world.scenario.bounds if hasattr(world, "scenario") else (None, None)
        self.domain = PoseDomain(robot.dimension, *bounds, reach=robot.reach)
        self.certificates = []
        for name in certificates:
            if name in ("ball", "rotation"):
                self.certificates.append(ClearanceBall(robot, rotation_aware=name == "rotation"))
            elif name == "polytope":
                self.certificates.append(KCPolytope(ladder or GuardLadder(robot.semi_axes)))
            else:
                self.certificates.append(FreeRegionPlanes(robot, arc=name == "region"))
        self.use_region = any(name.startswith("region") for name in certificates)
        largest = robot.largest_semi_axis
        self.horizon = float(largest if horizon is None else horizon)
        self.margin = float(getattr(world, "clearance_atol", 0.0)) + 1e-12 * robot.reach
        self.fallback = fallback
        self.max_guards = int(max_guards)
        if not (isinstance(probes, int) and probes >= 0):
            raise ValueError(f"probes: expected a number >= 0, got {probes!r}")
        self.probes = probes
        self._probe_pace = PayingSchedule(PROBE_WARMUP, PROBE_ODDS, PROBE_EVERY)
        self.learn_schedule = bool(learn_schedule)
        self._learn_pace = PayingSchedule(LEARN_WARMUP, LEARN_ODDS, LEARN_EVERY)
        self.sweep_test = bool(sweep_test)
        self.cache = cache if cache is not None else GuardCache()
        self.occupancy = occupancy
        self._grid: CoreOccupancy | None = None
        self.counters = dict.fromkeys(COUNTER_NAMES, 0)
        self.covered = dict.fromkeys((c.name for c in self.certificates), 0.0)
        self.guard_log: list[tuple[np.ndarray, float]] | None = None  # (pose, eps) if enabled

    @property
    def ladder(self) -> GuardLadder | None:
        """The polytope ladder, when the ``polytope`` certificate is on."""
        for c in self.certificates:
            if isinstance(c, KCPolytope):
                return c.ladder
        return None

    def measure(self, pose: np.ndarray) -> Guard:
        """One guard query at ``pose`` (not cached)."""
        self.counters["guards"] += 1
        if self.use_region:
            regions = self.world.free_regions(pose, self.horizon)
            guard = Guard.from_regions(pose, regions, self.robot, self.margin)
        else:
            guard = Guard.of_clearances(pose, self._body_clearances(pose))
        if self.guard_log is not None and guard.clearance > 0.0:
            # every body inflated by this factor about its centre is free
            self.guard_log.append((pose, guard.clearance / self.robot.largest_semi_axis))
        return guard

    def state_valid(self, pose: ArrayLike, key: bytes | None = None) -> bool:
        """State validity with the cache: one collision query for a pose not seen before,
        remembered so that a later edge ending there skips its end-state query.
        ``key`` is ``pose.tobytes()`` when the caller has it."""
        p = np.asarray(pose, dtype=float)
        if not self.domain.admits(p):
            return False  # never free (not finite, or far outside the bounds)
        key = p.tobytes() if key is None else key
        known = self.cache.validity(key)
        if known is not None:
            return known
        grid = self._occupancy()
        if grid is not None and grid.blocked(p):
            self.counters["occupancy_rejections"] += 1
            self.cache.add_validity(key, False)
            return False
        return self._collision_free(p, key)

    def _occupancy(self) -> CoreOccupancy | None:
        """The occupancy grid, built on first use (None when ``occupancy`` is off)."""
        if self._grid is None and self.occupancy:
            self._grid = CoreOccupancy(self.world)
        return self._grid

    def _collision_free(self, p: np.ndarray, key: bytes) -> bool:
        """One collision query at a state neither the cache nor the grid knows; the result
        is cached, and a colliding state's grid cell is learned."""
        self.counters["collision_queries"] += 1
        valid = not self.world.in_collision(p)
        grid = self._grid
        if not valid and grid is not None and self._learning():  # for the next state there
            before = grid.queries
            grid.learn(p)
            self.counters["occupancy_queries"] += grid.queries - before
        self.cache.add_validity(key, valid)
        return valid

    def _learning(self) -> bool:
        """Whether a colliding state's grid cell is tested (:data:`LEARN_ODDS`): a cell
        costs a ball query to test and saves a collision query each time it rejects."""
        c = self.counters
        rejections = c["occupancy_rejections"] + c["rejected_occupancy"]
        return not self.learn_schedule or self._learn_pace.ask(c["occupancy_queries"], rejections)

    def _endpoint(self, pose: np.ndarray, key: bytes) -> Guard:
        guard = self.cache.guard(key)
        if guard is None:
            self.counters["endpoint_guards"] += 1
            guard = self.measure(pose)
            self.cache.add_guard(key, guard)
        return guard

    def _reach(self, guard: Guard, edge: Edge, m: float, s0: float, s1: float):
        """``(lo, hi)`` covered by ``guard`` at ``q(m)``; credits the winning certificates
        with what they cover of ``[s0, s1]``."""
        best_minus = best_plus = 0.0
        win_minus = win_plus = None
        need_minus, need_plus = m - s0, s1 - m
        for certificate in self.certificates:
            minus, plus = certificate.reach(guard, edge, m)
            if minus > best_minus:
                best_minus, win_minus = minus, certificate.name
            if plus > best_plus:
                best_plus, win_plus = plus, certificate.name
            if best_minus >= need_minus and best_plus >= need_plus:
                break  # the stretch is covered: later certificates cannot add to it
        lo, hi = m - best_minus, m + best_plus
        if win_minus is not None:
            self.covered[win_minus] += m - max(lo, s0) if m > s0 else 0.0
        if win_plus is not None:
            self.covered[win_plus] += min(hi, s1) - m if m < s1 else 0.0
        return lo, hi

    def _reject(self, reason: str) -> bool:
        self.counters["rejected"] += 1
        self.counters[reason] += 1
        return False

    def check(
        self, pose1: ArrayLike, pose2: ArrayLike, resolution: float = 0.01, probe: bool = True
    ) -> bool:
        """True when the whole edge ``pose1 -> pose2`` is proven free (see class docs); an
        edge with a pose outside :attr:`domain` (not finite, far outside the bounds; see
        :class:`kcplan.certification.domain.PoseDomain`) is rejected (``rejected_end_state``).
        ``probe=False`` skips the probes, which only reject early and prove nothing: for
        an edge a lazy planner has screened already (:meth:`screen`)."""
        c = self.counters
        c["edges"] += 1
        p1, p2 = self._poses(pose1, pose2)
        if not (self.domain.admits(p1) and self.domain.admits(p2)):
            return self._reject("rejected_end_state")  # never free
        k1, k2 = p1.tobytes(), p2.tobytes()
        cache, grid = self.cache, self._occupancy()
        if grid is not None and grid.blocked(p2):
            return self._reject("rejected_occupancy")
        g1, g2 = cache.guard(k1), cache.guard(k2)
        known = cache.validity(k2)
        # a state never seen (RRT's new states): the free grid test before any query;
        # a known state (PRM's milestones): the cached guards first, they often suffice
        tested = known is None and grid is not None
        if tested and grid.segment_blocked(p1, p2):
            return self._reject("rejected_occupancy")
        # known False, or unknown (the grid was asked above) and colliding
        if not (known or (known is None and self._collision_free(p2, k2))):
            return self._reject("rejected_end_state")
        edge = Edge(p1, p2, self.n)
        lo, hi = 0.0, 1.0
        if g1 is not None:
            c["cached_guards"] += 1
            lo = self._reach(g1, edge, 0.0, 0.0, 1.0)[1]
        if g2 is not None and lo < 1.0:
            c["cached_guards"] += 1
            hi = self._reach(g2, edge, 1.0, lo, 1.0)[0]
        if lo >= hi:
            c["certified_by_endpoints"] += 1
            return True
        if not tested and grid is not None and grid.segment_blocked(p1, p2):
            return self._reject("rejected_occupancy")
        if self.sweep_test:
            c["collision_queries"] += 1
            if self.world.sweep_core_collides(edge.pose(lo), edge.pose(hi), self.core_radius):
                return self._reject("rejected_sweep")
        if probe and self._probing() and not self._probe(edge, lo, hi):
            return self._reject("rejected_probe")
        if g1 is None:
            g1 = self._endpoint(p1, k1)
            if g1.clearance <= 0.0:
                return self._reject("rejected_guard")
            lo = self._reach(g1, edge, 0.0, 0.0, hi)[1]
        if lo < hi and g2 is None:
            g2 = self._endpoint(p2, k2)
            if g2.clearance <= 0.0:
                return self._reject("rejected_end_state")
            hi = self._reach(g2, edge, 1.0, lo, 1.0)[0]
        if lo >= hi:
            c["certified_by_endpoints"] += 1
            return True
        if self.fallback == "discrete":
            return self._sample(edge, resolution, lo, hi)
        return self._advance(edge, lo, hi)

    def screen(self, pose1: ArrayLike, pose2: ArrayLike, step: float) -> bool:
        """Whether the edge passes the cheap tests :meth:`check` begins with, and nothing
        more: both poses in :attr:`domain`, ``pose2`` and the centre path clear of blocked
        cells, ``pose2`` valid, the core capsule clear (``sweep_test``), and no probe in
        contact, at most ``step`` (length units) of motion of the robot's farthest point
        apart (``|t2 - t1| + reach |w12|`` over the edge; at most
        :data:`MAX_SCREEN_PROBES`). **Not a proof**: the edge may touch between its
        probes. A lazy planner screens its trees' edges so and certifies only the path
        it returns (:mod:`kcplan.planning.lazy`). The kernel's twin is
        ``EdgeCertifier::screen``."""
        if not step > 0.0:
            raise ValueError(f"step: expected a length > 0, got {step}")
        p1, p2 = self._poses(pose1, pose2)
        self.counters["screened_edges"] += 1
        if not (self.domain.admits(p1) and self.domain.admits(p2)):
            return False
        grid = self._occupancy()
        if grid is not None and (grid.blocked(p2) or grid.segment_blocked(p1, p2)):
            return False
        k2 = p2.tobytes()
        known = self.cache.validity(k2)
        if not (known or (known is None and self._collision_free(p2, k2))):
            return False
        edge = Edge(p1, p2, self.n)
        if self.sweep_test:
            self.counters["collision_queries"] += 1
            if self.world.sweep_core_collides(p1, p2, self.core_radius):
                return False
        count = min(MAX_SCREEN_PROBES, int(edge.sweep_speed(self.robot.reach) / step))
        return count == 0 or self._probe(edge, 0.0, 1.0, count)

    def _poses(self, pose1: ArrayLike, pose2: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Both poses as arrays; ``ValueError`` unless each has the robot's pose size."""
        p1, p2 = np.asarray(pose1, dtype=float), np.asarray(pose2, dtype=float)
        if p1.shape != p2.shape or p1.size != pose_size(self.n):
            raise ValueError(f"pose: expected {pose_size(self.n)} numbers per pose")
        return p1, p2

    def _probing(self) -> bool:
        """Whether this edge is probed (the schedule of :data:`PROBE_WARMUP`)."""
        probed, rejected = self.counters["probed_edges"], self.counters["rejected_probe"]
        return self.probes > 0 and self._probe_pace.ask(probed, rejected)

    def _probe(self, edge: Edge, lo: float, hi: float, count: int | None = None) -> bool:
        """False when one of ``count`` (default :attr:`probes`) probes of ``[lo, hi]``
        collides."""
        self.counters["probed_edges"] += 1
        for u in probe_points(self.probes if count is None else count):
            self.counters["probes"] += 1
            self.counters["collision_queries"] += 1
            if self.world.in_collision(edge.pose(lo + u * (hi - lo))):
                return False
        return True

    def _advance(self, edge: Edge, lo: float, hi: float) -> bool:
        def reach(m: float, s0: float, s1: float) -> tuple[float, float] | None:
            guard = self.measure(edge.pose(m))
            return None if guard.clearance <= 0.0 else self._reach(guard, edge, m, s0, s1)

        return self._decide(*advance(lo, hi, self.max_guards, reach))

    def _decide(self, reason: str | None, guards: int) -> bool:
        """Count an advancement's guards and its outcome (:func:`advance`)."""
        self.counters["bisection_nodes"] += guards
        if reason is not None:
            return self._reject(reason)
        self.counters["certified_one_guard"] += guards == 1
        return True

    def _sample(self, edge: Edge, resolution: float, lo: float, hi: float) -> bool:
        steps = max(1, math.ceil(1.0 / resolution))
        for i in range(1, steps):
            s = i / steps
            if s <= lo or s >= hi:
                continue  # covered by an endpoint guard
            self.counters["collision_queries"] += 1
            if self.world.in_collision(edge.pose(s)):
                return self._reject("rejected_guard")
        return True


def advance(
    lo: float,
    hi: float,
    max_guards: int,
    reach: Callable[[float, float, float], tuple[float, float] | None],
) -> tuple[str | None, int]:
    """Conservative advancement over ``[lo, hi]``: a guard at the middle ``m`` of each
    stretch ``[s0, s1]`` left open, until none is.

    ``reach(m, s0, s1)`` measures the guard at ``m`` and returns the stretch ``(g_lo,
    g_hi)`` around ``m`` it proves free, or None when the guard touches an obstacle.
    Returns ``(reason, guards)``: reason None (covered), ``"rejected_guard"`` (a guard
    touched an obstacle) or ``"not_proven"`` (``max_guards`` placed, or a guard that
    proves nothing), and the number of guards placed. The rigid and the arm certifiers
    advance by it; the compiled twin is ``EdgeCertifier::advance``.
    """
    pending = [(lo, hi)]
    guards = 0
    while pending:
        s0, s1 = pending.pop()
        if guards >= max_guards:
            return "not_proven", guards
        m = 0.5 * (s0 + s1)
        stretch = reach(m, s0, s1)
        guards += 1
        if stretch is None:
            return "rejected_guard", guards
        g_lo, g_hi = stretch
        if g_hi - g_lo <= 1e-12:
            return "not_proven", guards
        if g_lo > s0:
            pending.append((s0, g_lo))
        if g_hi < s1:
            pending.append((g_hi, s1))
    return None, guards


def probe_points(count: int) -> list[float]:
    """The first ``count`` points of the van der Corput sequence, 1/2, 1/4, 3/4, 1/8, 5/8,
    3/8, 7/8, 1/16, ...: each halves the largest stretch of ``[0, 1]`` not yet probed, in
    the order bisection would reach it (exact in binary floating point)."""
    out = []
    for i in range(1, count + 1):
        u, bit = 0.0, 0.5
        while i:
            u += bit * (i & 1)
            i, bit = i >> 1, bit * 0.5
        out.append(u)
    return out


def check_certificates(
    certificates: Sequence[str], robot: Robot, regions: bool, fallback: str
) -> None:
    """Raise ``ValueError`` (one line) unless the certificate names, the robot and the
    fallback fit together; ``regions``: the world offers region queries."""
    for name in ("region", "region-lever"):
        if name in certificates and not regions:
            raise ValueError(
                f"certificates: {name!r} needs a world with free_regions(pose, horizon)"
            )
    if "polytope" in certificates and not robot.is_single:
        raise ValueError(
            "certificates: 'polytope' (the paper's bound) needs one body centred at the "
            f"robot's origin, got {robot.describe()}"
        )
    if fallback not in ("bisection", "discrete"):
        raise ValueError(f"fallback: expected 'bisection' or 'discrete', got {fallback!r}")
    unknown = [c for c in certificates if c not in CERTIFICATE_NAMES]
    if unknown or not certificates:
        raise ValueError(
            f"certificates: expected names from {', '.join(CERTIFICATE_NAMES)}, "
            f"got {list(certificates)}"
        )


def _supported(world, option: str, value: bool | None, *needs: str) -> bool:
    """An option's value: its default (None) is on exactly when the world supports it."""
    missing = [name for name in needs if not hasattr(world, name)]
    if value and missing:
        raise ValueError(f"{option}: the world has no {', '.join(missing)}")
    return not missing if value is None else bool(value)
