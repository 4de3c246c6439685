"""Where the robot's origin cannot be: grid cells proven blocked for every orientation.

The robot contains the ball of radius ``r`` about its origin, whatever its orientation
(its core radius, :attr:`kcplan.geometry.robot.Robot.core_radius`: ``min(a)`` for
``E_a``). For a cell of half-diagonal ``h < r`` centred at ``c``, every centre
``x`` in the cell has ``B(c, r - h) ⊂ B(x, r) ⊂ E_a(x, R)``; so if the ball
``B(c, r - h)`` meets an obstacle (one FCL query), every robot pose with its centre in
the cell collides, and a lookup rejects such a state with no query. The grid only ever
proves collisions, never freedom.

Cells are tested lazily, when a state in them was found colliding (:meth:`learn`), so a
problem that samples few colliding states pays for few cells.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["CoreOccupancy"]

_UNKNOWN, _BLOCKED, _OPEN = 0, 1, 2


class CoreOccupancy:
    """A regular grid over the bounds whose cells are learned blocked or not.

    Parameters
    ----------
    world : kcplan.world.CollisionWorld
        Provides ``ball_collides(center, radius)``, ``robot`` and the scenario bounds.
    max_cells : int
        Upper bound on the number of cells. Cells have half-diagonal ``r / 2`` unless
        this bound needs larger ones, with ``r`` the robot's core radius
        (:attr:`kcplan.geometry.robot.Robot.core_radius`, ``min(a)`` for one body at the
        origin); when the half-diagonal would reach ``0.9 r`` the grid is disabled
        (``enabled`` False: it never blocks anything).

    Attributes
    ----------
    queries : int
        FCL queries spent testing cells.
    """

    def __init__(self, world, max_cells: int = 1_000_000):
        low, high = (np.asarray(b, dtype=float) for b in world.scenario.bounds)
        n = len(low)
        r = world.robot.core_radius
        extent = np.maximum(high - low, 1e-12)
        side = max(float(np.prod(extent) / max_cells) ** (1.0 / n), r / math.sqrt(n), 1e-12)
        half_diagonal = 0.5 * side * math.sqrt(n)
        self.world = world
        self.low, self.side, self.dimension = low.tolist(), side, n
        self.shape = tuple(int(math.ceil(e / side)) for e in extent)
        self.enabled = half_diagonal < 0.9 * r
        self.radius = (r - half_diagonal) * (1.0 - 1e-6)
        self.queries = 0
        self._blocked_cells = 0
        # tested cells only (a dict: no cost for the cells never visited)
        self._cells: dict[tuple[int, ...], int] = {}

    def _cell(self, position: ArrayLike) -> tuple | None:
        index = []
        for k in range(self.dimension):
            f = (float(position[k]) - self.low[k]) // self.side
            if not 0.0 <= f < self.shape[k]:  # before int(): inf and NaN have no index
                return None
            index.append(int(f))
        return tuple(index)

    def blocked(self, position: ArrayLike) -> bool:
        """True when the cell of ``position`` is known blocked (no query)."""
        if not self.enabled:
            return False
        cell = self._cell(position)
        return cell is not None and self._cells.get(cell) == _BLOCKED

    def learn(self, position: ArrayLike) -> bool:
        """Test the cell of ``position`` if it was never tested (one FCL query); whether
        it is blocked."""
        if not self.enabled:
            return False
        cell = self._cell(position)
        if cell is None:
            return False
        state = self._cells.get(cell, _UNKNOWN)
        if state == _UNKNOWN:
            centre = [lo + (i + 0.5) * self.side for lo, i in zip(self.low, cell, strict=True)]
            self.queries += 1
            state = _BLOCKED if self.world.ball_collides(np.array(centre), self.radius) else _OPEN
            self._cells[cell] = state
            self._blocked_cells += state == _BLOCKED
        return state == _BLOCKED

    def segment_blocked(self, start: ArrayLike, end: ArrayLike) -> bool:
        """True when a point of the segment ``start -> end`` (centre positions) lies in a
        cell known blocked (no query). Points are taken one cell length apart, so a
        blocked cell the segment only clips may be missed: a False proves nothing."""
        if not self.enabled:
            return False
        n = self.dimension
        a = [float(v) for v in start[:n]]
        b = [float(v) for v in end[:n]]
        d = [y - x for x, y in zip(a, b, strict=True)]
        cells = math.dist(a, b) / self.side
        steps = (int(cells) if cells < 255.0 else 255) + 1  # inf and NaN: 256
        cells, low, side, shape = self._cells, self.low, self.side, self.shape
        # one point per cell length, from the end backwards: a new state in an obstacle,
        # the common case, is found first; plain floats beat numpy on a few points
        for j in range(steps, -1, -1):
            f = j / steps
            cell = []
            for k in range(n):
                i = (a[k] + f * d[k] - low[k]) // side
                if not 0.0 <= i < shape[k]:
                    break
                cell.append(int(i))
            else:
                if cells.get(tuple(cell)) == _BLOCKED:
                    return True
        return False

    @property
    def blocked_fraction(self) -> float:
        """Fraction of all cells known blocked."""
        return self._blocked_cells / math.prod(self.shape) if self.enabled else 0.0
