"""What an SRDF says beside the disabled pairs: planning groups, named states and the base.

MoveIt's semantic robot description names **groups** of joints to plan for (``<group>``:
joints, links, chains and subgroups), **named states** of a group (``<group_state>``,
e.g. ``ready``), and how the robot's root meets the world (``<virtual_joint>``: fixed,
planar or floating). Pinocchio reads the SRDF's disabled pairs
(:func:`kcplan.arm.load_arm`) and reference states, not its groups; this module reads the
rest with the standard library's XML parser and resolves each group against the URDF's
joint tree (Pinocchio's model), as MoveIt's ``RobotModel`` builds a ``JointModelGroup``:

- ``<joint name="J"/>``: joint ``J`` (a fixed joint has no variable and adds nothing);
- ``<link name="L"/>``: the joint whose child is ``L`` (nothing when that joint is fixed);
- ``<chain base_link="B" tip_link="T"/>``: the joints on the tree's path between ``B``
  and ``T`` (up from ``T`` to ``B``, or through their nearest common ancestor), not the
  joint above ``B``;
- ``<group name="G"/>``: every joint of group ``G``.

A group's joints are its revolute and prismatic joints in the URDF's depth-first order
(Pinocchio's joint order, MoveIt's variable order). A group that names a joint kcplan
cannot plan (floating, planar) is refused with a line naming it. A continuous joint is
a revolute one whose angle wraps, and the planar virtual joint stands for the moving
base's three joints when the model was read with that base
(:mod:`kcplan.arm.description`).
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from kcplan.arm.model import ArmError, plannable_joint

__all__ = ["Srdf", "VirtualJoint", "read_srdf"]


@dataclass(frozen=True)
class VirtualJoint:
    """An SRDF ``<virtual_joint>``: how the robot's root link ``child_link`` meets
    ``parent_frame`` (``fixed``, ``planar`` or ``floating``)."""

    name: str
    kind: str
    parent_frame: str
    child_link: str


@dataclass(frozen=True)
class Srdf:
    """An SRDF's groups, named states and virtual joints, as written (unresolved).

    Attributes
    ----------
    source : str
        The SRDF's path, for messages.
    groups : dict of str to list of (str, dict)
        Each group's members in file order: ``("joint", {"name": ...})``, ``("link",
        {"name": ...})``, ``("chain", {"base_link": ..., "tip_link": ...})`` or
        ``("group", {"name": ...})``.
    states : dict of (str, str) to dict of str to float
        ``(group, state)`` to the state's joint values (radians or metres).
    virtual_joints : tuple of VirtualJoint
    """

    source: str
    groups: dict[str, list[tuple[str, dict[str, str]]]]
    states: dict[tuple[str, str], dict[str, float]]
    virtual_joints: tuple[VirtualJoint, ...]

    def group_joints(self, name: str, model) -> tuple[str, ...]:
        """The movable joints of group ``name`` in the URDF's order (module docstring).

        Parameters
        ----------
        name : str
        model : pinocchio.Model
            The URDF's whole model (:func:`kcplan.arm.model.urdf_model`, with the moving
            base when the group names the virtual joint).

        Raises
        ------
        ArmError
            ``SRDF: group: ...`` for a group not in the file, a member that names no
            joint or link of the URDF, a subgroup cycle, a joint kcplan cannot plan, or a
            group without a movable joint.
        """
        if name not in self.groups:
            known = ", ".join(sorted(self.groups)) or "none"
            raise ArmError(f"{self.source}: group: expected one of the SRDF's groups "
                           f"({known}), got {name!r}")  # fmt: skip
        ids = sorted(self._joint_ids(name, model, ()))
        if not ids:
            raise ArmError(f"{self.source}: group {name!r}: expected at least one revolute "
                           "or prismatic joint, got none")  # fmt: skip
        return tuple(model.names[i] for i in ids)

    def state(self, name: str, joints: tuple[str, ...], group: str | None = None
              ) -> dict[str, float]:  # fmt: skip
        """Named state ``name`` (joint name to value): of ``group``, or without one, of
        the first group whose state of that name sets every joint of ``joints``.

        Raises
        ------
        ArmError
            For no such state, or one that leaves a joint of ``joints`` out.
        """
        if group is not None:
            found = [v for (g, s), v in self.states.items() if (g, s) == (group, name)]
            whose = f"group {group!r}'s named states"
            known = sorted(s for g, s in self.states if g == group)
        else:
            found = [v for (g, s), v in self.states.items() if s == name and set(joints) <= set(v)]
            whose = "named states that set every joint of the planning group"
            known = sorted({s for (g, s), v in self.states.items() if set(joints) <= set(v)})
        if not found:
            raise ArmError(f"{self.source}: group_state: expected one of the {whose} "
                           f"({', '.join(known) or 'none'}), got {name!r}")  # fmt: skip
        missing = [j for j in joints if j not in found[0]]
        if missing:
            raise ArmError(
                f"{self.source}: group_state {name!r}: expected a value of every "
                f"joint of the planning group, got none of {', '.join(missing)}"
            )
        return dict(found[0])

    def _joint_ids(self, name: str, model, seen: tuple[str, ...]) -> set[int]:
        if name in seen:
            cycle = " -> ".join((*seen, name))
            raise ArmError(f"{self.source}: group {seen[0]!r}: expected subgroups without a "
                           f"cycle, got {cycle}")  # fmt: skip
        if name not in self.groups:
            raise ArmError(f"{self.source}: group {seen[-1]!r}: subgroup {name!r} is not a "
                           "group of the SRDF")  # fmt: skip
        virtual = {v.name for v in self.virtual_joints}
        ids: set[int] = set()
        for kind, attrs in self.groups[name]:
            where = f"{self.source}: group {name!r}: {kind}"
            if kind == "group":
                ids |= self._joint_ids(attrs.get("name", ""), model, (*seen, name))
            elif kind == "joint":
                joint = attrs.get("name", "")
                if joint in virtual:
                    ids |= _base_joints(model, joint, where)
                else:
                    ids |= _movable(model, joint, where)
            elif kind == "link":
                ids |= _parent_joint(model, attrs.get("name", ""), where)
            else:  # chain
                ids |= _chain(model, attrs.get("base_link", ""), attrs.get("tip_link", ""), where)
        return ids


def read_srdf(path: str | os.PathLike) -> Srdf:
    """Read ``path``'s groups, named states and virtual joints.

    Raises
    ------
    ArmError
        ``SRDF: srdf: ...`` for a missing or unreadable file, or a group, state or
        virtual joint without the attributes MoveIt requires.
    """
    source = os.fspath(path)
    if not Path(source).is_file():
        raise ArmError(f"{source}: srdf: expected an SRDF file, found none")
    try:
        root = ET.parse(source).getroot()
    except (ET.ParseError, OSError) as err:
        raise ArmError(f"{source}: srdf: expected readable XML, got: {err}") from None
    groups: dict[str, list[tuple[str, dict[str, str]]]] = {}
    for element in root.findall("group"):  # the robot's own (a subgroup's is inside one)
        name = element.get("name")
        if not name:
            raise ArmError(f"{source}: group: expected a name")
        members = []
        for child in element:
            if child.tag == "chain":
                if not child.get("base_link") or not child.get("tip_link"):
                    raise ArmError(f"{source}: group {name!r}: chain: expected base_link and "
                                   "tip_link")  # fmt: skip
            elif child.tag in ("joint", "link", "group"):
                if not child.get("name"):
                    raise ArmError(f"{source}: group {name!r}: {child.tag}: expected a name")
            else:
                continue
            members.append((child.tag, dict(child.attrib)))
        groups[name] = members
    states: dict[tuple[str, str], dict[str, float]] = {}
    for element in root.findall("group_state"):
        group, name = element.get("group"), element.get("name")
        if not group or not name:
            raise ArmError(f"{source}: group_state: expected a group and a name")
        values = {}
        for joint in element.iter("joint"):
            try:
                values[joint.get("name", "")] = float(joint.get("value", ""))
            except ValueError:
                raise ArmError(
                    f"{source}: group_state {name!r}: joint {joint.get('name')!r}: "
                    f"expected a number, got {joint.get('value')!r}"
                ) from None
        states[group, name] = values
    virtual = []
    for element in root.findall("virtual_joint"):
        attrs = [element.get(k) for k in ("name", "type", "parent_frame", "child_link")]
        if not all(attrs):
            raise ArmError(f"{source}: virtual_joint: expected name, type, parent_frame and "
                           "child_link")  # fmt: skip
        virtual.append(VirtualJoint(*attrs))
    return Srdf(source, groups, states, tuple(virtual))


def _movable(model, joint: str, where: str) -> set[int]:
    """Joint ``joint``'s id when it is revolute or prismatic; nothing for a fixed joint."""
    if model.existJointName(joint):
        return {plannable_joint(model, joint, where)}
    if model.existFrame(joint) and _is_fixed_joint(model, model.getFrameId(joint)):
        return set()
    raise ArmError(f"{where}: {joint!r} is not a joint of the URDF")


