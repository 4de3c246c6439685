"""Gap-free path verification by conservative advancement (independent of KC bounds).

A pose with clearance ``d`` proves free every pose of the edge whose robot points moved
less than ``d`` from it; robot points move at most ``sweep_speed * |ds|``
(:meth:`kcplan.geometry.pose.Edge.sweep_speed`: translation change plus the robot's
reach times rotation angle change; the reach is the largest distance of a point of any
body from the robot's origin, :attr:`kcplan.geometry.robot.Robot.reach`). Stepping by
``d / sweep_speed`` therefore covers each edge without gaps, however thin the obstacles,
using only FCL clearances (the minimum over bodies).

The same walk checks a robot's own part (:class:`kcplan.world.part.PartWorld`, ``kcplan
verify --mesh``): any world with ``dimension``, ``safe_clearance(pose)`` and ``reach``
(or ``robot.reach``) will do, and one with ``encloses_obstacle(pose)`` is also asked
whether an obstacle lies wholly inside the robot at the first pose (a surface cannot see
it there).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from kcplan.geometry.pose import Edge
from kcplan.world.collision import CollisionWorld
from kcplan.world.part import PartWorld

__all__ = ["PathCheck", "verify_path"]


@dataclass
class PathCheck:
    """Result of :func:`verify_path`.

    ``collides`` is True when some pose along the path touches an obstacle, or comes
    closer than ``tolerance`` (then ``first_collision`` is that pose, on edge
    ``edge_index`` at parameter ``s``). ``min_clearance`` is the smallest FCL clearance
    seen (0 on collision); ``queries`` the number of clearance queries used.
    """

    collides: bool
    min_clearance: float
    queries: int
    edge_index: int = -1
    s: float = 0.0
    first_collision: list | None = None


def verify_path(
    world: CollisionWorld | PartWorld,
    states: ArrayLike,
    tolerance: float = 1e-6,
    max_queries: int = 10**6,
    padding: float = 0.0,
) -> PathCheck:
    """Check every edge of a path, interpolated as OMPL does, without gaps.

    Parameters
    ----------
    world : CollisionWorld or PartWorld
        The robot's ellipsoids, or its own part, against the obstacles.
    states : array_like, shape (k, 3 or 7)
        Flat poses of the path's waypoints.
    tolerance : float
        Clearances (after FCL's error allowance) below this count as a collision, in
        length units; this also bounds the number of steps near contact.
    max_queries : int
        Safety limit; exceeding it is reported as a collision (not proven free).
    padding : float
        The clearance the path must keep (length units): a pose nearer than ``padding +
        tolerance`` counts as a collision, and each step advances by the clearance less
        the padding, so the padding is checked without gaps (``min_clearance`` stays the
        clearance itself).
    """
    P = np.asarray(states, dtype=float)
    n = world.dimension
    radius = world.reach if hasattr(world, "reach") else world.robot.reach
    queries, lowest = 0, np.inf
    if len(P) == 1:
        P = np.vstack([P, P])
    enclosed = getattr(world, "encloses_obstacle", None)
    if enclosed is not None and enclosed(P[0]):
        return PathCheck(True, 0.0, 0, 0, 0.0, P[0].tolist())
    for k in range(len(P) - 1):
        edge = Edge(P[k], P[k + 1], n)
        speed = edge.sweep_speed(radius)
        s = 0.0
        while True:
            pose = edge.pose(s)
            d = world.safe_clearance(pose)
            queries += 1
            lowest = min(lowest, d)
            d -= padding  # the obstacles grown by the padding
            if d < tolerance or queries > max_queries:
                return PathCheck(
                    True, 0.0 if d < tolerance else lowest, queries, k, s, pose.tolist()
                )
            if s >= 1.0:
                break
            s = 1.0 if speed == 0.0 else min(1.0, s + d / speed)
    return PathCheck(False, float(lowest), queries)
