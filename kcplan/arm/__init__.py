"""Arm robots: a URDF's chain (read by Pinocchio) with its links covered by ellipsoids.

:func:`load_arm` builds an :class:`ArmModel` (the immutable description);
:mod:`kcplan.arm.kinematics` computes joint and body frames from it.
"""

from kcplan.arm.kinematics import body_frames, joint_axes, joint_frames
from kcplan.arm.model import ArmBody, ArmError, ArmModel, load_arm

__all__ = [
    "ArmBody",
    "ArmError",
    "ArmModel",
    "body_frames",
    "joint_axes",
    "joint_frames",
    "load_arm",
]
