"""The edge certifier of arms: joint-space edges proved free by the chain's clearance balls.

For the straight edge ``q(s) = q1 + s (q2 - q1)`` a *guard* at ``s = m`` measures, for each
covering body ``k``, its certain clearance ``d_k`` to the obstacles and, for each self
pair ``(k, l)``, their certain distance ``d_kl`` (:meth:`kcplan.arm.ArmWorld.
safe_clearances`). Along the edge no point of body ``k`` moves faster than ``v_k`` per unit
of ``s``, and no two points of ``k`` and ``l`` approach faster than ``v_kl``
(:mod:`kcplan.arm.bounds`, Schwarzer, Saha and Latombe 2005); nor, within ``t`` of ``m``,
farther than ``A t + Q t^2 / 2``, with ``A`` from the levers at ``q(m)`` (the farthest
points from each joint's origin there) and ``Q`` from how fast they can grow along the
edge (:func:`kcplan.arm.bounds.levers`, :func:`kcplan.arm.bounds.lever_growth`; a pair
takes the joints that carry one of its bodies only); nor, for a body, farther than
``A1 t + M t^2 / 2``, with ``A1`` from its exact twist at ``q(m)`` and ``M`` its largest
acceleration along the edge (:func:`kcplan.arm.bounds.first_order_speeds`,
:func:`kcplan.arm.bounds.point_accelerations`: Taylor's theorem with its remainder; the
twist's joint contributions partly cancel, so ``A1`` is about half of ``A``); a pair takes
the same terms of both bodies in the frame of the joints that carry both
(:func:`kcplan.arm.bounds.relative_first_order`,
:func:`kcplan.arm.bounds.relative_accelerations`). So for ``|s - m| < r`` with

    r = min over bodies and pairs of max( d / v , t , t1 ),
        A t + Q t^2 / 2 = d,  A1 t1 + M t1^2 / 2 = d

every body stays clear of every obstacle (it was ``d_k`` away and moved less than
``d_k``) and of every body it may collide with: the stretch ``(m - r, m + r)`` is free.
The covers contain the links' collision geometry, so the links are free too. The edge is
certified when guards cover all of ``[0, 1]``; a guard at a state in contact (``r = 0``)
rejects it.

Before any guard is paid for, *probes* look for a colliding state on the stretch the
cached guards left open: collision queries at the van der Corput points of that stretch
(1/2, 1/4, 3/4, ...), one per :data:`PROBE_STEP` radians of joint-space distance, at most
:data:`MAX_PROBES`. A colliding probe proves the edge not free at a collision query's
price (a guard costs a distance query of every body and pair); they cost the certified
edges a few cheap queries each.

*The KC certificate* (``kc_inflation = eps > 0``) is a second proof of each body's
clearance to the scene, after the paper's idea that an ellipsoid may move far along its
long axes and stay inside a slightly larger one. At a guard at ``q(m)`` body ``k``
(``E = c_g + R_g diag(a) B``, ``B`` the unit ball) grown about its centre by ``1 + eps``,
its *KC guard* ``G = c_g + R_g (1 + eps) diag(a) B``, is proved clear of the scene by one
query (:meth:`kcplan.arm.ArmWorld.grown_clear`). At ``s`` the body is ``c(s) + R(s)
diag(a) B``; in the guard's frame its centre is displaced by ``d = R_g^T (c(s) - c_g)``
and it is turned by ``R_g^T R(s)``, by an angle ``theta``. For a unit ``n`` its support
function is ``n . d + |diag(a) R(s)^T R_g n|``, and the turn moves it by at most ``(a_max -
a_min) theta`` (:mod:`kcplan.certification.certificates.ball`: an ellipsoid's support function
turns at most ``a_max - a_min`` per radian), while ``n . d <= |diag(a) n| |diag(a)^-1 d|``
and ``|diag(a) n| >= a_min``. So the body lies inside ``G``, whose support function is
``(1 + eps) |diag(a) n|``, as long as

    |diag(a)^-1 d| + (a_max - a_min) theta / a_min <= eps          (KC)

(the containment condition of the paper's Sec. 4, with the rotation and translation
bounded separately). Along the edge ``theta <= w_k t`` (``w_k``: the revolute steps that
carry the body, :func:`kcplan.arm.bounds.turn_speeds`), and the centre, a point of the
body, moves by at most ``min(v t, A t + Q t^2 / 2)`` (so ``|diag(a)^-1 d|`` by that over
``a_min``) and by ``u t + r``, ``|r| <= M t^2 / 2`` (``u`` the centre's velocity at
``q(m)``, :func:`kcplan.arm.bounds.twists`; Taylor's remainder as above), so
``|diag(a)^-1 d| <= |diag(a)^-1 R_g^T u| t + M t^2 / (2 a_min)``. Each gives a ``t``
within which (KC) holds; the body's radius is the largest of those and of its ball's.
Moving along its long axes (``|diag(a)^-1 R_g^T u|`` small) a body may go much farther
than its clearance. Self pairs keep the ball. A KC guard is asked only where the ball
leaves a body short, and cached with its guard.

*The plane certificate* (``planes``, with ``first_order``) is a third proof of a body's
clearance to the scene, for bodies that slide past a surface. At a guard body ``k`` and an
obstacle piece lie on either side of a slab of width ``g`` across a unit ``n``
(:meth:`kcplan.arm.ArmWorld.separations`: the body in ``{n . x <= b}``, the piece in ``{n .
x >= b + g}``, from the exact support functions along the line from a box, ball or
cylinder's point nearest the body's centre, or else along FCL's nearest points; a poor
direction only narrows the slab). A point ``x`` of
the body moves along ``n`` at ``n . (u + w x (x - c)) = n . u + (x - c) . (n x w)`` at the
guard, for a hull at most that of one of its vertices (a linear function's largest value
on it), for an ellipsoid at most ``|n . u| + |n x w| a_max``, and its acceleration is
at most ``M`` (as above), so within ``t`` of the guard it crosses at most ``S t + M t^2 /
2`` of the slab (``S`` that speed), and the body stays on its side, free of the piece,
while that is below ``g``. A body's radius is then the smallest over the pieces of the
larger of this root and the ball's reach of the body's distance to that piece alone. The
hand moving over a table (``n`` vertical, its twist mostly horizontal) so goes much
farther than its clearance. The kernel measures the slabs of the pieces within the
horizon the ball needs (every other piece gives at least what is needed), and only for a
body that limits the radius; the twin measures every slab of every body. The radii
differ only where both are at least what is needed.

With ``kc_inflation = 0`` this is the ``ca`` certificate of arms (the rigid robots'
clearance ball with the chain's speeds). The module imports neither OMPL nor FCL (the
world does the queries).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from kcplan.arm.bounds import (
    carries,
    lever_growth,
    levers,
    point_accelerations,
    point_speeds,
    relative_accelerations,
    relative_first_order,
    relative_speeds,
    turn_speeds,
    twist_speeds,
    twists,
)
from kcplan.arm.kinematics import body_frames
from kcplan.certification.certifier import COUNTER_NAMES, advance, probe_points
from kcplan.certification.guard import GuardCache

__all__ = [
    "ARM_CERTIFICATES",
    "ARM_COUNTER_NAMES",
    "DEFAULT_ARM_CERTIFICATES",
    "DEFAULT_KC_INFLATION",
    "MAX_PROBES",
    "PROBE_STEP",
    "ArmEdgeCertifier",
    "ArmGuard",
    "stretch_radii",
]

ARM_COUNTER_NAMES = tuple(
    name
    for name in COUNTER_NAMES
    if name not in ("rejected_sweep", "rejected_occupancy")
    and name not in ("occupancy_rejections", "occupancy_queries")
)
"""The rigid certifier's counters (:data:`kcplan.certification.certifier.COUNTER_NAMES`), with
the same meanings, less those of the steps arms do not have (core sweep, occupancy
grid)."""

PROBE_STEP = 0.1
"""Joint-space distance (radians, L2 of the joint vector) per probe; the kernel's twin is
``ArmCertifier::kProbeStep``. OMPL's default discrete check of the Panda steps 0.134."""
MAX_PROBES = 64
"""Probes per edge at most (``ArmCertifier::kMaxProbes``)."""
ARM_CERTIFICATES = ("ball", "kc", "region")
"""The certificates of arms: the chain's clearance balls (always), the KC guards
(``kc_inflation > 0``) and the free-region planes (``planes``; module docstring). A
certifier's ``certificates`` names those it uses, in this order."""
DEFAULT_ARM_CERTIFICATES = ARM_CERTIFICATES
"""What the ``kc-*`` planners use on arms: all of them (the planes make the Panda's MBM
problems 0.89x the time without them, ``benchmarks/RESULTS.md`` 15.1)."""
DEFAULT_KC_INFLATION = 0.2
"""The KC guard's inflation ``eps`` of the ``kc-*`` planners on arms (a scenario's
``robot.inflation`` overrides it): each body grown by 1.2 about its centre."""


