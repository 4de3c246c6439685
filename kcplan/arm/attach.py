"""Objects attached to an arm's link: a grasped part that moves with the link.

In the spirit of MoveIt's ``AttachedCollisionObject`` (a link, an object whose pose is in
the link's frame, and ``touch_links`` allowed to touch it): :func:`attach` returns a new
:class:`kcplan.arm.ArmModel` whose Pinocchio geometry holds each object as one more
collision object of its link's joint, so that everything built on the arm sees it as a
part of that link: its bodies (its hull, :mod:`kcplan.arm.hulls`) are carried by the
joint, their speeds bounded through the chain like the link's, checked against the scene
and against every link but its own and its ``touch`` links (and the pairs a scene
allows), proven apart where they cannot touch (:mod:`kcplan.arm.pairs`), verified on
its own shape by :mod:`kcplan.arm.verify` and drawn by the views. Nothing of the arm is
fitted again; :func:`detach` gives the arm back.

This module imports neither OMPL nor FCL.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from kcplan.arm.model import ArmBody, ArmError, ArmModel, hull_bodies, self_pairs_of
from kcplan.arm.shapes import coal_obstacle
from kcplan.world.obstacles import Obstacle

__all__ = ["Attached", "attach", "detach"]


@dataclass(frozen=True)
class Attached:
    """One object held by a link.

    Attributes
    ----------
    name : str
        Its name: the "link" of its bodies, for allowed pairs and reports.
    link : str
        The URDF link that holds it.
    shape : Obstacle
        Its solid (a scenario obstacle of kind ``box``, ``cylinder``, ``sphere`` or
        ``mesh``) with centre, rotation and vertices in the link's frame, metres.
    touch : tuple of str
        Links it may touch (the fingers that hold it); its own link always may.
    """

    name: str
    link: str
    shape: Obstacle
    touch: tuple[str, ...] = ()


def attach(arm: ArmModel, objects: Sequence[Attached]) -> ArmModel:
    """``arm`` holding ``objects`` (module docstring); ``arm`` itself is unchanged.

    Raises
    ------
    ArmError
        An unknown link or touch link, a name already used, an arm covered by ellipsoids
        (attached objects are hulls), or a shape that is not a solid.
    """
    import pinocchio as pin

    if arm.bodies and all(b.hull is None for b in arm.bodies):
        raise ArmError(f"{arm.urdf}: attached: expected an arm of hulls (robot.representation)")
    model, geometry = arm.model, arm.geometry.copy()
    links = {model.frames[o.parentFrame].name for o in geometry.geometryObjects}
    names = links | {b.link for b in arm.bodies}
    bodies = list(arm.bodies)
    for obj in objects:
        for name in (obj.link, *obj.touch):
            if not model.existFrame(name, pin.FrameType.BODY):
                raise ArmError(f"{arm.urdf}: attached.{obj.name}: {name!r} is not a link")
        if obj.name in names:
            raise ArmError(f"{arm.urdf}: attached.{obj.name}: the name is a link's or taken")
        names.add(obj.name)
        frame_id = model.getFrameId(obj.link, pin.FrameType.BODY)
        frame = model.frames[frame_id]
        try:
            shape, pose = coal_obstacle(obj.shape)
        except ValueError as err:
            raise ArmError(f"{arm.urdf}: attached.{obj.name}: {err}") from None
        placement = frame.placement * pose  # in the frame of the link's joint
        index = geometry.addGeometryObject(
            pin.GeometryObject(obj.name, int(frame.parentJoint), frame_id, placement, shape)
        )
        allowed = {obj.link, *obj.touch}
        for other, item in enumerate(geometry.geometryObjects[:index]):
            if model.frames[item.parentFrame].name not in allowed:
                geometry.addCollisionPair(pin.CollisionPair(other, index))
        new = geometry.geometryObjects[index]
        for frame_, semi_axes, hull in hull_bodies(new, arm.urdf):
            bodies.append(
                ArmBody(obj.name, index, int(new.parentJoint),
                        np.asarray(placement.homogeneous) @ frame_, semi_axes, hull)
            )  # fmt: skip
    base = arm.geometry if arm.base_geometry is None else arm.base_geometry
    return dataclasses.replace(
        arm, geometry=geometry, bodies=tuple(bodies), self_pairs=self_pairs_of(geometry, bodies),
        attached=(*arm.attached, *objects), base_geometry=base,
    )  # fmt: skip


def detach(arm: ArmModel, names: Sequence[str] | None = None) -> ArmModel:
    """``arm`` without the attached objects named (default: all of them).

    Raises
    ------
    ArmError
        A name that is not attached.
    """
    held = {obj.name: obj for obj in arm.attached}
    names = list(held) if names is None else list(names)
    for name in names:
        if name not in held:
            raise ArmError(f"{arm.urdf}: detach: {name!r} is not attached ({', '.join(held)})")
    if not held:
        return arm
    base = dataclasses.replace(
        arm, geometry=arm.base_geometry, attached=(), base_geometry=None,
        bodies=tuple(b for b in arm.bodies if b.link not in held),
    )  # fmt: skip
    base = dataclasses.replace(base, self_pairs=self_pairs_of(base.geometry, list(base.bodies)))
    keep = [held[n] for n in held if n not in names]
    return attach(base, keep) if keep else base
