"""An arm's state validity check as a Python user writes it by hand, on Pinocchio.

The checker of the ``rrtconnect-pin`` planner (:data:`kcplan.planning.problem.PLANNERS`):
stock OMPL RRT-Connect at OMPL's default resolution whose ``isValid`` is this Python
function. It holds the *same* bodies as :class:`kcplan.arm.world.ArmWorld` (those of
:attr:`kcplan.arm.ArmModel.bodies`: links' hulls as coal ``Convex`` shapes, ellipsoids as
``Ellipsoid`` shapes) in a ``pinocchio.GeometryModel``, each attached to the joint that
carries its link at the body's placement in that joint's frame; the scene's obstacles
are geometry objects of that model too, fixed to the universe (joint 0) at their pose.
The collision pairs are the checked self pairs (:attr:`ArmWorld.self_pairs`: the SRDF's
disabled pairs and the scene's allowed collision matrix removed) and every body with
every obstacle. A state is valid when it lies inside the joint limits and
``pinocchio.computeCollisions(geometry_model, geometry_data, True)`` finds no pair in
contact after ``pinocchio.forwardKinematics`` and ``pinocchio.updateGeometryPlacements``
placed the bodies.

Obstacles become the same solids as in :func:`kcplan.world.collision.fcl_obstacle_parts`
(:func:`kcplan.arm.shapes.coal_obstacle`). ``tests/test_arm_peers.py`` compares the verdicts with
:meth:`ArmWorld.in_collision` on random Panda states.

This is discrete state checking, not certification: OMPL's motion validator samples the
edge at its resolution and calls :meth:`PinChecker.is_valid` at each sample.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence

import numpy as np
from numpy.typing import ArrayLike

from kcplan.arm.model import ArmModel
from kcplan.arm.shapes import coal_obstacle
from kcplan.arm.world import checked_pairs
from kcplan.world.obstacles import Obstacle

__all__ = ["PinChecker"]


class PinChecker:
    """State validity of an arm with Pinocchio's ``computeCollisions`` (see the module
    docstring).

    Parameters
    ----------
    arm : ArmModel
        The arm and its covering ellipsoids (semi-axes in metres).
    obstacles : sequence of Obstacle
        3D obstacles in the arm's base frame.
    allowed : collection of frozenset of str
        Link pairs allowed to touch (a scene's allowed collision matrix).

    Attributes
    ----------
    geometry_model : pinocchio.GeometryModel
        The bodies (indices ``0 .. len(arm.bodies) - 1``, in ``arm.bodies`` order), then
        the obstacles' pieces, and the collision pairs.
    geometry_data : pinocchio.GeometryData
    self_pairs : int
        Number of body-body collision pairs (``len(checked_pairs(arm, allowed))``).
    obstacle_pairs : int
        Number of body-obstacle collision pairs (bodies times obstacles).
    calls : int
        Number of :meth:`in_collision` calls so far (states checked).

    Notes
    -----
    Not thread-safe: one ``pinocchio.Data`` and ``GeometryData`` are reused.
    """

    def __init__(self, arm: ArmModel, obstacles: Sequence[Obstacle] = (), allowed: Collection = ()):
        import coal
        import pinocchio as pin

        self.arm = arm
        self._pin = pin
        model = pin.GeometryModel()
        for k, body in enumerate(arm.bodies):
            model.addGeometryObject(
                pin.GeometryObject(
                    f"body{k}:{body.link}",
                    int(body.joint),
                    int(arm.model.getFrameId(body.link)),
                    pin.SE3(np.asarray(body.placement, dtype=float)),
                    _coal_shape(coal, body),
                )
            )
        first = len(arm.bodies)
        for ob in obstacles:
            geometry, pose = coal_obstacle(ob)
            model.addGeometryObject(pin.GeometryObject(f"obstacle{ob.index}", 0, 0, pose, geometry))
        pairs = checked_pairs(arm, frozenset(allowed))
        for i, j in pairs.tolist():
            model.addCollisionPair(pin.CollisionPair(i, j))
        for i in range(first):
            for k in range(first, model.ngeoms):
                model.addCollisionPair(pin.CollisionPair(i, k))
        self.geometry_model = model
        self.geometry_data = pin.GeometryData(model)
        self.self_pairs = len(pairs)
        self.obstacle_pairs = first * (model.ngeoms - first)
        self._data = arm.model.createData()
        self.calls = 0

    def in_collision(self, state: ArrayLike) -> bool:
        """Whether a body at ``state`` (joint values in ``arm.joints`` order, radians or
        metres) touches an obstacle or a body it may collide with.

        Raises
        ------
        ValueError
            When ``state`` is not ``arm.dof`` finite numbers.
        """
        q = np.asarray(state, dtype=float)
        if q.shape != (self.arm.dof,) or not np.isfinite(q).all():
            raise ValueError(
                f"state: expected {self.arm.dof} finite joint values, got {q.tolist()}"
            )
        pin, model = self._pin, self.arm.model
        self.calls += 1
        pin.forwardKinematics(model, self._data, self.arm.configuration(q))
        pin.updateGeometryPlacements(model, self._data, self.geometry_model, self.geometry_data)
        return bool(pin.computeCollisions(self.geometry_model, self.geometry_data, True))

    def is_valid(self, state) -> bool:
        """OMPL's ``isValid`` of a ``RealVectorStateSpace`` state of the group: inside the
        joint limits and not :meth:`in_collision`."""
        q = np.array([state[j] for j in range(self.arm.dof)])
        return self.arm.within_limits(q) and not self.in_collision(q)


def _coal_shape(coal, body):
    """The body's coal shape: its hull as a Convex, else its ellipsoid."""
    if body.hull is None:
        return coal.Ellipsoid(*np.asarray(body.semi_axes, dtype=float).tolist())
    points, triangles = coal.StdVec_Vec3s(), coal.StdVec_Triangle()
    for v in body.hull.vertices:
        points.append(np.asarray(v, dtype=float))
    for t in body.hull.triangles.tolist():
        triangles.append(coal.Triangle(*t))
    return coal.Convex(points, triangles)
