"""Clearance balls: conservative advancement, plain or rotation-aware.

If the robot at the guard pose ``g`` has clearance ``d``, the offset body
``E(g) + B(d)`` (Minkowski sum) is free. A convex body ``K`` lies inside a convex body
``L`` iff their support functions satisfy ``h_K(n) <= h_L(n)`` for every unit ``n``, and
``h_{E(g) + B(d)} = h_{E(g)} + d``. The robot at ``q = (R, t)`` has
``h_{E(q)}(n) = t . n + |A R^T n|`` (``A = diag(a)``), so ``E(q)`` stays free while

    |t(s) - t(m)| + L |theta(s) - theta(m)| <= d,

where ``L`` bounds how fast ``|A R^T n|`` changes per radian of rotation about any axis:

* ``L = max(a)`` (``ball``): every point of the robot lies within ``max(a)`` of its
  centre, and a rotation by ``phi`` moves it by a chord of at most ``max(a) phi``;
  classic conservative advancement.
* ``L = max(a) - min(a)`` (``rotation``). Proof: with ``u = R^T n`` (unit) and the body
  axis ``e`` of the rotation, ``d/dphi |A u(phi)| = -e . (u x A^2 u) / |A u|``, and
  ``|u x A^2 u|^2 = sum a_i^4 u_i^2 - (sum a_i^2 u_i^2)^2``, the variance ``Var(X)`` of
  ``X = a_i^2`` under the weights ``u_i^2``, whose mean is ``E = |A u|^2``. By the
  Bhatia-Davis inequality ``Var(X) <= (a_max^2 - E)(E - a_min^2)``, and
  ``(a_max^2 - E)(E - a_min^2) - (a_max - a_min)^2 E = -(E - a_max a_min)^2 <= 0``, so
  the rate is at most ``a_max - a_min`` (reached in 2D at ``E = a_max a_min``).
  A round robot turns for free.

Along an OMPL edge ``|t(s) - t(m)| = |s - m| |dt|`` and the rotation angle is
``|s - m| |w|``, so the ball covers ``|s - m| <= d / (|dt| + L |w|)`` on both sides.

Several bodies (:mod:`kcplan.geometry.robot`). Body ``k`` with centre ``p_k`` in the
robot frame has ``h_k(n) = n . (t + R p_k) + |A_k R_k^T R^T n|``. Rotating the robot by
``phi`` about its origin moves ``R p_k`` along an arc, by a chord of at most
``|p_k| phi``, so ``n . R p_k`` changes by at most ``|p_k| phi``; the last term changes
by at most ``(a_max,k - a_min,k) phi`` as above. With body ``k``'s own clearance
``d_k``, body ``k`` stays free while ``|s - m| (|dt| + L_k |w|) <= d_k`` with
``L_k = |p_k| + a_max,k - a_min,k`` (``rotation``) or ``|p_k| + a_max,k`` (``ball``:
every point of the body lies within that distance of the origin), and the edge is
covered where every body is: the minimum over bodies. One body at the origin gives the
levers above.
"""

from __future__ import annotations

import math

from numpy.typing import ArrayLike

from kcplan.certification.guard import Guard
from kcplan.geometry.pose import Edge
from kcplan.geometry.robot import Robot

__all__ = ["ClearanceBall"]


class ClearanceBall:
    """Conservative advancement with a clearance ball per body (see the module docstring).

    Parameters
    ----------
    robot : Robot or array_like
        The robot, or the semi-axes ``(n,)`` of one body at the origin.
    rotation_aware : bool
        Levers ``|p_k| + a_max,k - a_min,k`` (name ``rotation``) instead of
        ``|p_k| + a_max,k`` (``ball``).
    """

    def __init__(self, robot: Robot | ArrayLike, rotation_aware: bool = False):
        robot = Robot.of(robot)
        self.levers = robot.levers if rotation_aware else tuple(b.reach for b in robot.bodies)
        self.name = "rotation" if rotation_aware else "ball"

    def reach(self, guard: Guard, edge: Edge, m: float) -> tuple[float, float]:
        r = math.inf
        v, w = edge.translation_speed, edge.rotation_speed
        for body, lever in zip(guard.bodies, self.levers, strict=True):
            speed = v + lever * w
            if speed > 0.0:
                r = min(r, body.clearance / speed)
        return r, r