@dataclass(frozen=True, eq=False)
class ArmGuard:
    """One guard of an arm: the certain clearance of each body to the scene
    ``(bodies,)`` and of each checked self pair ``(pairs,)``, metres, the levers at
    its state (:func:`kcplan.arm.bounds.levers`, ``(bodies, dof)``), the state, and
    whether each body's KC guard is clear (``(bodies,)``; None without the KC
    certificate)."""

    scene: np.ndarray
    pairs: np.ndarray
    levers: np.ndarray
    state: np.ndarray
    grown: np.ndarray | None = None
    separations: tuple | None = None  # ArmWorld.separations at the state (planes)

    @property
    def clearance(self) -> float:
        """The smallest of them (``inf`` with neither); > 0: the state is free. This is
        what :class:`kcplan.certification.guard.GuardCache` reads a state's validity from."""
        return float(min(self.scene.min(initial=math.inf), self.pairs.min(initial=math.inf)))


class ArmEdgeCertifier:
    """Prove joint-space edges of an arm free, or reject them (see the module docstring).

    ``check(q1, q2)`` follows OMPL's ``MotionValidator`` contract: ``q1`` is assumed valid,
    ``q2`` is not. Steps: (1) a state outside the joint limits or not finite rejects the
    edge with no query; (2) ``q2``'s validity (one collision query, cached); (3) the
    cached guards of its ends, which may certify it with no query; (4) probes of the
    stretch they leave open; (5) the missing end guards (measured and cached per state, as
    the rigid certifier caches them); (6) a guard in the middle of each stretch left open
    until none is (certified), one is in contact (rejected) or ``max_guards`` were placed
    ("not proven", rejected).

    Parameters
    ----------
    world : kcplan.arm.ArmWorld
    max_guards : int
        Guards per edge after the ends before "not proven".
    probes : bool
        Probe the stretch left open before the guards (module docstring).
    cache_entries : int
        States whose validity and guard are remembered (the rigid certifier's
        :class:`kcplan.certification.guard.GuardCache`: the oldest are dropped first).
    first_order : bool
        Bound the bodies' motion by their twist at the guard as well (module docstring);
        False: the levers alone (the ablation).
    kc_inflation : float
        The KC certificate's ``eps`` (module docstring); 0: the clearance ball alone
        (the ``ca`` ablation).
    planes : bool
        The plane certificate (module docstring; with ``first_order`` only); False is
        the ablation.
    """

    backend = "python"

    def __init__(
        self,
        world,
        max_guards: int = 256,
        cache_entries: int = 200_000,
        probes: bool = True,
        first_order: bool = True,
        kc_inflation: float = 0.0,
        planes: bool = True,
    ):
        if not (math.isfinite(kc_inflation) and kc_inflation >= 0.0):
            raise ValueError(f"kc_inflation: expected a finite number >= 0, got {kc_inflation!r}")
        self.kc_inflation = float(kc_inflation)
        self.world, self.arm = world, world.arm
        self.probes, self.first_order = bool(probes), bool(first_order)
        self.planes = bool(planes) and self.first_order
        self.certificates = arm_certificates(self.kc_inflation, self.planes)
        self.n = self.arm.dof
        self.max_guards = int(max_guards)
        self._rho = point_speeds(self.arm)
        C, pairs = carries(self.arm), world.self_pairs
        self._rho_pairs = relative_speeds(self._rho, C, pairs)
        # joints that carry the first (second) body of a pair only
        self._only = (C[pairs[:, 0]] & ~C[pairs[:, 1]], C[pairs[:, 1]] & ~C[pairs[:, 0]])
        self.cache = GuardCache(cache_entries)
        self.counters = dict.fromkeys(ARM_COUNTER_NAMES, 0)
        self.covered = {"ball": 0.0}
        self._semi_axes = np.array([b.semi_axes for b in self.arm.bodies]).reshape(-1, 3)
        self.fallback = "bisection"

    def _joints(self, state: ArrayLike) -> np.ndarray:
        q = np.asarray(state, dtype=float)
        if q.shape != (self.n,):
            raise ValueError(f"state: expected {self.n} joint values, got {q.size}")
        return q

    def _admits(self, q: np.ndarray) -> bool:
        return self.arm.within_limits(q)

    def state_valid(self, state: ArrayLike) -> bool:
        """One collision query for a state not seen before (remembered); ``ValueError`` for
        a state of the wrong length, as the kernel's."""
        q = self._joints(state)
        if not self._admits(q):
            return False
        key = q.tobytes()
        known = self.cache.validity(key)
        if known is None:
            self.counters["collision_queries"] += 1
            known = not self.world.in_collision(q)
            self.cache.add_validity(key, known)
        return known

    def _measure(self, q: np.ndarray) -> ArmGuard:
        self.counters["guards"] += 1
        grown = None
        if self.kc_inflation > 0:
            self.counters["collision_queries"] += 1
            grown = self.world.grown_clear(q, 1.0 + self.kc_inflation)
        separations = self.world.separations(q) if self.planes else None
        return ArmGuard(*self.world.safe_clearances(q), levers(self.arm, q), q, grown, separations)

    def _endpoint(self, q: np.ndarray) -> ArmGuard:
        key = q.tobytes()
        guard = self.cache.guard(key)
        if guard is None:
            self.counters["endpoint_guards"] += 1
            guard = self._measure(q)
            self.cache.add_guard(key, guard)
        else:
            self.counters["cached_guards"] += 1
        return guard

    def _terms(self, q1: np.ndarray, q2: np.ndarray) -> tuple:
        """What a guard's radius needs of the edge: the global speeds of the bodies and
        pairs, ``|dq|``, the growth terms ``Q`` of bodies and pairs, the largest accelerations
        ``M`` of bodies and pairs, the signed step and the bodies' turn speeds (module
        docs)."""
        dq = np.abs(q2 - q1)
        growth = lever_growth(self.arm, dq)
        first, second = self.world.self_pairs[:, 0], self.world.self_pairs[:, 1]
        only_first, only_second = self._only
        pair_growth = (growth[first] * only_first + growth[second] * only_second).sum(axis=1)
        accel = point_accelerations(self.arm, dq)
        pair_accel = relative_accelerations(self.arm, dq, self.world.self_pairs)
        return (self._rho @ dq, self._rho_pairs @ dq, dq, growth.sum(axis=1), pair_growth,
                (accel, pair_accel), q2 - q1, turn_speeds(self.arm, dq))  # fmt: skip

    def _radius(self, guard: ArmGuard, terms: tuple) -> float:
        """The half width, in ``s``, of the stretch a guard proves free (module docs)."""
        if guard.clearance <= 0.0:
            return 0.0
        speed, pair_speed, dq, growth, pair_growth, (accel, pair_accel), step, turn = terms
        first, second = self.world.self_pairs[:, 0], self.world.self_pairs[:, 1]
        only_first, only_second = self._only
        L = guard.levers
        pair_levers = L[first] * only_first + L[second] * only_second
        a = self._semi_axes
        twist = velocity = None
        if self.first_order or guard.grown is not None:
            w, velocity = twists(self.arm, guard.state, step)
            if self.first_order:
                twist = (twist_speeds(self.arm, w, velocity), accel)
        bodies = stretch_radii(guard.scene, speed, L @ dq, growth, twist)
        frames = None  # the bodies' frames at the guard, for the planes and the KC guards
        if guard.separations is not None or guard.grown is not None:
            frames = body_frames(self.arm, guard.state)
        if guard.separations is not None:
            hulls = [  # each hull's vertices about its centre, world axes (None: ellipsoid)
                None if b.hull is None else b.hull.vertices @ f[:3, :3].T
                for b, f in zip(self.arm.bodies, frames, strict=True)
            ]
            planes = _plane_reaches(
                guard.separations, a.max(axis=1), hulls, w, velocity, speed, L @ dq, growth,
                *twist,
            )  # fmt: skip
            bodies = np.fmax(bodies, planes)
        if guard.grown is not None:
            rotations = np.array([f[:3, :3] for f in frames])
            kc = _kc_reaches(
                self.kc_inflation, guard.grown, a, rotations,
                velocity if self.first_order else None, turn, speed, L @ dq, growth, accel,
            )  # fmt: skip
            bodies = np.fmax(bodies, kc)
        pair_twist = None
        if self.first_order:
            pairs = self.world.self_pairs
            pair_twist = (relative_first_order(self.arm, guard.state, step, pairs), pair_accel)
        pairs = stretch_radii(guard.pairs, pair_speed, pair_levers @ dq, pair_growth, pair_twist)
        r = min(bodies.min(initial=math.inf), pairs.min(initial=math.inf))
        return r * (1.0 - 1e-9)  # the open stretch, with a margin for rounding

    def _reject(self, reason: str) -> bool:
        self.counters["rejected"] += 1
        self.counters[reason] += 1
        return False

    def check(
        self, state1: ArrayLike, state2: ArrayLike, resolution: float = 0.01, probe: bool = True
    ) -> bool:
        """True when the whole edge ``q1 -> q2`` is proven free (see the class docs).
        ``probe=False`` skips the probes, which only reject early and prove nothing: for an
        edge a lazy planner has screened already (:meth:`screen`)."""
        c = self.counters
        c["edges"] += 1
        q1, q2 = self._joints(state1), self._joints(state2)
        q2 = self.arm.edge_end(q1, q2)  # a wrapping angle turns the shorter way
        if not (self._admits(q1) and self._admits(q2)):
            return self._reject("rejected_end_state")
        if not self.state_valid(q2):
            return self._reject("rejected_end_state")
        terms = self._terms(q1, q2)
        g1, g2 = self.cache.guard(q1.tobytes()), self.cache.guard(q2.tobytes())
        lo, hi = 0.0, 1.0
        if g1 is not None:
            c["cached_guards"] += 1
            lo = self._radius(g1, terms)
        if g2 is not None and lo < 1.0:
            c["cached_guards"] += 1
            hi = 1.0 - self._radius(g2, terms)
        if lo >= hi:
            return self._certified_by_endpoints()
        if self.probes and probe and not self._probe(q1, q2, lo, hi, _length(q2 - q1)):
            return self._reject("rejected_probe")
        if g1 is None:
            lo = self._radius(self._endpoint(q1), terms)
            if lo <= 0.0:
                return self._reject("rejected_guard")
        if g2 is None and lo < hi:
            hi = 1.0 - self._radius(self._endpoint(q2), terms)
            if hi >= 1.0:
                return self._reject("rejected_end_state")
        if lo >= hi:
            return self._certified_by_endpoints()
        return self._advance(q1, q2, lo, hi, terms)

    def screen(self, state1: ArrayLike, state2: ArrayLike, step: float = PROBE_STEP) -> bool:
        """Whether the edge passes the collision queries :meth:`check` begins with, and
        nothing more: both ends within the limits, ``q2`` valid, and no probe over the
        whole edge in contact, one per ``step`` radians of joint-space distance (at most
        :data:`MAX_PROBES`). **Not a proof**: the edge may touch between its probes. A
        lazy planner screens its tree's edges so and certifies only the path it returns
        (:mod:`kcplan.planning.lazy`). The kernel's twin is ``ArmCertifier::screen``."""
        if not step > 0.0:
            raise ValueError(f"step: expected a joint-space distance > 0, got {step}")
        self.counters["screened_edges"] += 1
        q1, q2 = self._joints(state1), self._joints(state2)
        q2 = self.arm.edge_end(q1, q2)
        if not (self._admits(q1) and self._admits(q2) and self.state_valid(q2)):
            return False
        return self._probe(q1, q2, 0.0, 1.0, _length(q2 - q1), step)

    def _certified_by_endpoints(self) -> bool:
        self.counters["certified_by_endpoints"] += 1
        self.covered["ball"] += 1.0
        return True

    def _probe(self, q1, q2, lo: float, hi: float, length: float, step: float = PROBE_STEP) -> bool:
        """False when a probe of ``[lo, hi]`` collides (module docstring), one per ``step``."""
        count = min(MAX_PROBES, int((hi - lo) * length / step))
        if count == 0:
            return True
        self.counters["probed_edges"] += 1
        for u in probe_points(count):
            self.counters["probes"] += 1
            self.counters["collision_queries"] += 1
            if self.world.in_collision(q1 + (lo + u * (hi - lo)) * (q2 - q1)):
                return False
        return True

    def _advance(self, q1, q2, lo, hi, terms) -> bool:
        def reach(m: float, s0: float, s1: float) -> tuple[float, float] | None:
            r = self._radius(self._measure(q1 + m * (q2 - q1)), terms)
            return None if r <= 0.0 else (m - r, m + r)

        reason, guards = advance(lo, hi, self.max_guards, reach)
        self.counters["bisection_nodes"] += guards
        if reason is not None:
            return self._reject(reason)
        self.counters["certified_one_guard"] += guards == 1
        self.covered["ball"] += 1.0
        return True


