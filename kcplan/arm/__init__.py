"""Arm robots: a URDF's chain (read by Pinocchio), each link its own convex hull.

:func:`load_arm` builds an :class:`ArmModel` (the immutable description): by default
each link is its collision mesh's convex hull (:mod:`kcplan.arm.hulls`), or, asked for,
covered by ellipsoids (:mod:`kcplan.cover`); parts can be attached to a link
(:mod:`kcplan.arm.attach`) and pairs of links proven never to touch are left out
(:mod:`kcplan.arm.pairs`); an SRDF's planning groups and named states choose the joints
and the states (:mod:`kcplan.arm.srdf`);
:mod:`kcplan.arm.kinematics` computes joint and body frames from it, and
:mod:`kcplan.arm.bounds` bounds how far its bodies move along a joint-space edge.
"""

from kcplan.arm.bounds import carries, pair_speeds, point_speeds, speeds
from kcplan.arm.kinematics import body_frames, joint_axes, joint_frames
from kcplan.arm.model import ArmBody, ArmError, ArmModel, load_arm
from kcplan.arm.world import ArmWorld

__all__ = [
    "ArmBody",
    "ArmError",
    "ArmModel",
    "ArmWorld",
    "body_frames",
    "carries",
    "joint_axes",
    "joint_frames",
    "load_arm",
    "pair_speeds",
    "point_speeds",
    "speeds",
]
