"""A robot's joint tree as kcplan plans it: the URDF, with a moving base and continuous
joints made into joints whose motion the chain's bounds cover.

Pinocchio reads a URDF's planar or floating root as one joint of several numbers and a
continuous joint as two (``JointModelRUB*``: cos and sin); the speed bounds of
:mod:`kcplan.arm.bounds` are written for joints of one number each. So, before Pinocchio
reads it, the URDF's XML is rewritten (the standard library's parser; the file is never
changed):

- **A planar base** (:class:`PlanarBase`, MoveIt's ``virtual_joint type="planar"``) becomes
  three joints above the URDF's root link, named as MoveIt names the base's variables:
  ``NAME/x`` (prismatic along the world's x), ``NAME/y`` (prismatic along y) and
  ``NAME/theta`` (revolute about z). A point of a link then moves with the base as with
  any joint of the chain: the slides at speed 1, the turn at the point's distance from the
  base's axis (its lever), so the certifiers' bounds cover the base unchanged.
- **A continuous joint** becomes a revolute joint with limits ``[-pi, pi]`` whose angle
  *wraps* (:attr:`Description.wrapping`), as does the base's ``theta``.

*Wrapping angles.* A state holds a wrapping angle in ``[-pi, pi]``; the edge between two
states turns it the shorter way round (OMPL's ``SO2StateSpace``): from ``a`` to
``a + wrap(b - a)``, ``wrap`` taking a difference into ``[-pi, pi)``
(:func:`unwrapped`). The chain's bounds hold for any angle (a revolute joint's speed
bound does not depend on its limits), so the certifiers prove the edge through its
unwrapped end.

This module imports neither OMPL nor FCL.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "DEFAULT_BASE_VELOCITY",
    "Description",
    "PlanarBase",
    "read_description",
    "unwrapped",
    "wrapped",
]

BASE_TYPES = ("planar",)
"""The moving bases kcplan plans (MoveIt's ``virtual_joint`` types); ``floating`` is not
one yet."""


DEFAULT_BASE_VELOCITY = (0.5, 1.0)
"""A base's speed limits when none are given: 0.5 m/s along x and y, 1 rad/s of yaw
(a PR2 drives at up to 1 m/s, a Fetch at 1 m/s, a TIAGo at 1 m/s; half, indoors)."""


@dataclass(frozen=True)
class PlanarBase:
    """A base that drives on the floor: ``x``, ``y`` (metres) within ``bounds`` and a yaw
    ``theta`` (radians, wrapping), MoveIt's planar virtual joint.

    Attributes
    ----------
    name : str
        The virtual joint's name; the base's joints are ``NAME/x``, ``NAME/y`` and
        ``NAME/theta``.
    bounds : tuple of (float, float)
        ``((xmin, xmax), (ymin, ymax))``, metres, in the world's frame.
    velocity : tuple of (float, float)
        The base's speed limits (the URDF gives none for a virtual joint): metres per
        second along each of x and y, radians per second of yaw; written as the base's
        joints' ``<limit velocity>``, which a trajectory's timing reads
        (:func:`kcplan.trajectory.certified.joint_limits`).
    """

    name: str
    bounds: tuple[tuple[float, float], tuple[float, float]]
    velocity: tuple[float, float] = DEFAULT_BASE_VELOCITY

    @property
    def joints(self) -> tuple[str, str, str]:
        """The base's three joints, in state order."""
        return (f"{self.name}/x", f"{self.name}/y", f"{self.name}/theta")


@dataclass(frozen=True)
class Description:
    """The URDF as kcplan reads it (module docstring).

    Attributes
    ----------
    urdf : str
        The file.
    xml : str or None
        The rewritten XML, or None when the file is read as it is (no base, no continuous
        joint).
    wrapping : tuple of str
        The joints whose angle wraps: the base's ``theta`` and the continuous joints.
    base : PlanarBase or None
    """

    urdf: str
    xml: str | None
    wrapping: tuple[str, ...] = ()
    base: PlanarBase | None = field(default=None)

    def model(self):
        """Pinocchio's model of the whole tree (``pinocchio.Model``)."""
        import pinocchio as pin

        if self.xml is None:
            return pin.buildModelFromUrdf(self.urdf)
        return pin.buildModelFromXML(self.xml)

    def geometry(self, model, kind, package_dirs: Sequence[str]):
        """Pinocchio's geometry of ``kind`` (``pinocchio.GeometryType``) on ``model``."""
        import pinocchio as pin

        if self.xml is None:
            return pin.buildGeomFromUrdf(model, self.urdf, kind, package_dirs=list(package_dirs))
        return pin.buildGeomFromUrdfString(model, self.xml, kind, package_dirs=list(package_dirs))


class DescriptionError(ValueError):
    """A URDF that cannot take the base asked for; ``str(err)`` names file and field."""


def read_description(urdf: str | os.PathLike, base: PlanarBase | None = None) -> Description:
    """Read ``urdf`` and rewrite it for kcplan (module docstring).

    Raises
    ------
    DescriptionError
        ``URDF: urdf: ...`` for a file the XML parser cannot read; ``URDF: robot.base:
        ...`` for a base on a URDF whose root already moves (a ``planar`` or ``floating``
        joint) or whose joint names the base's would take.
    OSError
        For a file that cannot be opened.
    """
    source = os.fspath(urdf)
    try:
        root = ET.parse(source).getroot()
    except ET.ParseError as err:
        raise DescriptionError(f"{source}: urdf: expected a readable URDF, got: {err}") from None
    joints = root.findall("joint")
    continuous = [j for j in joints if j.get("type") == "continuous"]
    if base is None and not continuous:
        return Description(source, None)
    wrapping = []
    for joint in continuous:  # a revolute joint of limits [-pi, pi] whose angle wraps
        joint.set("type", "revolute")
        limit = joint.find("limit")
        if limit is None:
            limit = ET.SubElement(joint, "limit", {"effort": "0", "velocity": "0"})
        limit.set("lower", repr(-math.pi))
        limit.set("upper", repr(math.pi))
        wrapping.append(joint.get("name", ""))
    if base is not None:
        moving = [j.get("name") for j in joints if j.get("type") in ("planar", "floating")]
        if moving:
            raise DescriptionError(
                f"{source}: robot.base: expected a URDF whose root does not move already, "
                f"got the {moving[0]!r} joint of type {_type_of(joints, moving[0])}"
            )
        taken = {j.get("name") for j in joints} & set(base.joints)
        if taken:
            raise DescriptionError(
                f"{source}: robot.base: the base's joints take the names {sorted(taken)}, "
                "which the URDF's joints have: name the virtual joint otherwise"
            )
        _prepend_base(root, base, source)
        wrapping.append(base.joints[2])
    return Description(source, ET.tostring(root, encoding="unicode"), tuple(wrapping), base)


def _type_of(joints, name: str) -> str:
    return next(j.get("type") for j in joints if j.get("name") == name)


def _prepend_base(root: ET.Element, base: PlanarBase, source: str) -> None:
    """The base's three joints and two massless links between a new root link (the
    world's frame) and the URDF's root link."""
    children = {child.get("link") for child in root.findall("joint/child")}
    roots = [link.get("name") for link in root.findall("link") if link.get("name") not in children]
    if len(roots) != 1:
        raise DescriptionError(f"{source}: urdf: expected one root link, got {roots}")
    names = [f"{base.name}/world", f"{base.name}/x_link", f"{base.name}/y_link", roots[0]]
    taken = {link.get("name") for link in root.findall("link")} & set(names[:3])
    if taken:
        raise DescriptionError(f"{source}: robot.base: the links {sorted(taken)} are the URDF's")
    for name in names[:3]:
        root.insert(0, ET.Element("link", {"name": name}))
    (xmin, xmax), (ymin, ymax) = base.bounds
    linear, angular = base.velocity
    specs = (
        (base.joints[0], "prismatic", "1 0 0", xmin, xmax, linear),
        (base.joints[1], "prismatic", "0 1 0", ymin, ymax, linear),
        (base.joints[2], "revolute", "0 0 1", -math.pi, math.pi, angular),
    )
    for k, (name, kind, axis, low, high, speed) in enumerate(specs):
        joint = ET.SubElement(root, "joint", {"name": name, "type": kind})
        ET.SubElement(joint, "parent", {"link": names[k]})
        ET.SubElement(joint, "child", {"link": names[k + 1]})
        ET.SubElement(joint, "origin", {"xyz": "0 0 0", "rpy": "0 0 0"})
        ET.SubElement(joint, "axis", {"xyz": axis})
        limit = {"lower": repr(float(low)), "upper": repr(float(high)), "effort": "0",
                 "velocity": repr(float(speed))}  # fmt: skip
        ET.SubElement(joint, "limit", limit)


def wrapped(delta: ArrayLike) -> NDArray[np.float64]:
    """``delta`` taken into ``[-pi, pi)`` (radians): the shorter turn."""
    return (np.asarray(delta, dtype=float) + math.pi) % (2.0 * math.pi) - math.pi


def unwrapped(
    q1: ArrayLike, q2: ArrayLike, wraps: NDArray[np.bool_]
) -> NDArray[np.float64]:
    """The end of the edge ``q1 -> q2`` as the straight segment from ``q1`` reaches it: the
    wrapping joints (``wraps``, shape ``(dof,)``) at ``q1 + wrap(q2 - q1)``, the others at
    ``q2``; shape ``(dof,)``. Every state of the edge is ``q1 + s (out - q1)``."""
    q1, q2 = np.asarray(q1, dtype=float), np.asarray(q2, dtype=float)
    return np.where(wraps, q1 + wrapped(q2 - q1), q2)
