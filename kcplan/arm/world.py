"""Collision and clearance queries of an arm's covering ellipsoids, on python-fcl.

The reference world of arms (the compiled kernel will hold its twin): the bodies of an
:class:`kcplan.arm.ArmModel` placed at a joint configuration (:func:`body_frames`),
against the scene's obstacles (the scenario's 3D kinds, built as
:class:`kcplan.world.CollisionWorld` builds them) and against each other for the pairs
that may collide (:attr:`ArmModel.self_pairs`).

Distances from FCL's GJK may be slightly too large; the ``safe_*`` queries subtract the
same allowance as the rigid world (``d (1 - CLEARANCE_RTOL) - clearance_atol``,
:data:`kcplan.world.collision.CLEARANCE_RTOL`), so that a certificate built on them is
sound.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence

import fcl
import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.arm.kinematics import body_frames
from kcplan.arm.model import ArmModel
from kcplan.world.collision import CLEARANCE_ATOL, CLEARANCE_RTOL, fcl_obstacle_parts
from kcplan.world.scenario import Obstacle

__all__ = ["ArmWorld", "checked_pairs"]


def checked_pairs(arm: ArmModel, allowed: Collection[frozenset]) -> NDArray[np.int64]:
    """The body pairs of ``arm.self_pairs`` whose links are not an ``allowed`` pair."""
    keep = [
        (i, j)
        for i, j in arm.self_pairs
        if frozenset((arm.bodies[i].link, arm.bodies[j].link)) not in allowed
    ]
    return np.array(keep, dtype=np.int64).reshape(-1, 2)


class ArmWorld:
    """The scene of an arm: its obstacles and its self-collision pairs.

    Parameters
    ----------
    arm : ArmModel
    obstacles : sequence of Obstacle
        3D obstacles (:class:`kcplan.world.scenario.Obstacle`), in the arm's base frame.
    size : float, optional
        Size of the scene in metres, for FCL's absolute error allowance (default: the
        larger of 2 m and the obstacles' extent).
    allowed : collection of frozenset of str, optional
        Link pairs allowed to touch (a scene's allowed collision matrix): their bodies
        are not checked against each other.

    Notes
    -----
    States are joint vectors of shape ``(arm.dof,)`` in :attr:`ArmModel.joints` order.
    ``counters`` counts ``collision_queries`` and ``distance_queries`` (one per state
    queried). Not thread-safe: the bodies' FCL objects are reused.
    """

    def __init__(
        self,
        arm: ArmModel,
        obstacles: Sequence[Obstacle] = (),
        size: float | None = None,
        allowed: Collection[frozenset] = (),
    ):
        self.arm = arm
        self.obstacles = tuple(obstacles)
        self.allowed = frozenset(allowed)
        self.self_pairs = checked_pairs(arm, self.allowed)
        """The pairs of :attr:`ArmModel.self_pairs` whose links are not allowed to touch."""
        self._bodies = [
            fcl.CollisionObject(fcl.Ellipsoid(*b.semi_axes.tolist()), fcl.Transform())
            for b in arm.bodies
        ]
        self._objects = []
        for ob in self.obstacles:
            if len(ob.center) != 3:
                raise ValueError(f"{ob.label}: expected a 3D obstacle for an arm")
            for geometry, tf in fcl_obstacle_parts(ob, 3):
                self._objects.append(fcl.CollisionObject(geometry, tf))
        self._manager = fcl.DynamicAABBTreeCollisionManager()
        if self._objects:
            self._manager.registerObjects(self._objects)
            self._manager.setup()
        if size is None:
            corners = [ob.center for ob in self.obstacles] or [np.zeros(3)]
            size = max(2.0, float(np.ptp(np.array(corners), axis=0).max()))
        self.clearance_atol = CLEARANCE_ATOL * float(size)
        self.counters = {"collision_queries": 0, "distance_queries": 0}

    def reset_counters(self) -> None:
        """Set the query counters to zero."""
        self.counters = dict.fromkeys(self.counters, 0)

    def _place(self, state: ArrayLike) -> None:
        q = np.asarray(state, dtype=float)
        if q.shape != (self.arm.dof,) or not np.isfinite(q).all():
            raise ValueError(
                f"state: expected {self.arm.dof} finite joint values, got {q.tolist()}"
            )
        for obj, frame in zip(self._bodies, body_frames(self.arm, q), strict=True):
            obj.setTransform(fcl.Transform(frame[:3, :3], frame[:3, 3]))

    def in_collision(self, state: ArrayLike) -> bool:
        """Whether a body at ``state`` touches an obstacle or a body it may collide with
        (one collision query)."""
        self._place(state)
        self.counters["collision_queries"] += 1
        if self._objects:
            for obj in self._bodies:
                data = fcl.CollisionData()
                self._manager.collide(obj, data, fcl.defaultCollisionCallback)
                if data.result.is_collision:
                    return True
        request = fcl.CollisionRequest()
        for i, j in self.self_pairs:
            result = fcl.CollisionResult()
            if fcl.collide(self._bodies[i], self._bodies[j], request, result):
                return True
        return False

    def clearances(self, state: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Distances at ``state``: of each body to the nearest obstacle ``(bodies,)``
        (``inf`` without obstacles) and between the bodies of each self pair
        ``(pairs,)``, metres, 0 on contact (one distance query)."""
        self._place(state)
        self.counters["distance_queries"] += 1
        scene = np.full(len(self._bodies), math.inf)
        if self._objects:
            for k, obj in enumerate(self._bodies):
                data = fcl.DistanceData()
                self._manager.distance(obj, data, fcl.defaultDistanceCallback)
                scene[k] = max(float(data.result.min_distance), 0.0)
        pairs = np.empty(len(self.self_pairs))
        request = fcl.DistanceRequest()
        for m, (i, j) in enumerate(self.self_pairs):
            result = fcl.DistanceResult()
            pairs[m] = max(fcl.distance(self._bodies[i], self._bodies[j], request, result), 0.0)
        return scene, pairs

    def safe_clearances(self, state: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """:meth:`clearances` less FCL's error allowance: distances that are certain."""
        scene, pairs = self.clearances(state)
        return self._safe(scene), self._safe(pairs)

    def _safe(self, d: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.maximum(d * (1.0 - CLEARANCE_RTOL) - self.clearance_atol, 0.0)
