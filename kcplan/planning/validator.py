"""The KC motion validator: an ``ompl.base.MotionValidator`` that certifies edges.

Usable in any OMPL setup on SE(2) or SE(3)::

    from kcplan import KCMotionValidator
    mv = KCMotionValidator(si, robot, world)    # robot: Robot or semi-axes
    si.setMotionValidator(mv)
    ...

and, for an arm, on the ``RealVectorStateSpace`` of its planning group (bounds: the
joint limits), with ``robot`` a :class:`kcplan.arm.ArmModel` and ``world`` its
:class:`kcplan.arm.ArmWorld` (edges decided by
:class:`kcplan.certification.arm_certifier.ArmEdgeCertifier`).

The validator keeps no reference to ``si`` (only to its state space): ``si`` holds the
validator through a C++ ``shared_ptr`` that Python's collector cannot see, so a reference
back would make a cycle that outlives the script, and nanobind would report its objects
as leaked at exit (ompl-python-notes, section 6).

Contract (OMPL's, as far as the Python binding allows):

* ``checkMotion(s1, s2)`` returns True only when the whole edge, interpolated as OMPL
  does (linear translation, shorter-arc yaw, slerp), is proven free. ``s1`` is assumed
  valid; ``s2`` is checked. The one exception is asked for by name: while
  :attr:`KCMotionValidator.screen_step` is set (a lazy planner growing its trees) an
  edge is only screened by probes, and the planner must certify its path.
* The OMPL 2.0 wheel dispatches only the two-argument ``checkMotion`` to Python. The
  three-argument form (with ``lastValid``) calls it and leaves ``lastValid`` untouched,
  so planners that use it (the KPIECE family) treat a rejected edge as wholly invalid;
  none of kcplan's registered planners uses that form.
* OMPL's own motion counters stay at zero for a Python validator; :attr:`counters` has
  kcplan's (see :class:`kcplan.certification.certifier.EdgeCertifier`).
* Not thread-safe; OMPL calls it from the thread that runs ``solve()``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray
from ompl import base as ob

from kcplan.arm.world import ArmWorld
from kcplan.certification.certifiers import certifier_for
from kcplan.geometry.robot import Robot
from kcplan.planning.states import joint_reader, state_pose

__all__ = ["KCMotionValidator"]


class KCMotionValidator(ob.MotionValidator):
    """Certify OMPL edges with guards and certificates (see the module docstring).

    Parameters
    ----------
    si : ompl.base.SpaceInformation
        On an ``SE2StateSpace`` or ``SE3StateSpace``, or an arm's joint space.
    robot : Robot or array_like or ArmModel
        The robot (:class:`kcplan.geometry.robot.Robot`), or the semi-axes ``(2,)`` or
        ``(3,)`` of one ellipse/ellipsoid at the origin, in the state space's length unit;
        or an arm (:class:`kcplan.arm.ArmModel`, with an :class:`kcplan.arm.ArmWorld`).
    world : object
        :class:`kcplan.CollisionWorld`, :class:`kcplan.arm.ArmWorld`, or a world written
        in Python (``in_collision(pose)``, ``safe_body_clearances(pose)``, and
        ``free_regions`` for the ``region`` certificate) for flat poses
        ``[x, y, yaw]`` / ``[x, y, z, qx, qy, qz, qw]``.
    certificates : sequence of str, optional
        The certificates (:func:`kcplan.certification.certifiers.certifier_for`).
    backend : {"kernel", "python"}, optional
        Who decides: the compiled kernel (on coal; the default where the world has one)
        or the Python reference (on python-fcl; the only choice for a world written in
        Python). Both decide every edge by the same steps; neither accepts an edge to a
        state that is not finite.
    **options
        The options of the robot's kind, :data:`kcplan.certification.certifiers.RIGID_OPTIONS`
        or :data:`~kcplan.certification.certifiers.ARM_OPTIONS`, described at
        :func:`~kcplan.certification.certifiers.certifier_for`, which chooses the certifier;
        an option of the other kind is one ``ValueError``.
    """

    def __init__(
        self,
        si: ob.SpaceInformation,
        robot: Robot | ArrayLike,
        world,
        certificates: Sequence[str] | None = None,
        backend: str | None = None,
        **options,
    ):
        super().__init__(si)
        self.space = si.getStateSpace()  # not si itself: see the module docstring
        self.error: Exception | None = None
        self.certifier = certifier_for(robot, world, backend, certificates=certificates, **options)
        """The certifier that decides (:data:`kcplan.certification.certifiers.Certifier`)."""
        self.backend = self.certifier.backend
        """``"kernel"`` (compiled, on coal) or ``"python"`` (the reference certifier)."""
        self.n = self.certifier.n
        self.screen_step: float | None = None
        """None (the default): ``checkMotion`` certifies. A step: it only *screens* the
        edge (``certifier.screen``: probes at most ``screen_step`` apart, radians of
        joint-space distance for an arm, length units of the robot's farthest point's
        motion for a rigid robot), which proves nothing; a lazy planner sets it while
        its trees grow and certifies the path it returns (:mod:`kcplan.planning.lazy`)."""
        arm = isinstance(world, ArmWorld)
        if arm:  # the state's layout worked out once, not per state read
            self._joints = joint_reader(self.n, world.arm.wraps)
            self._read = self._read_joints
        else:
            self._read = state_pose
        if self.backend != "kernel":
            return
        # the hot paths: one call into the kernel with the state's floats, nothing else
        if arm:
            self.state_valid, self.checkMotion = self._valid_kernel_arm, self._check_kernel_arm
        elif self.n == 2:
            self.state_valid = self._valid_kernel_se2
            if self.certifier.fallback != "discrete":  # which needs OMPL's resolution
                self.checkMotion = self._check_kernel_se2
        else:
            self.state_valid = self._valid_kernel_se3
            if self.certifier.fallback != "discrete":
                self.checkMotion = self._check_kernel_se3

    def _read_joints(self, state, n: int) -> NDArray[np.float64]:
        return np.array(self._joints(state))

    def _valid_kernel_arm(self, state) -> bool:
        return self.certifier.compiled.state_valid(self._joints(state))

    def _check_kernel_arm(self, s1, s2) -> bool:
        try:
            step, q1, q2 = self.screen_step, self._joints(s1), self._joints(s2)
            if step is not None:
                return self.error is None and self.certifier.compiled.screen(q1, q2, step)
            return self.error is None and self.certifier.compiled.check(q1, q2)
        except Exception as err:  # noqa: BLE001 - see checkMotion
            return self._fail(err)

    @property
    def counters(self) -> dict:
        """kcplan's counters (:data:`kcplan.certification.certifier.COUNTER_NAMES`) and, as
        ``covered_NAME``, the edge parameter each certificate covered."""
        return self.certifier.counters | {
            f"covered_{k}": round(v, 6) for k, v in self.certifier.covered.items()
        }

    def state_valid(self, state) -> bool:
        """A state validity check that shares the validator's cache: use it as the
        setup's checker so that edges ending at checked states skip that query."""
        return self.certifier.state_valid(self._read(state, self.n))

    def _check_kernel_se2(self, s1, s2) -> bool:
        try:
            args = (s1.getX(), s1.getY(), s1.getYaw(), s2.getX(), s2.getY(), s2.getYaw())
            if self.screen_step is not None:
                return self.error is None and self.certifier.screen_se2(*args, self.screen_step)
            return self.error is None and self.certifier.check_se2(*args)
        except Exception as err:  # noqa: BLE001 - see checkMotion
            return self._fail(err)

    def _check_kernel_se3(self, s1, s2) -> bool:
        try:
            r1, r2 = s1.rotation(), s2.rotation()
            args = (
                s1.getX(), s1.getY(), s1.getZ(), r1.x, r1.y, r1.z, r1.w,
                s2.getX(), s2.getY(), s2.getZ(), r2.x, r2.y, r2.z, r2.w,
            )  # fmt: skip
            if self.screen_step is not None:
                return self.error is None and self.certifier.screen_se3(*args, self.screen_step)
            return self.error is None and self.certifier.check_se3(*args)
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
            q1, q2 = self._read(s1, self.n), self._read(s2, self.n)
            if self.screen_step is not None:
                return bool(self.certifier.screen(q1, q2, self.screen_step))
            return bool(self.certifier.check(q1, q2, resolution))
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
