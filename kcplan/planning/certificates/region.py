"""The free-region certificate: the robot moving inside a convex free region.

This is the Kinematics of Containment with the larger body being the free space itself.
A region guard lists every obstacle piece within a horizon ``H`` of the robot at
``q(m)`` (:meth:`kcplan.world.CollisionWorld.free_region`): for a convex piece ``i`` a
plane ``n_i . x <= c_i`` that contains the piece (its exact support function), with the
robot's slack ``sigma_i(m) = n_i . t(m) - |A R(m)^T n_i| - c_i > 0``
(:meth:`kcplan.planning.guard.Guard.from_region`), and the robot's clearance ``d_i`` to it.

Along the edge ``t(s) = t(m) + (s - m) dt`` exactly, and ``|A R(s)^T n|`` changes by at
most ``L |s - m| |w|`` with ``L = max(a) - min(a)`` (proof in
:mod:`kcplan.planning.certificates.ball`), so

    sigma_i(s) >= sigma_i(m) + (s - m) (n_i . dt) - |s - m| L |w|,

linear in ``|s - m|`` on each side: piece ``i`` stays on its side of the plane for
``s - m < sigma_i / (L |w| - n_i . dt)`` (forever when the edge moves away from the plane
faster than it turns), and for ``|s - m| <= d_i / (|dt| + L |w|)`` by its clearance
ball. Either proof suffices for that piece; pieces beyond the horizon are at least ``H``
away, covered by the ball of radius ``H``. The reach is the minimum over pieces. Motion
along a wall is free: only rotation and motion towards a plane use up its slack.
Non-convex pieces (meshes) have no plane and keep their clearance ball.

Several bodies (:mod:`kcplan.geometry.robot`). Each body ``k`` has its own region, with
slacks ``sigma_ik = n_i . c_k - |A_k R_k^T R^T n_i| - c_i`` of its centre
``c_k(s) = t(s) + R(s) p_k``. The centre of an offset body follows an arc, not the
chord: ``n_i . R(s) p_k`` changes by at most ``|p_k| |s - m| |w|`` (a rotation by
``phi`` about the origin moves ``p_k`` by a chord of at most ``|p_k| phi``), so the rule
above holds for body ``k`` with the lever ``L_k = |p_k| + a_max,k - a_min,k`` in place of
``L``, and the edge's reach is the minimum over bodies and pieces. (A second-order rule,
using the velocity of the body's centre at ``m`` and a remainder quadratic in
``|s - m|``, would be tighter for long levers; it is not used.)
"""

from __future__ import annotations

import math

from numpy.typing import ArrayLike

from kcplan.geometry.pose import Edge
from kcplan.geometry.robot import Robot
from kcplan.planning.guard import Guard

__all__ = ["FreeRegionPlanes"]


class FreeRegionPlanes:
    """Separating planes and clearances of the pieces within each body's horizon.

    Parameters
    ----------
    robot : Robot or array_like
        The robot, or the semi-axes ``(n,)`` of one body at the origin.
    """

    name = "region"

    def __init__(self, robot: Robot | ArrayLike):
        self.levers = Robot.of(robot).levers

    def reach(self, guard: Guard, edge: Edge, m: float) -> tuple[float, float]:
        minus = plus = math.inf
        v, w = edge.translation_speed, edge.rotation_speed
        dx, dy, dz = edge.dt.tolist() + [0.0] * (3 - len(edge.dt))
        for body, lever in zip(guard.bodies, self.levers, strict=True):
            turn = lever * w
            speed = v + turn
            if speed <= 0.0:
                continue
            reach = body.horizon / speed
            plus, minus = min(plus, reach), min(minus, reach)
            # a handful of pieces: plain floats beat numpy's per-call cost
            for nx, ny, nz, slack, clearance in body.planes:
                ball = clearance / speed
                if slack > 0.0:
                    along = nx * dx + ny * dy + nz * dz
                    rate = turn - along  # slack used up per unit s going forward
                    ahead = slack / rate if rate > 0.0 else math.inf
                    rate = turn + along  # ... going backward
                    behind = slack / rate if rate > 0.0 else math.inf
                    plus = min(plus, max(ahead, ball))
                    minus = min(minus, max(behind, ball))
                else:
                    plus, minus = min(plus, ball), min(minus, ball)
        return minus, plus
