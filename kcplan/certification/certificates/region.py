"""The free-region certificate: the robot moving inside a convex free region.

This is the Kinematics of Containment with the larger body being the free space itself.
A region guard lists every obstacle piece within a horizon ``H`` of the robot at
``q(m)`` (:meth:`kcplan.world.CollisionWorld.free_region`): for a convex piece ``i`` a
plane ``n_i . x <= c_i`` that contains the piece (its exact support function), with the
robot's slack ``sigma_i(m) = n_i . t(m) - |A R(m)^T n_i| - c_i > 0``
(:meth:`kcplan.certification.guard.Guard.from_region`), and the robot's clearance ``d_i`` to it.

Along the edge ``t(s) = t(m) + (s - m) dt`` exactly, and ``|A R(s)^T n|`` changes by at
most ``L |s - m| |w|`` with ``L = max(a) - min(a)`` (proof in
:mod:`kcplan.certification.certificates.ball`), so

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
``L``, and the edge's reach is the minimum over bodies and pieces: the *lever rule*
(certificate ``region-lever``).

The *arc rule* (``region``, the default) follows the arc to second order. The angular
velocity ``w`` is the same at every ``s`` in the world frame (``Edge.spin``), so with
``x = s - m`` and ``v = R(m) p_k`` (the guard's ``arm``), ``R(s) p_k = exp(x hat(w)) v``.
Let ``f(x) = exp(x hat(w)) v``: ``f(0) = v``, ``f'(0) = w x v`` and ``|f''| = |hat(w)^2
f| <= |w|^2 |v|``, so by Taylor's theorem with the integral remainder

    |R(s) p_k - R(m) p_k - x (w x v)| <= |p_k| |w|^2 x^2 / 2.

The centre moves by ``c_k(s) - c_k(m) = x c' + e`` with the velocity ``c' = dt + w x v``
and ``|e| <= b x^2``, ``b = |p_k| |w|^2 / 2``; the shape term is bounded as before. So

    sigma_ik(s) >= sigma_ik + x (n_i . c') - |x| L0 |w| - b x^2,   L0 = a_max,k - a_min,k,

and piece ``i`` stays on its side while ``b x^2 + r x < sigma_ik`` with ``r = L0 |w| -
n_i . c'`` going forward (``L0 |w| + n_i . c'`` backward): up to the positive root
``2 sigma / (r + sqrt(r^2 + 4 b sigma))``. Likewise every point of body ``k`` stays
within ``|x| (|c'| + L0 |w|) + b x^2`` of where it was, which bounds the reach of the
clearance ball and of the horizon. Both rules are sound, so each reach is the larger of
the two: for a body at the robot's origin (``p_k = 0``) they are the same rule, and for
long levers the arc rule is the longer wherever the turn does not carry the body towards
the plane.
"""

from __future__ import annotations

import math

from numpy.typing import ArrayLike

from kcplan.certification.guard import Guard
from kcplan.geometry.pose import Edge
from kcplan.geometry.robot import Robot

__all__ = ["FreeRegionPlanes"]


class FreeRegionPlanes:
    """Separating planes and clearances of the pieces within each body's horizon.

    Parameters
    ----------
    robot : Robot or array_like
        The robot, or the semi-axes ``(n,)`` of one body at the origin.
    arc : bool
        The arc rule as well as the lever rule (``region``); False: the lever rule alone
        (``region-lever``, the ablation).
    """

    def __init__(self, robot: Robot | ArrayLike, arc: bool = True):
        robot = Robot.of(robot)
        self.arc = bool(arc)
        self.name = "region" if self.arc else "region-lever"
        self.levers = robot.levers
        self.offsets = [b.offset for b in robot.bodies]
        self.shape_levers = [float(b.semi_axes.max() - b.semi_axes.min()) for b in robot.bodies]

    def reach(self, guard: Guard, edge: Edge, m: float) -> tuple[float, float]:
        minus = plus = math.inf
        v, w = edge.translation_speed, edge.rotation_speed
        dx, dy, dz = edge.dt.tolist() + [0.0] * (3 - len(edge.dt))
        ox, oy, oz = edge.spin
        for body, lever, shape_lever, offset in zip(
            guard.bodies, self.levers, self.shape_levers, self.offsets, strict=True
        ):
            turn = lever * w
            speed = v + turn
            if speed <= 0.0:
                continue
            # the arc rule: the centre's velocity c' = dt + w x R p_k, and its curvature term
            rx, ry, rz = body.arm
            cx, cy, cz = dx + oy * rz - oz * ry, dy + oz * rx - ox * rz, dz + ox * ry - oy * rx
            shape_turn = shape_lever * w
            # a body at the origin has no arc: the two rules are one (bend = inf: the lever's)
            bend = 0.5 * offset * w * w if self.arc and offset > 0.0 else math.inf
            arc_speed = math.sqrt(cx * cx + cy * cy + cz * cz) + shape_turn
            reach = _within(body.horizon, speed, arc_speed, bend)
            plus, minus = min(plus, reach), min(minus, reach)
            # a handful of pieces: plain floats beat numpy's per-call cost
            for nx, ny, nz, slack, clearance in body.planes:
                ball = _within(clearance, speed, arc_speed, bend)
                if slack > 0.0:
                    along = nx * dx + ny * dy + nz * dz
                    away = nx * cx + ny * cy + nz * cz  # n . c', off the piece
                    rate = turn - along  # slack used up per unit s going forward
                    ahead = max(
                        slack / rate if rate > 0.0 else math.inf,
                        _arc_reach(slack, shape_turn - away, bend),
                    )
                    rate = turn + along  # ... going backward
                    behind = max(
                        slack / rate if rate > 0.0 else math.inf,
                        _arc_reach(slack, shape_turn + away, bend),
                    )
                    plus = min(plus, max(ahead, ball))
                    minus = min(minus, max(behind, ball))
                else:
                    plus, minus = min(plus, ball), min(minus, ball)
        return minus, plus


def _within(d: float, speed: float, arc_speed: float, bend: float) -> float:
    """How long the body stays within distance ``d`` of where it is at ``m``: the longer
    of the lever rule's and the arc rule's reach."""
    return max(d / speed, _arc_reach(d, arc_speed, bend))


def _arc_reach(budget: float, rate: float, bend: float) -> float:
    """The least ``x > 0`` with ``budget - rate x - bend x^2 = 0`` (inf when there is
    none); 0 for no budget, and without the arc rule (``bend = inf``)."""
    if bend == math.inf or not budget > 0.0:
        return 0.0
    if budget == math.inf:
        return math.inf
    if bend <= 0.0:
        return budget / rate if rate > 0.0 else math.inf
    root = math.sqrt(rate * rate + 4.0 * bend * budget)
    # each form free of cancellation on its side of rate = 0
    return 2.0 * budget / (rate + root) if rate > 0.0 else (root - rate) / (2.0 * bend)
