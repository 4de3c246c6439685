"""Plug kcplan's KC motion validator into your own OMPL SE(2) setup.

No kcplan scenario file or collision world: the obstacles are python-fcl boxes built here,
and the robot is made of two ellipses (an L). The "world" the validator needs is any
object with two methods on flat poses ``[x, y, yaw]`` of the robot's frame:
``in_collision(pose) -> bool`` and ``safe_body_clearances(pose)``, one distance per body
that never overestimates (for a one-body robot ``safe_clearance(pose) -> float`` is
enough). The validator's certificates handle the arc an offset body follows when the
robot turns::

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
from kcplan.geometry.robot import Body, Robot
from kcplan.planning.verify import verify_path

# two ellipses, metres and radians: a 2 x 1 body at the robot's origin and a 1.5 x 0.5
# arm whose centre sits at (-1, 1.3) in the robot frame, turned by 90 degrees
ROBOT = Robot(
    [
        Body(np.array([2.0, 1.0]), np.array([0.0, 0.0, 0.0])),
        Body(np.array([1.5, 0.5]), np.array([-1.0, 1.3, math.pi / 2])),
    ]
)


class TwoWalls:
    """A 40 x 20 room with two walls and a gap; each body as an FCL ellipsoid."""

    def __init__(self) -> None:
        walls = [((15.0, 6.0), (1.0, 12.0)), ((25.0, 14.0), (1.0, 12.0))]  # centre, size
        self.objects = [
            fcl.CollisionObject(fcl.Box(w, h, 10.0), fcl.Transform(np.array([x, y, 0.0])))
            for (x, y), (w, h) in walls
        ]
        self.manager = fcl.DynamicAABBTreeCollisionManager()
        self.manager.registerObjects(self.objects)
        self.manager.setup()
        # z semi-axis min(a): the ellipsoid's z = 0 slice and projection are the ellipse
        self.bodies = [
            fcl.CollisionObject(fcl.Ellipsoid(a, b, min(a, b)), fcl.Transform())
            for a, b in (body.semi_axes for body in ROBOT.bodies)
        ]

    def _place(self, pose) -> None:
        for body, (x, y, yaw) in zip(self.bodies, ROBOT.body_poses(pose), strict=True):
            q = np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])  # FCL: [w, x, y, z]
            body.setTransform(fcl.Transform(q, np.array([x, y, 0.0])))

    def in_collision(self, pose) -> bool:
        self._place(pose)
        for body in self.bodies:
            data = fcl.CollisionData()
            self.manager.collide(body, data, fcl.defaultCollisionCallback)
            if data.result.is_collision:
                return True
        return False

    # what kcplan.planning.verify_path needs to re-check a path independently
    dimension, robot = 2, ROBOT

    def safe_clearance(self, pose) -> float:
        return min(self.safe_body_clearances(pose))

    def safe_body_clearances(self, pose) -> list[float]:
        self._place(pose)
        out = []
        for body in self.bodies:
            data = fcl.DistanceData()
            self.manager.distance(body, data, fcl.defaultDistanceCallback)
            d = max(data.result.min_distance, 0.0)
            out.append(max(d * (1 - 2e-3) - 1e-6, 0.0))  # FCL's GJK may overestimate
        return out


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
    validator = KCMotionValidator(si, ROBOT, world)
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
        # independent of the certificates: gap-free conservative advancement
        check = verify_path(world, states)
        print(
            f"verified: {'COLLIDES' if check.collides else 'free'}, min clearance "
            f"{check.min_clearance:.3f} ({check.queries} clearance queries)"
        )
        solved = not check.collides
        del path
    print("validator counters:", validator.counters)
    validator.close()  # optional: drops the validator's references (it makes no cycle with si)
    return 0 if solved else 1


if __name__ == "__main__":
    raise SystemExit(main())