def _base_joints(model, joint: str, where: str) -> set[int]:
    """The joints of the moving base named after virtual joint ``joint``
    (:class:`kcplan.arm.description.PlanarBase`: ``JOINT/x``, ``JOINT/y``,
    ``JOINT/theta``), which ``model`` has when it was read with that base."""
    names = [f"{joint}/{axis}" for axis in ("x", "y", "theta")]
    if not all(model.existJointName(name) for name in names):
        raise ArmError(f"{where}: {joint!r} is a virtual joint (a moving base); expected "
                       "robot.base (type: planar, bounds) to plan it")  # fmt: skip
    return {int(model.getJointId(name)) for name in names}


def _link_frame(model, link: str, where: str):
    import pinocchio as pin

    if not model.existFrame(link, pin.FrameType.BODY):
        raise ArmError(f"{where}: {link!r} is not a link of the URDF")
    return model.frames[model.getFrameId(link, pin.FrameType.BODY)]


def _is_fixed_joint(model, frame_id: int) -> bool:
    import pinocchio as pin

    return model.frames[frame_id].type == pin.FrameType.FIXED_JOINT


def _parent_joint(model, link: str, where: str) -> set[int]:
    """The movable joint whose child is ``link`` (none when that joint is fixed, or for
    the root link)."""
    import pinocchio as pin

    frame = _link_frame(model, link, where)
    above = model.frames[frame.parentFrame]
    if above.type == pin.FrameType.JOINT and frame.parentJoint > 0:
        return _movable(model, above.name, where)
    return set()


def _chain(model, base: str, tip: str, where: str) -> set[int]:
    """The movable joints on the tree's path between links ``base`` and ``tip``."""

    def up(link: str) -> list[int]:  # movable joints from the link to the root, in turn
        joint = _link_frame(model, link, where).parentJoint
        out = []
        while joint > 0:
            out.append(joint)
            joint = model.parents[joint]
        return out

    from_tip, from_base = up(tip), up(base)
    shared = set(from_tip) & set(from_base)
    path = {j for j in from_tip if j not in shared} | {j for j in from_base if j not in shared}
    for j in path:
        _movable(model, model.names[j], where)  # refuses a kind kcplan cannot plan
    return path
