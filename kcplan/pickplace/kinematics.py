"""Forward kinematics of the KUKA LWR 4 (7 revolute joints), standard Denavit-Hartenberg.

Parameters (metres, radians), one row per joint ``i``: ``(d_i, a_i, alpha_i)``, joint
angle ``theta_i = q_i``; frame ``i`` follows frame ``i - 1`` by
``Rot_z(theta_i) Trans_z(d_i) Trans_x(a_i) Rot_x(alpha_i)``.

The link twists and the offsets ``d3 = 0.4`` and ``d5 = 0.39`` are those of C. Gaz,
F. Flacco, A. De Luca, "Identifying the Dynamic Model Used by the KUKA LWR: A Reverse
Engineering Approach", ICRA 2014, Table I (as used by the Robotics Toolbox model
``mdl_LWR``, whose second twist ``-pi`` is a known typo for ``-pi/2``). The base height
``d1 = 0.3105`` and flange length ``d7 = 0.078`` are KUKA's LWR 4+ dimensions, which the
paper's setting needs because the object is held at the flange. The zero configuration is
the arm stretched straight up along the base z axis.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["LWR_DH", "dh_transform", "forward_kinematics"]

LWR_DH = np.array(
    [
        # d       a    alpha
        [0.3105, 0.0, np.pi / 2],
        [0.0, 0.0, -np.pi / 2],
        [0.4, 0.0, -np.pi / 2],
        [0.0, 0.0, np.pi / 2],
        [0.39, 0.0, np.pi / 2],
        [0.0, 0.0, -np.pi / 2],
        [0.078, 0.0, 0.0],
    ]
)
"""Standard DH parameters ``(d, a, alpha)`` of the KUKA LWR 4, shape (7, 3)."""


def dh_transform(theta: ArrayLike, d: float, a: float, alpha: float) -> NDArray[np.float64]:
    """``Rot_z(theta) Trans_z(d) Trans_x(a) Rot_x(alpha)`` for each angle, shape (k, 4, 4)."""
    t = np.atleast_1d(np.asarray(theta, dtype=float))
    ct, st = np.cos(t), np.sin(t)
    ca, sa = np.cos(alpha), np.sin(alpha)
    T = np.zeros((len(t), 4, 4))
    T[:, 0, 0], T[:, 0, 1], T[:, 0, 2], T[:, 0, 3] = ct, -st * ca, st * sa, a * ct
    T[:, 1, 0], T[:, 1, 1], T[:, 1, 2], T[:, 1, 3] = st, ct * ca, -ct * sa, a * st
    T[:, 2, 1], T[:, 2, 2], T[:, 2, 3] = sa, ca, d
    T[:, 3, 3] = 1.0
    return T


def forward_kinematics(q: ArrayLike, dh: ArrayLike = LWR_DH) -> NDArray[np.float64]:
    """Flange pose in the base frame for each joint vector.

    Parameters
    ----------
    q : array_like, shape (k, 7) or (7,)
        Joint angles in radians.
    dh : array_like, shape (7, 3)
        ``(d, a, alpha)`` per joint, default :data:`LWR_DH`.

    Returns
    -------
    ndarray, shape (k, 4, 4) or (4, 4)
        Homogeneous transforms (rotation, translation in metres).
    """
    Q = np.asarray(q, dtype=float)
    single = Q.ndim == 1
    Q = np.atleast_2d(Q)
    params = np.asarray(dh, dtype=float)
    if Q.shape[1] != len(params):
        raise ValueError(f"q: expected {len(params)} joint angles per row, got {Q.shape[1]}")
    T = np.broadcast_to(np.eye(4), (len(Q), 4, 4)).copy()
    for i, (d, a, alpha) in enumerate(params):
        T = T @ dh_transform(Q[:, i], d, a, alpha)
    return T[0] if single else T
