"""Forward kinematics of an arm from the joint placements and axes Pinocchio's model gives.

This is the chain the certificates bound (joint origins, axes, the frames between them),
written out in numpy so that it can be read and bounded term by term; the compiled kernel
will hold its C++ twin. Both are compared with ``pinocchio.forwardKinematics``
(``tests/test_arm.py``, to 1e-12 on random configurations).

Conventions: a frame is a 4 x 4 homogeneous matrix ``[[R, t], [0, 1]]`` mapping the
joint's (or body's) coordinates to the world's; joint ``i`` of the reduced model has the
frame ``oMi[i] = oMi[parent(i)] @ jointPlacements[i] @ motion_i(q)``, where
``motion_i`` turns by ``q`` about the joint's axis (revolute) or slides ``q`` along it
(prismatic), and ``oMi[0]`` (the universe) is the identity.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:  # the model calls these functions: no import at run time
    from kcplan.arm.model import ArmModel

__all__ = ["JOINT_KINDS", "body_frames", "joint_axes", "joint_frames", "link_frames"]

JOINT_KINDS = {
    "JointModelRX": ("revolute", (1.0, 0.0, 0.0)),
    "JointModelRY": ("revolute", (0.0, 1.0, 0.0)),
    "JointModelRZ": ("revolute", (0.0, 0.0, 1.0)),
    "JointModelRevoluteUnaligned": ("revolute", None),
    "JointModelPX": ("prismatic", (1.0, 0.0, 0.0)),
    "JointModelPY": ("prismatic", (0.0, 1.0, 0.0)),
    "JointModelPZ": ("prismatic", (0.0, 0.0, 1.0)),
    "JointModelPrismaticUnaligned": ("prismatic", None),
}
"""Pinocchio joint models a planning group may hold: ``(kind, axis)`` with the axis in
the joint's frame (None: read from the joint model). A continuous joint (Pinocchio's
``JointModelRUB*``, two configuration numbers cos and sin) is refused: its angle has no
limits for a joint-space box."""


def joint_axes(arm: ArmModel) -> NDArray[np.float64]:
    """Unit axis of every joint of the reduced model in its own frame, shape
    ``(njoints, 3)`` (row 0, the universe, is zero)."""
    model = arm.model
    axes = np.zeros((model.njoints, 3))
    for i in range(1, model.njoints):
        joint = model.joints[i]
        _, axis = JOINT_KINDS[joint.shortname()]
        if axis is None:  # an unaligned joint carries its axis
            axis = np.asarray(joint.extract().axis, dtype=float).ravel()
        axes[i] = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return axes


def _rotation(axis: NDArray[np.float64], angle: float) -> NDArray[np.float64]:
    """Rodrigues' formula: the rotation by ``angle`` about the unit ``axis``."""
    x, y, z = axis
    K = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


def joint_frames(arm: ArmModel, state: Sequence[float]) -> NDArray[np.float64]:
    """World frames of every joint of the reduced model at ``state`` (the group's joint
    values, :attr:`ArmModel.joints` order), shape ``(njoints, 4, 4)``."""
    model = arm.model
    q = arm.configuration(state)
    axes = joint_axes(arm)
    frames = np.empty((model.njoints, 4, 4))
    frames[0] = np.eye(4)
    for i in range(1, model.njoints):
        joint = model.joints[i]
        kind, _ = JOINT_KINDS[joint.shortname()]
        motion = np.eye(4)
        value = float(q[joint.idx_q])
        if kind == "revolute":
            motion[:3, :3] = _rotation(axes[i], value)
        else:
            motion[:3, 3] = value * axes[i]
        placement = np.asarray(model.jointPlacements[i].homogeneous, dtype=float)
        frames[i] = frames[model.parents[i]] @ placement @ motion
    return frames


def body_frames(arm: ArmModel, state: Sequence[float]) -> NDArray[np.float64]:
    """World frames of every covering body at ``state``, shape ``(len(arm.bodies), 4,
    4)``: body ``k`` is the ellipsoid of semi-axes ``arm.bodies[k].semi_axes`` about the
    frame's origin along its axes."""
    frames = joint_frames(arm, state)
    return np.stack([frames[b.joint] @ b.placement for b in arm.bodies])


def link_frames(arm: ArmModel, states: Sequence[Sequence[float]], link: str) -> NDArray[np.float64]:
    """World frames of the URDF link ``link`` at each of ``states`` (``(k, dof)``), shape
    ``(k, 4, 4)``: its parent joint's frame (:func:`joint_frames`) times the link's
    placement in it.

    Raises
    ------
    ValueError
        ``link: expected a link of the URDF ...`` for a name that is not one.
    """
    model = arm.model
    fid = model.getFrameId(link)
    if fid >= len(model.frames) or model.frames[fid].name != link:
        raise ValueError(f"link: expected a link of {arm.urdf}, got {link!r}")
    frame = model.frames[fid]
    placement = np.asarray(frame.placement.homogeneous, dtype=float)
    joint = int(frame.parentJoint)
    return np.stack([joint_frames(arm, q)[joint] @ placement for q in np.atleast_2d(states)])
