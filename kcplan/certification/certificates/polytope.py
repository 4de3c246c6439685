"""The paper's certificate: the convex lower bound ``P_eps`` of a free guard.

A guard ``(1 + eps) E_a`` at pose ``g`` is free when the robot's clearance there is at
least ``eps max(a)`` (``(1 + eps) E_a`` lies inside ``E_a + B(eps max(a))``). Every robot
pose whose KC coordinates relative to ``g`` lie in ``P_eps`` keeps the robot inside that
guard (paper Sec. 4; made sound in :mod:`kcplan.kc.convex`). Seen from ``q(m)`` the KC
coordinates of ``q(s)`` are ``(s - m) direction(m)`` (design notes, Sec. 4), a line
through the origin, so the guard covers ``[m - lam-, m + lam+]`` with ``lam+-`` the gauge
of ``P_eps`` along ``+-direction(m)`` (:meth:`GuardLadder.reach`). The ladder holds
polytopes for a few inflations; the largest one the clearance allows is used.

The polytope is the paper's bound for one ellipsoid ``E_a`` centred at the robot's
origin; for a robot of several bodies :class:`kcplan.certification.certifier.EdgeCertifier`
refuses it.
"""

from __future__ import annotations

from kcplan.certification.guard import Guard
from kcplan.certification.ladder import GuardLadder
from kcplan.geometry.pose import Edge

__all__ = ["KCPolytope"]


class KCPolytope:
    """The KC convex lower bound of the largest free guard on the ladder."""

    name = "polytope"

    def __init__(self, ladder: GuardLadder):
        self.ladder = ladder

    def reach(self, guard: Guard, edge: Edge, m: float) -> tuple[float, float]:
        level = self.ladder.level_for(guard.clearance)
        if level < 0:
            return 0.0, 0.0
        plus, minus = self.ladder.reach(level, edge.direction(m))
        return minus, plus
