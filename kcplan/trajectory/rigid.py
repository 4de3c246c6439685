"""Timing of a rigid robot's path within translational and angular speed limits.

An edge of an SE(2) or SE(3) path is OMPL's interpolation (:class:`kcplan.geometry.pose.
Edge`): the translation moves along the straight segment, ``|t2 - t1| = L`` long, while
the orientation turns about one fixed axis by ``A`` radians, both in proportion to the
edge's parameter ``f`` in ``[0, 1]``. So the robot's translational speed is ``L f'`` and its
angular speed ``A f'``: the edge is the straight 2-coordinate path ``(0, 0) -> (L, A)``
(distance travelled, angle turned), and limits on those two coordinates' speeds and
accelerations are exactly the translational and angular limits. Each edge is timed so
by TOPP-RA (:func:`kcplan.trajectory.timing.time_path`), from rest to rest: a rigid path
is not blended (its corners' certificate would need its own proof), it stops at every
corner, and each edge is one its planner certified. Imports neither OMPL nor FCL.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.geometry.pose import Edge, pose_size
from kcplan.trajectory.curve import BlendedPath
from kcplan.trajectory.timing import sample_times, time_path

__all__ = [
    "DEFAULT_RIGID_ACCELERATIONS",
    "DEFAULT_RIGID_SPEEDS",
    "RigidTrajectory",
    "time_rigid_path",
]

DEFAULT_RIGID_SPEEDS = (1.0, 1.0)
"""Translational (the scenario's length unit per second) and angular (rad/s) speed limits
when none are given."""
DEFAULT_RIGID_ACCELERATIONS = (2.0, 2.0)
"""Translational and angular acceleration limits when none are given (per second)."""


@dataclass(frozen=True, eq=False)
class RigidTrajectory:
    """A rigid robot's path timed edge by edge (module docstring).

    Attributes
    ----------
    waypoints : ndarray, shape (k, 3) or (k, 7)
        The path's poses (:mod:`kcplan.geometry.pose` layout).
    dimension : int
        2 or 3.
    timings : tuple of (int, Trajectory)
        Each moving edge's index and its timing on ``(0, 0) -> (L, A)``.
    starts : ndarray
        Seconds at which each of ``timings`` begins.
    velocity_limits, acceleration_limits : ndarray, shape (2,)
        Translational and angular limits it was timed with.
    """

    waypoints: NDArray[np.float64]
    dimension: int
    timings: tuple
    starts: NDArray[np.float64]
    velocity_limits: NDArray[np.float64]
    acceleration_limits: NDArray[np.float64]

    @property
    def duration(self) -> float:
        """Seconds from start to end."""
        if not self.timings:
            return 0.0
        return float(self.starts[-1] + self.timings[-1][1].duration)

    def at(self, t: ArrayLike) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """``(s, pose, velocity, acceleration)`` at the times ``t`` (seconds, ``(m,)``):
        ``s`` is the edge index plus the fraction along it; ``velocity`` and
        ``acceleration`` are the robot frame origin's linear velocity (``n``) followed by the
        angular velocity (1 number in 2D, 3 in 3D), world frame."""
        t = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        n = self.dimension
        width = n + (1 if n == 2 else 3)
        s = np.zeros(len(t))
        poses = np.tile(self.waypoints[0], (len(t), 1))
        vel, acc = np.zeros((len(t), width)), np.zeros((len(t), width))
        which = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, None)
        for j, (k, timing) in enumerate(self.timings):
            rows = np.flatnonzero(which == j)
            if rows.size == 0:
                continue
            edge = Edge(self.waypoints[k], self.waypoints[k + 1], n)
            arc, _, d1, d2 = timing.at(t[rows] - self.starts[j])
            total = timing.path.length  # sqrt(L^2 + A^2)
            u = np.array([edge.translation_speed, edge.rotation_speed]) / total
            f, fd, fdd = arc / total, (d1 @ u) / total, (d2 @ u) / total
            s[rows] = k + f
            poses[rows] = [edge.pose(x) for x in f]
            motion = np.concatenate([edge.dt, [edge.spin[2]] if n == 2 else edge.spin])
            vel[rows] = fd[:, None] * motion
            acc[rows] = fdd[:, None] * motion
        return s, poses, vel, acc

    def sample(self, rate: float) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray]:
        """``(t, s, pose, velocity, acceleration)`` every ``1 / rate`` s, the end included."""
        t = sample_times(self.duration, rate)
        return (t, *self.at(t))

    def peak_ratios(self) -> tuple[float, float]:
        """The largest translational or angular speed and acceleration over the limits,
        exactly (each edge's :meth:`Trajectory.peak_ratios`)."""
        peaks = [timing.peak_ratios() for _, timing in self.timings] or [(0.0, 0.0)]
        return max(p[0] for p in peaks), max(p[1] for p in peaks)


def time_rigid_path(
    waypoints: ArrayLike,
    dimension: int,
    velocity_limits: ArrayLike = DEFAULT_RIGID_SPEEDS,
    acceleration_limits: ArrayLike = DEFAULT_RIGID_ACCELERATIONS,
) -> RigidTrajectory:
    """Time a rigid robot's path edge by edge (module docstring).

    Parameters
    ----------
    waypoints : array_like, shape (k, 3) or (k, 7)
        Poses, ``k >= 1``.
    dimension : int
        2 or 3.
    velocity_limits, acceleration_limits : array_like, shape (2,)
        Translational and angular, > 0.
    """
    W = np.array(waypoints, dtype=float)
    if W.ndim != 2 or W.shape[1] != pose_size(dimension) or len(W) < 1:
        raise ValueError(f"waypoints: expected poses of {pose_size(dimension)} numbers")
    v = np.array(velocity_limits, dtype=float).reshape(-1)
    a = np.array(acceleration_limits, dtype=float).reshape(-1)
    timings, starts, clock = [], [], 0.0
    for k in range(len(W) - 1):
        edge = Edge(W[k], W[k + 1], dimension)
        length, angle = edge.translation_speed, edge.rotation_speed
        if length == 0.0 and angle == 0.0:
            continue
        timing = time_path(BlendedPath([[0.0, 0.0], [length, angle]]), v, a)
        timings.append((k, timing))
        starts.append(clock)
        clock += timing.duration
    return RigidTrajectory(W, dimension, tuple(timings), np.array(starts), v, a)
