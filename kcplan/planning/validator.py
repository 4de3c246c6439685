"""The KC motion validator: an ``ompl.base.MotionValidator`` that certifies edges.

Usable in any OMPL setup on SE(2) or SE(3)::

    from kcplan import KCMotionValidator
    mv = KCMotionValidator(si, robot, world)    # robot: Robot or semi-axes
    si.setMotionValidator(mv)
    ...

and, for an arm, on the ``RealVectorStateSpace`` of its planning group (bounds: the
joint limits), with ``robot`` a :class:`kcplan.arm.ArmModel` and ``world`` its
:class:`kcplan.arm.ArmWorld` (edges decided by
:class:`kcplan.planning.arm_certifier.ArmEdgeCertifier`).

The validator keeps no reference to ``si`` (only to its state space): ``si`` holds the
validator through a C++ ``shared_ptr`` that Python's collector cannot see, so a reference
back would make a cycle that outlives the script, and nanobind would report its objects
as leaked at exit (ompl-python-notes, section 6).

Contract (OMPL's, as far as the Python binding allows):

* ``checkMotion(s1, s2)`` returns True only when the whole edge, interpolated as OMPL
  does (linear translation, shorter-arc yaw, slerp), is proven free. ``s1`` is assumed
  valid; ``s2`` is checked.
* The OMPL 2.0 wheel dispatches only the two-argument ``checkMotion`` to Python. The
  three-argument form (with ``lastValid``) calls it and leaves ``lastValid`` untouched,
  so planners that use it (the KPIECE family) treat a rejected edge as wholly invalid;
  none of kcplan's registered planners uses that form.
* OMPL's own motion counters stay at zero for a Python validator; :attr:`counters` has
  kcplan's (see :class:`kcplan.planning.certifier.EdgeCertifier`).
* Not thread-safe; OMPL calls it from the thread that runs ``solve()``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from numpy.typing import ArrayLike
from ompl import base as ob

from kcplan.arm.world import ArmWorld
from kcplan.geometry.robot import Robot
from kcplan.planning.arm_certifier import (
    ARM_CERTIFICATES,
    DEFAULT_ARM_CERTIFICATES,
    DEFAULT_KC_INFLATION,
    ArmEdgeCertifier,
)
from kcplan.planning.certifier import DEFAULT_PROBES, EdgeCertifier
from kcplan.planning.kernel import KernelArmCertifier, KernelCertifier
from kcplan.planning.ladder import GuardLadder
from kcplan.planning.states import joint_state, state_pose
from kcplan.world.collision import CollisionWorld

__all__ = ["KCMotionValidator"]


class KCMotionValidator(ob.MotionValidator):
    """Certify OMPL edges with guards and certificates (see the module docstring).

    Parameters
    ----------
    si : ompl.base.SpaceInformation
        On an ``SE2StateSpace`` or ``SE3StateSpace``.
    robot : Robot or array_like or ArmModel
        The robot (:class:`kcplan.geometry.robot.Robot`), or the semi-axes ``(2,)`` or
        ``(3,)`` of one ellipse/ellipsoid at the origin, in the state space's length unit;
        or an arm (:class:`kcplan.arm.ArmModel`, with an :class:`kcplan.arm.ArmWorld`).
    world : object
        ``in_collision(pose) -> bool`` and ``safe_body_clearances(pose)`` for flat
        poses ``[x, y, yaw]`` / ``[x, y, z, qx, qy, qz, qw]``; ``free_regions`` for the
        ``region`` certificate and ``sweep_core_collides`` for ``sweep_test``, e.g.
        :class:`kcplan.world.CollisionWorld`.
    certificates : sequence of str, optional
        Default ``("region",)``, or ``("rotation",)`` when the world has no
        ``free_regions``; see :data:`kcplan.planning.certifier.CERTIFICATE_SETS`. For an
        arm ``("ball", "kc", "region")`` (the default: the chain's clearance balls, the
        KC guards and the free-region planes of :mod:`kcplan.planning.arm_certifier`), or
        ``("ball",)`` with any of ``"kc"`` and ``"region"``.
    fallback : {"bisection", "discrete"}
        What to do with the part of an edge the endpoint guards do not cover: more
        guards (exact, the default) or OMPL-style sampling at the space's
        validity-checking resolution.
    inflations : sequence of float, optional
        Guard inflation ladder of the ``polytope`` certificate (default
        :data:`kcplan.planning.ladder.DEFAULT_LADDER`); for an arm one number, the KC
        guards' inflation ``eps`` (default
        :data:`kcplan.planning.arm_certifier.DEFAULT_KC_INFLATION`).
    horizon : float, optional
        Region horizon in length units (default the largest semi-axis).
    max_guards : int, optional
        Guards per edge before giving up ("not proven" rejects the edge); default 64, or
        256 for an arm (whose joint-space edges are long).
    sweep_test : bool, optional
        Reject an edge whose robot core (ball of radius ``min(a)`` for one body) sweeps into an
        obstacle with one collision query before measuring guards (default: when the
        world has ``sweep_core_collides``).
    probes : int
        Collision queries at bisection points of an edge before its guards, so that a
        colliding edge is rejected at a collision query's price (default
        :data:`kcplan.planning.certifier.DEFAULT_PROBES`; 0: none).
    learn_schedule : bool
        Rigid robots: test the occupancy grid's cells only while the grid pays
        (:data:`kcplan.planning.certifier.LEARN_ODDS`); False: at every colliding state.
    backend : {"kernel", "python"}, optional
        Who decides: the compiled kernel (:class:`kcplan.planning.kernel.KernelCertifier`,
        on coal; the default for a :class:`kcplan.CollisionWorld`, whose robot it
        certifies) or the Python reference (:class:`kcplan.planning.certifier.EdgeCertifier`,
        on python-fcl; the default, and the only choice, for a world written in Python).
        Both decide every edge by the same steps; neither accepts an edge to a pose that
        is not finite.
    part_balls : bool
        Arms, compiled: decide the self pairs of two links far apart at once by balls
        around the links' bodies (``ArmCertifier``'s ``part_balls``; the same decisions,
        fewer pairs looked at). False is the ablation.
    first_order : bool
        Arms: bound each body's motion near a guard by its twist there as well
        (:mod:`kcplan.planning.arm_certifier`); False is the ablation.
    """

    def __init__(
        self,
        si: ob.SpaceInformation,
        robot: Robot | ArrayLike,
        world,
        certificates: Sequence[str] | None = None,
        fallback: str = "bisection",
        inflations: Sequence[float] | None = None,
        horizon: float | None = None,
        max_guards: int | None = None,
        sweep_test: bool | None = None,
        backend: str | None = None,
        probes: int = DEFAULT_PROBES,
        part_balls: bool = True,
        first_order: bool = True,
        learn_schedule: bool = True,
    ):
        super().__init__(si)
        self.space = si.getStateSpace()  # not si itself: see the module docstring
        self.error: Exception | None = None
        if isinstance(world, ArmWorld):
            self._init_arm(
                robot, world, certificates, fallback, max_guards, backend, probes,
                (part_balls, first_order, inflations),
            )  # fmt: skip
            return
        max_guards = 64 if max_guards is None else max_guards
        robot = Robot.of(robot)
        ladder = None
        if certificates is not None and "polytope" in certificates:
            ladder = GuardLadder(robot.semi_axes, inflations)
        compiled = isinstance(world, CollisionWorld)
        if backend is None:
            backend = "kernel" if compiled else "python"
        if backend not in ("kernel", "python"):
            raise ValueError(f"backend: expected 'kernel' or 'python', got {backend!r}")
        if backend == "kernel" and not compiled:
            raise ValueError(
                "backend: 'kernel' needs a kcplan.CollisionWorld, got "
                f"{type(world).__name__} (use backend='python' for a world written in Python)"
            )
        if backend == "kernel":
            if world.robot is not robot and robot.to_spec() != world.robot.to_spec():
                raise ValueError("robot: the kernel certifies the world's own robot; got another")
            self.certifier = KernelCertifier(
                world, certificates, ladder, horizon, fallback, max_guards, sweep_test,
                probes=probes, learn_schedule=learn_schedule,
            )  # fmt: skip
        else:
            self.certifier = EdgeCertifier(
                world, robot, certificates, ladder, horizon, fallback, max_guards, sweep_test,
                probes=probes, learn_schedule=learn_schedule,
            )  # fmt: skip
        self.backend = backend
        """``"kernel"`` (compiled, on coal) or ``"python"`` (the reference certifier)."""
        self.n = self.certifier.n
        self._read = lambda state, n=self.n: state_pose(state, n)
        if backend == "kernel":
            # the hot path: one call into the kernel with the pose(s), nothing else
            self.state_valid = self._valid_kernel_se2 if self.n == 2 else self._valid_kernel_se3
            if fallback != "discrete":  # the discrete fallback needs OMPL's resolution
                self.checkMotion = self._check_kernel_se2 if self.n == 2 else self._check_kernel_se3

    def _init_arm(
        self, arm, world, certificates, fallback, max_guards, backend, probes, options
    ) -> None:
        part_balls, first_order, inflations = options
        if arm is not world.arm:
            raise ValueError("robot: an ArmWorld certifies its own arm; got another robot")
        backend = "kernel" if backend is None else backend
        if backend not in ("kernel", "python"):
            raise ValueError(f"backend: expected 'kernel' or 'python', got {backend!r}")
        chosen = DEFAULT_ARM_CERTIFICATES if certificates is None else tuple(certificates)
        if (
            not chosen
            or chosen[0] != "ball"
            or not set(chosen[1:]) <= {"kc", "region"}
            or len(set(chosen)) != len(chosen)
            or fallback != "bisection"
        ):
            raise ValueError(
                f"certificates: arms have {ARM_CERTIFICATES}: 'ball', then any of the others "
                f"(default {DEFAULT_ARM_CERTIFICATES}), with bisection; got {certificates!r} "
                f"with {fallback!r}"
            )
        kc_inflation, planes = 0.0, "region" in chosen
        if "kc" in chosen:
            kc_inflation = DEFAULT_KC_INFLATION if not inflations else float(inflations[0])
            if not (math.isfinite(kc_inflation) and kc_inflation > 0.0):
                raise ValueError(f"inflations: expected a KC inflation > 0, got {inflations!r}")
        max_guards = 256 if max_guards is None else max_guards
        if backend == "kernel":
            self.certifier = KernelArmCertifier(
                world, max_guards, probes=probes > 0, part_balls=part_balls,
                first_order=first_order, kc_inflation=kc_inflation, planes=planes,
            )  # fmt: skip
            # the hot path: one call into the kernel with the joint vector(s)
            self.state_valid = self._valid_kernel_arm
            self.checkMotion = self._check_kernel_arm
        else:
            self.certifier = ArmEdgeCertifier(
                world, max_guards, probes=probes > 0, first_order=first_order,
                kc_inflation=kc_inflation, planes=planes,
            )  # fmt: skip
        self.backend = backend
        self.n = arm.dof
        self._read = lambda state, n=arm.dof: joint_state(state, n)

    def _valid_kernel_arm(self, state) -> bool:
        return self.certifier.compiled.state_valid([state[j] for j in range(self.n)])

    def _check_kernel_arm(self, s1, s2) -> bool:
        try:
            n, check = self.n, self.certifier.compiled.check
            q1, q2 = [s1[j] for j in range(n)], [s2[j] for j in range(n)]
            return self.error is None and check(q1, q2)
        except Exception as err:  # noqa: BLE001 - see checkMotion
            return self._fail(err)

    @property
    def counters(self) -> dict:
        """kcplan's counters (:data:`kcplan.planning.certifier.COUNTER_NAMES`) and, as
        ``covered_NAME``, the edge parameter each certificate covered."""
        return self.certifier.counters | {
            f"covered_{k}": round(v, 6) for k, v in self.certifier.covered.items()
        }

    def state_valid(self, state) -> bool:
        """A state validity check that shares the validator's cache: use it as the
        setup's checker so that edges ending at checked states skip that query."""
        return self.certifier.state_valid(self._read(state))

    def _check_kernel_se2(self, s1, s2) -> bool:
        try:
            return self.error is None and self.certifier.check_se2(
                s1.getX(), s1.getY(), s1.getYaw(), s2.getX(), s2.getY(), s2.getYaw()
            )
        except Exception as err:  # noqa: BLE001 - see checkMotion
            return self._fail(err)

    def _check_kernel_se3(self, s1, s2) -> bool:
        try:
            r1, r2 = s1.rotation(), s2.rotation()
            return self.error is None and self.certifier.check_se3(
                s1.getX(), s1.getY(), s1.getZ(), r1.x, r1.y, r1.z, r1.w,
                s2.getX(), s2.getY(), s2.getZ(), r2.x, r2.y, r2.z, r2.w,
            )  # fmt: skip
        except Exception as err:  # noqa: BLE001 - see checkMotion
            return self._fail(err)

    def _valid_kernel_se2(self, state) -> bool:
        return self.certifier.state_valid_se2(state.getX(), state.getY(), state.getYaw())

    def _valid_kernel_se3(self, state) -> bool:
        r = state.rotation()
        return self.certifier.state_valid_se3(
            state.getX(), state.getY(), state.getZ(), r.x, r.y, r.z, r.w
        )

    def _fail(self, err: Exception) -> bool:
        self.error = self.error or err
        return False

    def checkMotion(self, s1, s2) -> bool:  # noqa: N802 - OMPL's name
        if self.error is not None:
            return False
        try:
            resolution = 0.01
            if self.certifier.fallback == "discrete":
                length = self.space.distance(s1, s2)
                # si's validity-checking resolution times the space's extent
                step = self.space.getLongestValidSegmentLength()
                resolution = min(1.0, step / length) if length > 0 else 1.0
            return bool(self.certifier.check(self._read(s1), self._read(s2), resolution))
        except Exception as err:  # through PRM's C++ threads an exception aborts
            return self._fail(err)  # rejecting is always safe; raise_error() re-raises it

    def raise_error(self) -> None:
        """Re-raise the first exception a ``checkMotion`` call caught, if any. An exception
        must not cross OMPL's C++ frames (through PRM's worker threads it aborts the
        process), so ``checkMotion`` rejects the edge, stores the exception and makes
        every later call reject; call this after ``solve()``."""
        if self.error is not None:
            raise self.error

    def close(self) -> None:
        """Drop every reference the validator holds (optional: it makes no reference
        cycle with ``si``); ``checkMotion`` rejects every edge afterwards."""
        self.__dict__.clear()
        self.error = RuntimeError("KCMotionValidator: used after close()")
