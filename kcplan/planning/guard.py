"""A guard: what one query at a robot pose proves about the space around it.

Every certificate (:mod:`kcplan.planning.certificates`) reads a guard and nothing else
from the world, so a guard measured once at a state the planner keeps can certify every
later edge from that state with no new query (:class:`GuardCache`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from kcplan.geometry.pose import pose_frame
from kcplan.world.region import FreeRegion

__all__ = ["Guard", "GuardCache"]


class Guard:
    """Measurements at one robot pose.

    Attributes
    ----------
    pose : ndarray, shape (3,) or (7,)
    clearance : float
        Distance from the robot to every obstacle, never an overestimate (0: touching or
        too close to tell).
    normals, slacks, clearances : ndarray, shapes (k, n), (k,), (k,)
        For each obstacle piece within ``horizon`` (region guards only; ``k = 0``
        otherwise): the unit direction from the piece towards the robot, the robot's
        *slack* ``sigma_i = n_i . t - |A R^T n_i| - c_i - margin`` (by how much the robot
        clears the piece's separating plane ``n_i . x <= c_i``; ``-inf`` without a plane),
        and the robot's clearance to the piece.
    horizon : float
        Every piece not listed is at least this far from the robot (``clearance``
        for a guard without a region).
    planes : tuple of (nx, ny, nz, slack, clearance)
        The same rows as plain floats (``nz = 0`` in 2D), for certificates that loop
        over a handful of pieces faster than numpy can.
    """

    __slots__ = ("pose", "clearance", "normals", "slacks", "clearances", "horizon", "planes")

    def __init__(
        self,
        pose: NDArray,
        clearance: float,
        normals: NDArray | None = None,
        slacks: NDArray | None = None,
        clearances: NDArray | None = None,
        horizon: float | None = None,
    ):
        self.pose = pose
        self.clearance = float(clearance)
        n = 2 if len(pose) == 3 else 3
        self.normals = np.zeros((0, n)) if normals is None else normals
        self.slacks = np.zeros(0) if slacks is None else slacks
        self.clearances = np.zeros(0) if clearances is None else clearances
        self.horizon = self.clearance if horizon is None else float(horizon)
        pad = [0.0] * (3 - n)
        self.planes = tuple(
            (*row, *pad, sigma, d)
            for row, sigma, d in zip(
                self.normals.tolist(), self.slacks.tolist(), self.clearances.tolist(), strict=True
            )
        )

    @classmethod
    def from_region(
        cls, pose: NDArray, region: FreeRegion, semi_axes: NDArray, margin: float
    ) -> Guard:
        """A guard from a region query at ``pose``.

        The robot ``{t + R A u : |u| <= 1}`` has its lowest point along ``n`` at
        ``n . t - |A R^T n|``, so it lies strictly on the free side of the plane
        ``n . x <= c`` exactly when ``n . t - |A R^T n| - c > 0``; ``margin`` (a length)
        absorbs floating-point rounding of that evaluation.
        """
        n = len(semi_axes)
        if region.clearance <= 0.0:
            return cls(pose, 0.0)
        normals = region.normals
        slacks = np.full(region.size, -math.inf)
        planes = np.isfinite(region.offsets)
        if planes.any():
            R, t = pose_frame(pose, n)
            body = normals[planes] @ R * semi_axes  # rows: (A R^T n_i)^T
            slacks[planes] = (
                normals[planes] @ t
                - np.sqrt(np.einsum("ij,ij->i", body, body))
                - region.offsets[planes]
                - margin
            )
        return cls(pose, region.clearance, normals, slacks, region.clearances, region.horizon)


class GuardCache:
    """Guards and validity of the states a planner keeps, keyed by their exact pose.

    OMPL copies states bit for bit, so a state handed back to the validator has exactly
    the numbers it had when it was measured; the key is those bytes, and a different
    pose can never hit another pose's entry. At most ``max_entries`` guards and as many
    validity marks are kept; the oldest are dropped first.
    """

    def __init__(self, max_entries: int = 200_000):
        self.max_entries = int(max_entries)
        self._guards: dict[bytes, Guard] = {}
        self._valid: dict[bytes, bool] = {}

    def __len__(self) -> int:
        return len(self._guards)

    def guard(self, key: bytes) -> Guard | None:
        """The guard measured at this pose, if any."""
        return self._guards.get(key)

    def add_guard(self, key: bytes, guard: Guard) -> None:
        self._bounded(self._guards)[key] = guard

    def validity(self, key: bytes) -> bool | None:
        """Whether the state at this pose was found valid (None: never checked)."""
        guard = self._guards.get(key)
        if guard is not None:
            return guard.clearance > 0.0
        return self._valid.get(key)

    def add_validity(self, key: bytes, valid: bool) -> None:
        self._bounded(self._valid)[key] = bool(valid)

    def _bounded(self, table: dict) -> dict:
        if len(table) >= self.max_entries:
            for key in list(table)[: max(1, self.max_entries // 4)]:  # oldest quarter
                del table[key]
        return table
