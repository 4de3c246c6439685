"""A guard: what one query at a robot pose proves about the space around it.

Every certificate (:mod:`kcplan.planning.certificates`) reads a guard and nothing else
from the world, so a guard measured once at a state the planner keeps can certify every
later edge from that state with no new query (:class:`GuardCache`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from kcplan.geometry.pose import rotate_vector
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
    planes : tuple of (nx, ny, nz, slack, clearance)
        One row per obstacle piece within ``horizon`` (region guards only; empty
        otherwise), as plain floats (certificates loop over a handful of pieces faster
        than numpy can): the unit direction from the piece towards the robot (``nz = 0``
        in 2D); the robot's *slack* ``sigma_i = n_i . t - |A R^T n_i| - c_i - margin``,
        by how much the robot clears the piece's separating plane ``n_i . x <= c_i``
        (``-inf`` without a plane); and the robot's clearance to the piece.
    horizon : float
        Every piece not listed is at least this far from the robot (``clearance``
        for a guard without a region).
    """

    __slots__ = ("pose", "clearance", "planes", "horizon")

    def __init__(
        self, pose: NDArray, clearance: float, planes: tuple = (), horizon: float | None = None
    ):
        self.pose = pose
        self.clearance = float(clearance)
        self.planes = planes
        self.horizon = self.clearance if horizon is None else float(horizon)

    @property
    def slacks(self) -> NDArray[np.float64]:
        """The planes' slacks, shape (k,)."""
        return np.array([row[3] for row in self.planes])

    @property
    def clearances(self) -> NDArray[np.float64]:
        """The pieces' clearances, shape (k,)."""
        return np.array([row[4] for row in self.planes])

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
        if region.clearance <= 0.0:
            return cls(pose, 0.0)
        p = pose.tolist()
        a = [float(v) for v in semi_axes] + [0.0] * (3 - len(semi_axes))
        if len(semi_axes) == 2:  # a yaw is a rotation about z: the 3D formula serves
            t = (p[0], p[1], 0.0)
            conjugate = (0.0, 0.0, -math.sin(0.5 * p[2]), math.cos(0.5 * p[2]))
        else:
            t = tuple(p[:3])
            qx, qy, qz, qw = p[3:]
            norm = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
            conjugate = (-qx / norm, -qy / norm, -qz / norm, qw / norm)
        pad = [0.0] * (3 - len(semi_axes))
        rows = []
        for normal, offset, d in zip(
            region.normals.tolist(),
            region.offsets.tolist(),
            region.clearances.tolist(),
            strict=True,
        ):
            nx, ny, nz = normal + pad
            slack = -math.inf
            if offset < math.inf:
                ux, uy, uz = rotate_vector(conjugate, (nx, ny, nz))  # R^T n
                h = math.sqrt((a[0] * ux) ** 2 + (a[1] * uy) ** 2 + (a[2] * uz) ** 2)  # |A R^T n|
                slack = nx * t[0] + ny * t[1] + nz * t[2] - h - offset - margin
            rows.append((nx, ny, nz, slack, d))
        return cls(pose, region.clearance, tuple(rows), region.horizon)


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
