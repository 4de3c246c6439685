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

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.geometry.rotations import exp_rotation, log_rotation

__all__ = [
    "pose_size",
    "quaternion_matrix",
    "pose_frame",
    "wrap_angle",
    "edge_coordinates",
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


def edge_coordinates(
    pose1: ArrayLike, pose2: ArrayLike, n: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """KC coordinates of an edge relative to its midpoint, and the midpoint pose.

    Under OMPL's interpolation the robot's pose along the edge, seen from the midpoint
    pose ``q(1/2)``, has KC coordinates ``xi(s) = (s - 1/2) xi12`` with
    ``xi12 = [w12, R_m^T (t2 - t1)]``: a segment through the origin (all rotations along
    the edge share one axis, and the translation moves at a constant rate). So the edge is
    inside a guard at the midpoint iff the segment from ``-xi12/2`` to ``+xi12/2`` is.

    Parameters
    ----------
    pose1, pose2 : array_like, shape (k, 3 or 7) or (3 or 7,)
        Edge end poses (layout in the module docstring).
    n : int
        2 or 3.

    Returns
    -------
    xi12 : ndarray, shape (k, 3 or 6) or (3 or 6,)
        ``[w12, R_m^T (t2 - t1)]``; rotation part in exponential coordinates (radians).
    midpoint : ndarray, shape (k, 3 or 7) or (3 or 7,)
        The pose ``q(1/2)``.
    """
    P1, P2 = np.atleast_2d(np.asarray(pose1, float)), np.atleast_2d(np.asarray(pose2, float))
    single = np.ndim(pose1) == 1 and np.ndim(pose2) == 1
    R1, t1 = pose_frame(P1, n)
    R2, t2 = pose_frame(P2, n)
    if n == 2:
        w12 = wrap_angle(P2[:, 2] - P1[:, 2])[:, None]
        yaw_m = wrap_angle(P1[:, 2] + 0.5 * w12[:, 0])
        Rm = exp_rotation(yaw_m[:, None], 2)
        mid = np.column_stack([0.5 * (t1 + t2), yaw_m])
    else:
        w12 = log_rotation(np.einsum("kji,kjl->kil", R1, R2)).reshape(-1, 3)
        Rm = R1 @ exp_rotation(0.5 * w12, 3).reshape(-1, 3, 3)
        mid = np.column_stack([0.5 * (t1 + t2), _matrix_quaternion(Rm, P1[:, 3:])])
    tau = np.einsum("kji,kj->ki", Rm, t2 - t1)
    xi12 = np.column_stack([w12, tau])
    return (xi12[0], mid[0]) if single else (xi12, mid)


def _matrix_quaternion(R: NDArray, hemisphere: NDArray) -> NDArray:
    """Quaternions ``[qx, qy, qz, qw]`` of rotation matrices, sign chosen to agree with
    ``hemisphere`` (so the midpoint of a slerp stays on the same side as its start)."""
    from scipy.spatial.transform import Rotation

    q = Rotation.from_matrix(R).as_quat()
    flip = np.einsum("ki,ki->k", q, hemisphere) < 0
    q[flip] *= -1.0
    return q
