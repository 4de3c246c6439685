"""A guard: what one query at a robot pose proves about the space around it.

Every certificate (:mod:`kcplan.certification.certificates`) reads a guard and nothing else
from the world, so a guard measured once at a state the planner keeps can certify every
later edge from that state with no new query (:class:`GuardCache`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from kcplan.geometry.pose import rotate_vector
from kcplan.geometry.robot import Robot
from kcplan.world.region import FreeRegion

__all__ = ["BodyGuard", "Guard", "GuardCache"]


class BodyGuard(NamedTuple):
    """What a guard knows about one body of the robot.

    Attributes
    ----------
    clearance : float
        Distance from the body to every obstacle, never an overestimate (0: touching or
        too close to tell).
    planes : tuple of (nx, ny, nz, slack, clearance)
        One row per obstacle piece within ``horizon`` of the body (region guards only;
        empty otherwise), as plain floats (certificates loop over a handful of pieces
        faster than numpy can): the unit direction from the piece towards the body
        (``nz = 0`` in 2D); the body's *slack* ``sigma_i = n_i . c - |A R^T n_i| - c_i -
        margin`` (body centre ``c``, world orientation ``R``), by how much the body clears
        the piece's separating plane ``n_i . x <= c_i`` (``-inf`` without a plane); and
        the body's clearance to the piece.
    horizon : float
        Every piece not listed is at least this far from the body.
    arm : tuple of 3 floats
        ``R p``: the body's centre less the robot's origin, in the world frame (region
        guards; ``(0, 0, 0)`` otherwise).
    """

    clearance: float
    planes: tuple = ()
    horizon: float = 0.0
    arm: tuple = (0.0, 0.0, 0.0)


class Guard:
    """Measurements at one robot pose, per body.

    Attributes
    ----------
    pose : ndarray, shape (3,) or (7,)
    bodies : tuple of BodyGuard
        One per body of the robot, in the robot's order.
    clearance : float
        The smallest body clearance: distance from the robot to every obstacle, never an
        overestimate (0: touching or too close to tell).
    """

    __slots__ = ("pose", "bodies", "clearance")

    def __init__(self, pose: NDArray, bodies: tuple[BodyGuard, ...]):
        self.pose = pose
        self.bodies = bodies
        self.clearance = min(b.clearance for b in bodies)

    @classmethod
    def of_clearances(cls, pose: NDArray, clearances) -> Guard:
        """A clearance-only guard: body ``k`` has clearance (and horizon) ``clearances[k]``."""
        return cls(pose, tuple(BodyGuard(float(d), (), float(d)) for d in clearances))

    @property
    def slacks(self) -> NDArray[np.float64]:
        """The planes' slacks of every body, shape (total pieces,)."""
        return np.array([row[3] for b in self.bodies for row in b.planes])

    @property
    def piece_clearances(self) -> NDArray[np.float64]:
        """The pieces' clearances of every body, shape (total pieces,)."""
        return np.array([row[4] for b in self.bodies for row in b.planes])

    @classmethod
    def from_regions(
        cls, pose: NDArray, regions: tuple[FreeRegion, ...], robot: Robot, margin: float
    ) -> Guard:
        """A guard from a region query at ``pose`` (one region per body).

        Body ``k`` at world pose ``(R, c)`` is ``{c + R A u : |u| <= 1}``; its lowest
        point along ``n`` is ``n . c - |A R^T n|``, so it lies strictly on the free side
        of the plane ``n . x <= c_i`` exactly when ``n . c - |A R^T n| - c_i > 0``;
        ``margin`` (a length) absorbs floating-point rounding of that evaluation.
        """
        if any(region.clearance <= 0.0 for region in regions):
            return cls.of_clearances(pose, [0.0] * len(regions))
        n = robot.dimension
        pad = [0.0] * (3 - n)
        bodies = []
        # one body at the origin (the common case) is at the robot's pose: no numpy
        body_poses = [pose.tolist()] if robot.is_single else robot.body_poses(pose).tolist()
        origin = pose.tolist()[:n] + pad
        for body_pose, body, region in zip(body_poses, robot.bodies, regions, strict=True):
            a = [float(v) for v in body.semi_axes] + pad
            if n == 2:  # a yaw is a rotation about z: the 3D formula serves
                c = (body_pose[0], body_pose[1], 0.0)
                conjugate = (0.0, 0.0, -math.sin(0.5 * body_pose[2]), math.cos(0.5 * body_pose[2]))
            else:
                c = tuple(body_pose[:3])
                qx, qy, qz, qw = body_pose[3:]
                norm = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
                conjugate = (-qx / norm, -qy / norm, -qz / norm, qw / norm)
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
                    h = math.sqrt((a[0] * ux) ** 2 + (a[1] * uy) ** 2 + (a[2] * uz) ** 2)
                    slack = nx * c[0] + ny * c[1] + nz * c[2] - h - offset - margin
                rows.append((nx, ny, nz, slack, d))
            arm = (c[0] - origin[0], c[1] - origin[1], c[2] - origin[2])
            bodies.append(BodyGuard(region.clearance, tuple(rows), region.horizon, arm))
        return cls(pose, tuple(bodies))


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
