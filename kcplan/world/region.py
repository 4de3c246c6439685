"""A free region around a robot pose: separating planes and clearances of nearby obstacles.

One region query (:meth:`kcplan.world.CollisionWorld.free_region`) finds every obstacle
piece within a horizon ``H`` of the robot with one broad-phase query, then measures each
with a narrow-phase distance query. For a convex piece ``i`` the nearest points ``p_r``
(robot) and ``p_o`` (obstacle) give a direction ``n_i = (p_r - p_o) / |p_r - p_o|``; the
piece lies in ``{x : n_i . x <= c_i}`` with ``c_i = h_i(n_i)`` its exact support function
(:mod:`.support`), so the planes bound a convex region containing the robot and free of
those pieces. Pieces the broad phase did not report are at least ``H`` away.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["FreeRegion"]


@dataclass(frozen=True, eq=False)
class FreeRegion:
    """What a region query knows about the obstacles around one robot pose.

    Attributes
    ----------
    normals : ndarray, shape (k, n)
        Unit directions from obstacle piece ``i`` towards the robot; a zero row where the
        piece is not convex (a mesh) or the direction is degenerate.
    offsets : ndarray, shape (k,)
        ``c_i``: piece ``i`` lies in ``{x : normals[i] . x <= offsets[i]}`` (exactly);
        ``inf`` on zero rows.
    clearances : ndarray, shape (k,)
        Distance from the robot at the pose to piece ``i``, never an overestimate
        (FCL's allowance subtracted, see :meth:`CollisionWorld.safe_clearance`).
    horizon : float
        Every obstacle piece not listed is at least this far from the robot.
    """

    normals: NDArray[np.float64]
    offsets: NDArray[np.float64]
    clearances: NDArray[np.float64]
    horizon: float

    @property
    def clearance(self) -> float:
        """Distance from the robot to every obstacle, never an overestimate; 0 when the
        robot touches one or is too close to tell."""
        if not len(self.clearances):
            return self.horizon
        return float(min(self.clearances.min(), self.horizon))

    @property
    def size(self) -> int:
        """Number of obstacle pieces within the horizon."""
        return len(self.clearances)

    @classmethod
    def colliding(cls, n: int) -> FreeRegion:
        """The region of a pose whose robot touches an obstacle (clearance 0)."""
        return cls(np.zeros((0, n)), np.zeros(0), np.zeros(0), 0.0)

    @classmethod
    def empty(cls, n: int, horizon: float = math.inf) -> FreeRegion:
        """No obstacle within ``horizon``."""
        return cls(np.zeros((0, n)), np.zeros(0), np.zeros(0), horizon)