def arm_certificates(kc_inflation: float, planes: bool) -> tuple[str, ...]:
    """The names (:data:`ARM_CERTIFICATES`) of the certificates a certifier with this KC
    inflation and planes uses."""
    used = {"ball": True, "kc": kc_inflation > 0, "region": planes}
    return tuple(name for name in ARM_CERTIFICATES if used[name])


def _length(dq: np.ndarray) -> float:
    """``|dq|`` summed in order, as the kernel sums it (the probe count is its floor)."""
    return math.sqrt(sum(float(d) * float(d) for d in dq))


def stretch_radii(
    d: np.ndarray, v: np.ndarray, A: np.ndarray, Q: np.ndarray, twist: tuple | None = None
) -> np.ndarray:
    """The radius clearances ``d`` give to each part of global speed ``v``, lever term
    ``A`` and growth ``Q``: ``max(d / v, t)`` with ``A t + Q t^2 / 2 = d``, and with
    ``twist = (A1, M)`` the root of ``A1 t + M t^2 / 2 = d`` as well (module docs; ``inf``
    for a part that does not move)."""
    t = np.full(len(d), math.inf)
    moving = v > 0
    t[moving] = np.maximum(d[moving] / v[moving], _root(d[moving], A[moving], Q[moving]))
    if twist is not None:
        A1, M = twist
        with np.errstate(divide="ignore", invalid="ignore"):
            t[moving] = np.fmax(t[moving], _root(d[moving], A1[moving], M[moving]))
    return t


