"""Robot poses as flat vectors, and the KC coordinates of a straight edge between two poses.

Pose layout (the same numbers OMPL's SE(2)/SE(3) states hold):

* 2D: ``[x, y, yaw]``, yaw in radians, counter-clockwise;
* 3D: ``[x, y, z, qx, qy, qz, qw]``, a unit quaternion with the scalar **last** (as in
  ROS, scipy and OMPL's ``SO3State``; FCL wants ``[w, x, y, z]``).

Edges are interpolated the way OMPL does: linearly in translation, along the shortest arc
in yaw (2D) and by slerp (3D), so ``q(s) = (R1 exp(s hat(w12)), t1 + s (t2 - t1))`` with
``w12 = log(R1^T R2)`` (design notes, section 4).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.geometry.rotations import exp_rotation

__all__ = [
    "pose_size",
    "quaternion_matrix",
    "pose_frame",
    "wrap_angle",
    "quaternion_multiply",
    "rotate_vector",
    "so2_difference",
    "Edge",
]


def pose_size(n: int) -> int:
    """Length of a pose vector: 3 in 2D, 7 in 3D."""
    if n not in (2, 3):
        raise ValueError(f"dimension: expected 2 or 3, got {n}")
    return 3 if n == 2 else 7


def wrap_angle(angle: ArrayLike) -> NDArray[np.float64]:
    """Angles wrapped to ``[-pi, pi)``."""
    return (np.asarray(angle, dtype=float) + np.pi) % (2.0 * np.pi) - np.pi


def quaternion_matrix(q: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices of quaternions ``[qx, qy, qz, qw]`` (normalised here).

    Parameters
    ----------
    q : array_like, shape (k, 4) or (4,)

    Returns
    -------
    ndarray, shape (k, 3, 3) or (3, 3)
    """
    Q = np.asarray(q, dtype=float)
    single = Q.ndim == 1
    Q = np.atleast_2d(Q)
    Q = Q / np.linalg.norm(Q, axis=1, keepdims=True)
    x, y, z, w = Q.T
    R = np.stack(
        [
            1 - 2 * (y * y + z * z),
            2 * (x * y - z * w),
            2 * (x * z + y * w),
            2 * (x * y + z * w),
            1 - 2 * (x * x + z * z),
            2 * (y * z - x * w),
            2 * (x * z - y * w),
            2 * (y * z + x * w),
            1 - 2 * (x * x + y * y),
        ],
        axis=1,
    ).reshape(-1, 3, 3)
    return R[0] if single else R


