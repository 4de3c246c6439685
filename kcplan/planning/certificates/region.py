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
"""

from __future__ import annotations

import math

from numpy.typing import ArrayLike

from kcplan.geometry.pose import Edge
from kcplan.planning.guard import Guard

__all__ = ["FreeRegionPlanes"]


class FreeRegionPlanes:
    """Separating planes and clearances of the pieces within a guard's horizon.

    Parameters
    ----------
    semi_axes : array_like, shape (n,)
    """

    name = "region"

    def __init__(self, semi_axes: ArrayLike):
        a = [float(v) for v in semi_axes]
        self.lever = max(a) - min(a)

    def reach(self, guard: Guard, edge: Edge, m: float) -> tuple[float, float]:
        turn = self.lever * edge.rotation_speed
        speed = edge.translation_speed + turn
        if speed <= 0.0:
            return math.inf, math.inf
        minus = plus = guard.horizon / speed
        if not guard.planes:
            return minus, plus
        dx, dy, dz = edge.dt.tolist() + [0.0] * (3 - len(edge.dt))
        # a handful of pieces: plain floats beat numpy's per-call cost
        for nx, ny, nz, slack, clearance in guard.planes:
            ball = clearance / speed
            along = nx * dx + ny * dy + nz * dz
            if slack > 0.0:
                rate = turn - along  # slack used up per unit s going forward
                ahead = slack / rate if rate > 0.0 else math.inf
                rate = turn + along  # ... going backward
                behind = slack / rate if rate > 0.0 else math.inf
                plus = min(plus, max(ahead, ball))
                minus = min(minus, max(behind, ball))
            else:
                plus, minus = min(plus, ball), min(minus, ball)
        return minus, plus