def _kc_reaches(
    eps: float,
    grown: np.ndarray,
    semi_axes: np.ndarray,
    rotations: np.ndarray,
    velocity: np.ndarray | None,
    turn: np.ndarray,
    v: np.ndarray,
    A: np.ndarray,
    Q: np.ndarray,
    M: np.ndarray,
) -> np.ndarray:
    """The radius each body's KC guard gives it (module docstring, (KC)), 0 where that
    guard is not clear: the largest ``t`` of ``(v + L w) t = eps a_min``, ``(A + L w) t + Q
    t^2 / 2 = eps a_min`` and, with the centres' ``velocity`` at the guard (``(bodies,
    3)``, world frame; ``rotations`` ``(bodies, 3, 3)`` the bodies' frames there),
    ``(|diag(a)^-1 R^T u| + L w / a_min) t + M t^2 / (2 a_min) = eps``, with ``L = a_max -
    a_min`` and ``w`` the bodies' ``turn`` speeds; shape ``(bodies,)``."""
    a_min, a_max = semi_axes.min(axis=1), semi_axes.max(axis=1)
    spin = (a_max - a_min) * turn
    budget = eps * a_min
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(v + spin > 0, budget / (v + spin), math.inf)
        t = np.fmax(t, _root(budget, A + spin, Q))
        if velocity is not None:
            local = np.einsum("kji,kj->ki", rotations, velocity) / semi_axes  # diag(a)^-1 R^T u
            nu = np.linalg.norm(local, axis=1)
            t = np.fmax(t, _root(eps, nu + spin / a_min, M / a_min))
    return np.where(grown, t, 0.0)