def pose_frame(pose: ArrayLike, n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Rotation matrix and translation of poses.

    Parameters
    ----------
    pose : array_like, shape (k, 3 or 7) or (3 or 7,)
    n : int
        2 or 3.

    Returns
    -------
    R : ndarray, shape (k, n, n) or (n, n)
    t : ndarray, shape (k, n) or (n,)
    """
    P = np.asarray(pose, dtype=float)
    single = P.ndim == 1
    P = np.atleast_2d(P)
    if P.shape[1] != pose_size(n):
        raise ValueError(
            f"pose: expected {pose_size(n)} numbers per pose in {n}D, got {P.shape[1]}"
        )
    R = exp_rotation(P[:, 2:3], 2) if n == 2 else quaternion_matrix(P[:, 3:])
    R = R.reshape(-1, n, n)
    t = P[:, :n]
    return (R[0], t[0]) if single else (R, t)


def quaternion_multiply(p: ArrayLike, q: ArrayLike) -> tuple[float, float, float, float]:
    """Hamilton product of quaternions ``[x, y, z, w]`` (4 numbers each), as a tuple."""
    px, py, pz, pw = p
    qx, qy, qz, qw = q
    return (
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
        pw * qw - px * qx - py * qy - pz * qz,
    )


def rotate_vector(q: ArrayLike, v: ArrayLike) -> tuple[float, float, float]:
    """Rotate ``v`` (3 numbers) by the unit quaternion ``q = [x, y, z, w]``, as a tuple.

    ``v + w t + u x t`` with ``t = 2 u x v`` (written out: ``np.cross`` costs about 20 us
    on 3-vectors, more than an FCL query)."""
    ux, uy, uz, w = (float(c) for c in q)
    vx, vy, vz = (float(c) for c in v)
    tx, ty, tz = 2.0 * (uy * vz - uz * vy), 2.0 * (uz * vx - ux * vz), 2.0 * (ux * vy - uy * vx)
    return (
        vx + w * tx + uy * tz - uz * ty,
        vy + w * ty + uz * tx - ux * tz,
        vz + w * tz + ux * ty - uy * tx,
    )


def so2_difference(yaw1: float, yaw2: float) -> float:
    """Signed yaw change along OMPL's SO(2) interpolation from ``yaw1`` to ``yaw2``
    (the shorter arc; at exactly pi OMPL goes the direct way, and so does this)."""
    diff = yaw2 - yaw1
    if abs(diff) > np.pi:
        diff -= np.copysign(2.0 * np.pi, diff)
    return diff


class Edge:
    """A straight edge between two poses under OMPL's interpolation.

    ``q(s) = (R1 exp(s hat(w12)), t1 + s (t2 - t1))`` for ``s`` in [0, 1], with ``w12``
    the shorter rotation from R1 to R2 (SO(2): :func:`so2_difference`; SO(3): slerp, which
    flips q2 when ``q1 . q2 < 0``). Seen from the pose ``q(m)``, the robot's KC
    coordinates along the edge are ``xi(s) = (s - m) * direction(m)`` with
    ``direction(m) = [w12, R(m)^T (t2 - t1)]``: a straight line through the origin,
    because all rotations along the edge share one axis. So a guard at ``q(m)`` whose
    convex lower bound reaches ``lam+`` along ``direction(m)`` and ``lam-`` against it
    covers the whole stretch ``s in [m - lam-, m + lam+]`` (design notes, section 4).

    Parameters
    ----------
    pose1, pose2 : array_like, shape (3,) or (7,)
        ``[x, y, yaw]`` or ``[x, y, z, qx, qy, qz, qw]``.
    n : int
        2 or 3.

    Attributes
    ----------
    spin : tuple of 3 floats
        The angular velocity in the world frame, radians per unit ``s`` (``R1 w12``;
        ``(0, 0, turn)`` in 2D), the same at every ``s``: ``R(s) = exp((s - m)
        hat(spin)) R(m)``.
    """

    __slots__ = (
        "n",
        "t1",
        "dt",
        "yaw1",
        "w",
        "q1",
        "axis",
        "angle",
        "translation_speed",
        "rotation_speed",
        "spin",
    )

    def __init__(self, pose1: ArrayLike, pose2: ArrayLike, n: int):
        p1, p2 = np.asarray(pose1, dtype=float), np.asarray(pose2, dtype=float)
        self.n = n
        self.t1, self.dt = p1[:n], p2[:n] - p1[:n]
        self.translation_speed = math.sqrt(float(self.dt @ self.dt))  # |t2 - t1| per unit s
        if n == 2:
            self.yaw1 = float(p1[2])
            turn = so2_difference(float(p1[2]), float(p2[2]))
            self.w = np.array([turn])
            self.rotation_speed = abs(turn)  # radians per unit s
            self.spin = (0.0, 0.0, turn)
            return
        # plain floats: numpy costs microseconds per call on 4-vectors
        a1, b1, c1, d1 = (float(v) for v in p1[3:])
        a2, b2, c2, d2 = (float(v) for v in p2[3:])
        n1 = math.sqrt(a1 * a1 + b1 * b1 + c1 * c1 + d1 * d1)
        n2 = math.sqrt(a2 * a2 + b2 * b2 + c2 * c2 + d2 * d2)
        if a1 * a2 + b1 * b2 + c1 * c2 + d1 * d2 < 0.0:
            n2 = -n2  # slerp takes the shorter way: flip q2
        q1 = (a1 / n1, b1 / n1, c1 / n1, d1 / n1)
        q2 = (a2 / n2, b2 / n2, c2 / n2, d2 / n2)
        rx, ry, rz, rw = quaternion_multiply((-q1[0], -q1[1], -q1[2], q1[3]), q2)
        norm = math.sqrt(rx * rx + ry * ry + rz * rz)
        self.q1 = q1
        self.angle = 2.0 * math.atan2(norm, rw)
        self.axis = (rx / norm, ry / norm, rz / norm) if norm > 0.0 else (1.0, 0.0, 0.0)
        self.w = np.array(self.axis) * self.angle
        self.rotation_speed = abs(self.angle)
        x, y, z = rotate_vector(q1, self.axis)
        self.spin = (x * self.angle, y * self.angle, z * self.angle)

    def sweep_speed(self, radius: float) -> float:
        """Bound on how fast any point within ``radius`` of the robot's centre moves, per
        unit ``s``: ``|t2 - t1| + radius * |w12|`` (a rotation by angle ``phi`` moves such
        a point by a chord at most ``radius * phi``)."""
        return self.translation_speed + radius * self.rotation_speed

    def pose(self, s: float) -> NDArray[np.float64]:
        """The pose ``q(s)``."""
        t = self.t1 + s * self.dt
        if self.n == 2:
            yaw = (self.yaw1 + s * float(self.w[0]) + math.pi) % (2.0 * math.pi) - math.pi
            return np.array([t[0], t[1], yaw])  # wrap_angle in plain floats
        return np.array([t[0], t[1], t[2], *self._rotation(s)])

    def _rotation(self, s: float) -> NDArray:
        half = 0.5 * s * self.angle
        sh = math.sin(half)
        x, y, z = self.axis
        return quaternion_multiply(self.q1, (sh * x, sh * y, sh * z, math.cos(half)))

    def direction(self, s: float) -> NDArray[np.float64]:
        """KC coordinates per unit ``s`` seen from ``q(s)``: ``[w12, R(s)^T (t2 - t1)]``."""
        if self.n == 2:
            yaw = self.yaw1 + s * self.w[0]
            c, si = np.cos(yaw), np.sin(yaw)
            dx, dy = self.dt
            return np.array([self.w[0], c * dx + si * dy, -si * dx + c * dy])
        x, y, z, w = self._rotation(s)
        return np.concatenate([self.w, rotate_vector((-x, -y, -z, w), self.dt)])
