"""The KC motion validator: an ``ompl.base.MotionValidator`` that certifies edges.

Usable in any OMPL setup on SE(2) or SE(3)::

    from kcplan import KCMotionValidator
    mv = KCMotionValidator(si, robot, world)    # robot: Robot or semi-axes
    si.setMotionValidator(mv)
    ...
    mv.close()          # when done: breaks the si <-> validator reference cycle

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

from collections.abc import Sequence

from numpy.typing import ArrayLike
from ompl import base as ob

from kcplan.geometry.robot import Robot
from kcplan.planning.certifier import EdgeCertifier
from kcplan.planning.ladder import GuardLadder
from kcplan.planning.states import state_pose

__all__ = ["KCMotionValidator"]


class KCMotionValidator(ob.MotionValidator):
    """Certify OMPL edges with guards and certificates (see the module docstring).

    Parameters
    ----------
    si : ompl.base.SpaceInformation
        On an ``SE2StateSpace`` or ``SE3StateSpace``.
    robot : Robot or array_like
        The robot (:class:`kcplan.geometry.robot.Robot`), or the semi-axes ``(2,)`` or
        ``(3,)`` of one ellipse/ellipsoid at the origin, in the state space's length unit.
    world : object
        ``in_collision(pose) -> bool`` and ``safe_body_clearances(pose)`` for flat
        poses ``[x, y, yaw]`` / ``[x, y, z, qx, qy, qz, qw]``; ``free_regions`` for the
        ``region`` certificate and ``sweep_core_collides`` for ``sweep_test``, e.g.
        :class:`kcplan.world.CollisionWorld`.
    certificates : sequence of str, optional
        Default ``("region",)``, or ``("rotation",)`` when the world has no
        ``free_regions``; see :data:`kcplan.planning.certifier.CERTIFICATE_SETS`.
    fallback : {"bisection", "discrete"}
        What to do with the part of an edge the endpoint guards do not cover: more
        guards (exact, the default) or OMPL-style sampling at the space's
        validity-checking resolution.
    inflations : sequence of float, optional
        Guard inflation ladder of the ``polytope`` certificate (default
        :data:`kcplan.planning.ladder.DEFAULT_LADDER`).
    horizon : float, optional
        Region horizon in length units (default the largest semi-axis).
    max_guards : int
        Guards per edge before giving up ("not proven" rejects the edge).
    sweep_test : bool, optional
        Reject an edge whose robot core (ball of radius ``min(a)`` for one body) sweeps into an
        obstacle with one collision query before measuring guards (default: when the
        world has ``sweep_core_collides``).
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
        max_guards: int = 64,
        sweep_test: bool | None = None,
    ):
        super().__init__(si)
        self.si = si
        self.space = si.getStateSpace()
        ladder = None
        if certificates is not None and "polytope" in certificates:
            ladder = GuardLadder(Robot.of(robot).semi_axes, inflations)
        self.certifier = EdgeCertifier(
            world,
            robot,
            certificates,
            ladder,
            horizon,
            fallback,
            max_guards,
            sweep_test,
        )
        self.n = self.certifier.n
        self.error: Exception | None = None

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
        return self.certifier.state_valid(state_pose(state, self.n))

    def checkMotion(self, s1, s2) -> bool:  # noqa: N802 - OMPL's name
        if self.error is not None:
            return False
        try:
            resolution = 0.01
            if self.certifier.fallback == "discrete":
                length = self.space.distance(s1, s2)
                extent = self.space.getMaximumExtent()
                step = self.si.getStateValidityCheckingResolution() * extent
                resolution = min(1.0, step / length) if length > 0 else 1.0
            return bool(
                self.certifier.check(state_pose(s1, self.n), state_pose(s2, self.n), resolution)
            )
        except Exception as err:  # through PRM's C++ threads an exception aborts
            self.error = err  # rejecting is always safe; raise_error() re-raises after solve
            return False

    def raise_error(self) -> None:
        """Re-raise the first exception a ``checkMotion`` call caught, if any. An exception
        must not cross OMPL's C++ frames (through PRM's worker threads it aborts the
        process), so ``checkMotion`` rejects the edge, stores the exception and makes
        every later call reject; call this after ``solve()``."""
        if self.error is not None:
            raise self.error

    def close(self) -> None:
        """Drop references to OMPL objects (call when done; see ompl-python-notes 6)."""
        self.__dict__.clear()
