"""The compiled edge certifiers behind the Python certifiers' interface.

:class:`KernelCertifier` runs :class:`kcplan._kernel.EdgeCertifier` (C++, on coal) on the
kernel twin of a :class:`kcplan.world.CollisionWorld` and answers exactly what
:class:`kcplan.certification.certifier.EdgeCertifier` answers: ``check``, ``state_valid``,
``counters`` and ``covered`` under the same names. It holds no logic of its own; the
decision is made in ``kcplan/_kernel/certifier.cpp``, whose Python twin is
:mod:`kcplan.certification.certifier`. :class:`KernelArmCertifier` does the same for arms
(``kcplan/_kernel/arm_certifier.cpp``, twin :mod:`kcplan.certification.arm_certifier`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from kcplan._kernel import ArmCertifier as _CompiledArmCertifier
from kcplan._kernel import EdgeCertifier as _CompiledCertifier
from kcplan.certification.arm_certifier import PROBE_STEP, arm_certificates
from kcplan.certification.certifier import CERTIFICATE_SETS, DEFAULT_PROBES, check_certificates
from kcplan.certification.ladder import GuardLadder

__all__ = ["KernelArmCertifier", "KernelCertifier"]


class KernelCertifier:
    """:class:`kcplan.certification.certifier.EdgeCertifier`'s decisions, made in C++.

    Parameters
    ----------
    world : kcplan.world.CollisionWorld
        Its :attr:`~kcplan.world.CollisionWorld.kernel` is used (built on first use); the
        certifier's queries show in ``world.counters``.
    certificates, ladder, horizon, fallback, max_guards, sweep_test, occupancy, probes
        As for :class:`~kcplan.certification.certifier.EdgeCertifier` (``sweep_test`` and
        ``occupancy`` default to on; both need a robot core).
    cache_entries : int
        Bound of the guard cache (guards, and as many validity marks).
    learn_schedule : bool
        As for :class:`~kcplan.certification.certifier.EdgeCertifier`.

    Notes
    -----
    Not thread-safe: use one world and certifier per thread.
    """

    backend = "kernel"

    def __init__(
        self,
        world,
        certificates: Sequence[str] | None = None,
        ladder: GuardLadder | None = None,
        horizon: float | None = None,
        fallback: str = "bisection",
        max_guards: int = 64,
        sweep_test: bool | None = None,
        occupancy: bool | None = None,
        cache_entries: int = 200_000,
        probes: int = DEFAULT_PROBES,
        learn_schedule: bool = True,
    ):
        robot = world.robot
        certificates = tuple(CERTIFICATE_SETS["kc"] if certificates is None else certificates)
        check_certificates(certificates, robot, regions=True, fallback=fallback)
        levels, rows, scale = [], [], 1.0
        if "polytope" in certificates:
            ladder = ladder or GuardLadder(robot.semi_axes)
            levels = ladder.inflations.tolist()
            rows = [block.ravel().tolist() for block in ladder.scaled_rows]
            scale = ladder.scale
        low, high = (np.asarray(b, dtype=float).tolist() for b in world.scenario.bounds)
        pad = [0.0] * (3 - robot.dimension)
        self.world, self.robot, self.n = world, robot, robot.dimension
        self.fallback = fallback
        self.certificates = certificates
        self._ladder = ladder
        self._kernel = _CompiledCertifier(
            world.kernel,
            list(certificates),
            fallback == "discrete",
            int(max_guards),
            -1.0 if horizon is None else float(horizon),
            True if sweep_test is None else bool(sweep_test),
            True if occupancy is None else bool(occupancy),
            int(probes),
            low + pad,
            high + pad,
            int(cache_entries),
            levels,
            rows,
            float(scale),
            bool(learn_schedule),
        )
        self.horizon = self._kernel.horizon
        self.margin = self._kernel.margin
        self.sweep_test = self._kernel.sweep_test
        self.occupancy = self._kernel.occupancy
        self.probes = self._kernel.probes
        self.learn_schedule = self._kernel.learn_schedule
        # the validator's hot path calls these directly (one Python call per edge)
        self.check_se2, self.check_se3 = self._kernel.check_se2, self._kernel.check_se3
        self.state_valid_se2 = self._kernel.state_valid_se2
        self.state_valid_se3 = self._kernel.state_valid_se3
        self.screen_se2, self.screen_se3 = self._kernel.screen_se2, self._kernel.screen_se3

    @property
    def ladder(self) -> GuardLadder | None:
        """The polytope ladder, when the ``polytope`` certificate is on."""
        return self._ladder

    @property
    def counters(self) -> dict[str, int]:
        """:data:`kcplan.certification.certifier.COUNTER_NAMES`, counted in C++."""
        return self._kernel.counters

    @property
    def covered(self) -> dict[str, float]:
        """Edge parameter each certificate covered (as the Python certifier's)."""
        return self._kernel.covered

    @property
    def cache_size(self) -> int:
        """Guards in the cache (bounded by ``cache_entries``)."""
        return self._kernel.cache_size

    def check(
        self, pose1: ArrayLike, pose2: ArrayLike, resolution: float = 0.01, probe: bool = True
    ) -> bool:
        """True when the whole edge ``pose1 -> pose2`` is proven free (``probe``: as
        :meth:`kcplan.certification.certifier.EdgeCertifier.check`)."""
        return self._kernel.check(_flat(pose1), _flat(pose2), float(resolution), bool(probe))

    def state_valid(self, pose: ArrayLike) -> bool:
        """State validity with the cache (one collision query for a pose not seen before)."""
        return self._kernel.state_valid(_flat(pose))

    def screen(self, pose1: ArrayLike, pose2: ArrayLike, step: float) -> bool:
        """The edge's cheap tests and probes only, not a proof
        (:meth:`kcplan.certification.certifier.EdgeCertifier.screen`)."""
        return self._kernel.screen(_flat(pose1), _flat(pose2), float(step))

    def measure(self, pose: ArrayLike) -> tuple[float, list]:
        """One guard query at ``pose`` (not cached): ``(clearance, bodies)`` with, per
        body, ``(clearance, planes, horizon)`` and planes ``(nx, ny, nz, slack,
        clearance)`` as in :class:`kcplan.certification.guard.BodyGuard`."""
        return self._kernel.measure(_flat(pose))


def _flat(pose: ArrayLike) -> list[float]:
    return np.asarray(pose, dtype=float).ravel().tolist()


class KernelArmCertifier:
    """:class:`kcplan.certification.arm_certifier.ArmEdgeCertifier`'s decisions, made in C++.

    Parameters
    ----------
    world : kcplan.arm.ArmWorld
        Its :attr:`~kcplan.arm.ArmWorld.kernel` is used (built on first use); the
        certifier's queries show in ``world.counters``.
    max_guards, cache_entries, probes
        As for :class:`~kcplan.certification.arm_certifier.ArmEdgeCertifier`.
    part_balls : bool
        Decide a group of self pairs (two links' bodies) at once when balls around the
        links' bodies show that none of them can limit a guard's radius, and ask a pair's
        bounding-ball gap only when its group is near (``ArmCertifier``; the radii, and so
        the decisions, are those without it). False: every pair at every guard.
    first_order : bool
        Bound the bodies' motion by their twist at each guard as well
        (:mod:`kcplan.certification.arm_certifier`); False is the ablation.
    kc_inflation : float
        The KC certificate's ``eps`` (:mod:`kcplan.certification.arm_certifier`); 0: the
        clearance ball alone (the ``ca`` ablation).
    planes : bool
        The plane certificate (with ``first_order``; :mod:`kcplan.certification.arm_certifier`):
        a body stays free of an obstacle while it does not cross the slab between them.
        False is the ablation.

    Notes
    -----
    ``counters`` adds ``refined_pairs`` (self pairs whose bounding balls' gap limited a
    guard's radius, so that coal measured their distance), ``refined_bodies``,
    ``skipped_groups`` (groups of pairs a radius decided by their links' balls),
    ``grown_queries`` (KC guards asked) and ``kc_reaches`` (bodies whose KC guard took them
    farther than their ball where a radius asked), ``plane_queries`` (bodies whose
    separations from the obstacles near them were asked) and ``plane_reaches`` (bodies the
    plane certificate took farther than the ball). Not thread-safe.
    """

    backend = "kernel"
    fallback = "bisection"

    def __init__(
        self,
        world,
        max_guards: int = 256,
        cache_entries: int = 200_000,
        probes: bool = True,
        part_balls: bool = True,
        first_order: bool = True,
        kc_inflation: float = 0.0,
        planes: bool = True,
    ):
        self.world = world
        self.n = world.arm.dof
        self.compiled = _CompiledArmCertifier(
            world.kernel, int(max_guards), int(cache_entries), bool(probes), bool(part_balls),
            bool(first_order), float(kc_inflation), bool(planes),
        )  # fmt: skip
        self.planes = self.compiled.planes
        self.certificates = arm_certificates(kc_inflation, self.planes)

    def check(
        self, state1: ArrayLike, state2: ArrayLike, resolution: float = 0.01, probe: bool = True
    ) -> bool:
        """True when the whole edge is proven free (``resolution`` is unused: arms have
        no discrete fallback; ``probe``: as
        :meth:`kcplan.certification.arm_certifier.ArmEdgeCertifier.check`)."""
        return self.compiled.check(_joints(state1), _joints(state2), bool(probe))

    def state_valid(self, state: ArrayLike) -> bool:
        """One collision query for a state not seen before (remembered)."""
        return self.compiled.state_valid(_joints(state))

    def screen(self, state1: ArrayLike, state2: ArrayLike, step: float = PROBE_STEP) -> bool:
        """The edge's probes only, not a proof
        (:meth:`kcplan.certification.arm_certifier.ArmEdgeCertifier.screen`)."""
        return self.compiled.screen(_joints(state1), _joints(state2), float(step))

    @property
    def counters(self) -> dict:
        return self.compiled.counters

    @property
    def covered(self) -> dict:
        return self.compiled.covered


def _joints(state: ArrayLike) -> list[float]:
    return np.asarray(state, dtype=float).ravel().tolist()