def _plane_reaches(
    separations: tuple,
    a_max: np.ndarray,
    hulls: list,
    w: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    A: np.ndarray,
    Q: np.ndarray,
    A1: np.ndarray,
    M: np.ndarray,
) -> np.ndarray:
    """The radius each body's slabs give it (module docstring, the plane certificate),
    shape ``(bodies,)``: over the pieces, the smallest of the larger of the ball's reach of
    the distance to that piece and the root of ``S t + M t^2 / 2 = gap``, ``S`` the
    fastest any point moves across the slab: ``max |n . u + x . (n x w)|`` over the
    vertices ``x`` of a hull (``hulls[k]``, ``(m, 3)`` about its centre in world axes),
    ``|n . u| + |n x w| a_max`` for an ellipsoid (``hulls[k]`` None). ``separations`` is
    :meth:`kcplan.arm.ArmWorld.separations` at the guard, ``w`` and ``u`` the bodies'
    twists there ``(bodies, 3)``, ``v, A, Q`` and ``(A1, M)`` as for :func:`stretch_radii`
    ``(bodies,)``."""
    normals, gaps, clearances = separations
    bodies, pieces = gaps.shape
    if pieces == 0:
        return np.full(bodies, math.inf)
    ball = stretch_radii(
        clearances.ravel(), np.repeat(v, pieces), np.repeat(A, pieces), np.repeat(Q, pieces),
        (np.repeat(A1, pieces), np.repeat(M, pieces)),
    ).reshape(bodies, pieces)  # fmt: skip
    along = np.einsum("kpi,ki->kp", normals, u)
    z = np.cross(normals, w[:, None, :])  # (bodies, pieces, 3)
    across = np.abs(along) + np.linalg.norm(z, axis=2) * a_max[:, None]
    for k, vertices in enumerate(hulls):
        if vertices is not None:  # a linear function's largest value on a hull: a vertex's
            spread = vertices @ z[k].T  # (m, pieces)
            across[k] = np.maximum(along[k] + spread.max(axis=0), -along[k] - spread.min(axis=0))
    rounding = 1e-12 * (np.linalg.norm(u, axis=1) + np.linalg.norm(w, axis=1) * a_max)
    across = across * (1.0 + 1e-12) + rounding[:, None]  # relative, and near 0 absolute
    with np.errstate(divide="ignore", invalid="ignore"):
        slab = np.where(gaps > 0, _root(np.maximum(gaps, 0.0), across, M[:, None]), 0.0)
    return np.fmax(ball, slab).min(axis=1)


def _root(d: np.ndarray, A: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """The root ``t`` of ``A t + Q t^2 / 2 = d``, in its stable form."""
    return 2.0 * d / (A + np.sqrt(A * A + 2.0 * Q * d))
