"""Plug kcplan's KC motion validator into your own OMPL SE(2) setup.

No kcplan scenario file or collision world: the obstacles are python-fcl boxes built here,
and the "world" the validator needs is any object with two methods on flat poses
``[x, y, yaw]``: ``in_collision(pose) -> bool`` and ``safe_clearance(pose) -> float``
(a distance to the obstacles that never overestimates)::

    python scripts/own_setup_example.py
"""

from __future__ import annotations

import math

import fcl
import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from kcplan import KCMotionValidator

SEMI_AXES = (2.0, 1.0)  # robot ellipse, metres


class TwoWalls:
    """A 40 x 20 room with two walls and a gap; the robot ellipse as an FCL ellipsoid."""

    def __init__(self) -> None:
        walls = [((15.0, 6.0), (1.0, 12.0)), ((25.0, 14.0), (1.0, 12.0))]  # centre, size
        self.objects = [
            fcl.CollisionObject(fcl.Box(w, h, 10.0), fcl.Transform(np.array([x, y, 0.0])))
            for (x, y), (w, h) in walls
        ]
        self.manager = fcl.DynamicAABBTreeCollisionManager()
        self.manager.registerObjects(self.objects)
        self.manager.setup()
        a, b = SEMI_AXES
        # z semi-axis min(a): the ellipsoid's z = 0 slice and projection are the ellipse
        self.robot = fcl.CollisionObject(fcl.Ellipsoid(a, b, min(a, b)), fcl.Transform())

    def _place(self, pose) -> None:
        x, y, yaw = pose
        q = np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])  # FCL: [w, x, y, z]
        self.robot.setTransform(fcl.Transform(q, np.array([x, y, 0.0])))

    def in_collision(self, pose) -> bool:
        self._place(pose)
        data = fcl.CollisionData()
        self.manager.collide(self.robot, data, fcl.defaultCollisionCallback)
        return bool(data.result.is_collision)

    def safe_clearance(self, pose) -> float:
        self._place(pose)
        data = fcl.DistanceData()
        self.manager.distance(self.robot, data, fcl.defaultDistanceCallback)
        d = max(data.result.min_distance, 0.0)
        return max(d * (1 - 2e-3) - 1e-6, 0.0)  # FCL's GJK may overestimate slightly


def main() -> int:
    ou.setLogLevel(ou.LOG_WARN)
    ou.RNG.setSeed(5)
    world = TwoWalls()
    space = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0, 0.0)
    bounds.setHigh(0, 40.0)
    bounds.setLow(1, 0.0)
    bounds.setHigh(1, 20.0)
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    si.setStateValidityChecker(lambda s: not world.in_collision((s.getX(), s.getY(), s.getYaw())))
    validator = KCMotionValidator(si, SEMI_AXES, world)
    si.setMotionValidator(validator)
    start, goal = si.allocState(), si.allocState()
    start.setXY(5.0, 15.0)
    start.setYaw(0.0)
    goal.setXY(35.0, 5.0)
    goal.setYaw(math.pi / 2)
    ss.setStartAndGoalStates(start, goal)
    ss.setPlanner(og.RRTConnect(si))
    ss.solve(5.0)
    solved = ss.haveExactSolutionPath()
    if solved:
        ss.simplifySolution(1.0)
        path = ss.getSolutionPath()
        states = [(q.getX(), q.getY(), q.getYaw()) for q in path.getStates()]
        print(f"solved: {len(states)} states, length {path.length():.2f}")
        for x, y, yaw in states:
            print(f"  x {x:7.3f}  y {y:7.3f}  yaw {yaw:+.3f}")
        del path
    print("validator counters:", validator.counters)
    validator.close()  # break the si <-> validator cycle (no nanobind leak messages)
    return 0 if solved else 1


if __name__ == "__main__":
    raise SystemExit(main())
