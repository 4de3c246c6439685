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
"""

from __future__ import annotations

import math

from numpy.typing import ArrayLike

from kcplan.geometry.pose import Edge
from kcplan.planning.guard import Guard

__all__ = ["ClearanceBall"]


class ClearanceBall:
    """Conservative advancement with a clearance ball (see the module docstring).

    Parameters
    ----------
    semi_axes : array_like, shape (n,)
    rotation_aware : bool
        Lever ``max(a) - min(a)`` (name ``rotation``) instead of ``max(a)`` (``ball``).
    """

    def __init__(self, semi_axes: ArrayLike, rotation_aware: bool = False):
        a = [float(v) for v in semi_axes]
        self.lever = max(a) - min(a) if rotation_aware else max(a)
        self.name = "rotation" if rotation_aware else "ball"

    def reach(self, guard: Guard, edge: Edge, m: float) -> tuple[float, float]:
        speed = edge.translation_speed + self.lever * edge.rotation_speed
        r = guard.clearance / speed if speed > 0.0 else math.inf
        return r, r
