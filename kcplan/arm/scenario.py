"""Scenario files of arms: a URDF robot, its planning group, start, goal and scene.

The format (``scenarios/README.md``)::

    name: box_1
    robot: {urdf: panda/panda.urdf, srdf: panda/panda.srdf,   # or example: NAME
            joints: [panda_joint1, ..., panda_joint7],        # or group: panda_arm
            base: {type: planar, bounds: [[-2, 2], [-2, 2]]}, # a base that drives
            fixed: {NAME: VALUE},
            package_dirs: [DIR], representation: hulls, bodies_per_link: K,
            max_offset: E, inflation: 0.0}
    start: {joints: [...]}            # the group's values, in ``joints`` order
    goal: {state: ready}              # or a named state of the SRDF (group_state)
    obstacles: [{box: {center, size, quaternion}}, {cylinder: {center, quaternion,
                 radius, height}}, {sphere: ...}, {ellipsoid: ...}, {convex: ...},
                 {mesh: ...}]
    allowed: [[LINK, LINK], ...]      # link pairs allowed to touch (MoveIt's ACM)
    attached: [{link: panda_hand, name: part, box: {center, size, quaternion},
                touch: [panda_leftfinger, panda_rightfinger]}]   # held, in the link's frame

Paths are relative to the scenario file. ``example: NAME`` names an arm of
example-robot-data (:data:`kcplan.arm.examples.EXAMPLE_ARMS`; its URDF, its SRDF where it
has one, and its arm's joints unless ``joints`` is given) instead of ``urdf``.
``package_dirs`` are folders that hold the packages of the URDF's
``package://PACKAGE/...`` mesh URIs, searched before the URDF's folder,
``ROS_PACKAGE_PATH`` and example-robot-data's share folder
(:func:`kcplan.arm.model.package_folders`). ``joints`` is the planning group in state
order; every other joint is fixed, at ``fixed`` or 0 (:func:`kcplan.arm.load_arm`).
``group`` instead names one of the SRDF's planning groups (its joints in the URDF's
order, :mod:`kcplan.arm.srdf`), and a start or goal may be one of the SRDF's named
states (``state: NAME``: the group's ``group_state``, or with ``joints`` a state of any
group that sets every joint of the planning group).
``base: {type: planar, bounds: [[xmin, xmax], [ymin, ymax]], name: N, velocity: [0.5,
1.0]}`` makes the robot
drive (:mod:`kcplan.arm.description`): its joints ``N/x``, ``N/y`` (metres) and
``N/theta`` (radians, an angle that wraps: an edge turns it the shorter way round) stand
before the URDF's root link, named after the SRDF's planar virtual joint (else ``base``);
they belong to the planning group when ``joints`` lists them, when ``group`` includes the
virtual joint, or, for an example robot without either, before its arm's joints;
``velocity`` (m/s along x and y, rad/s of yaw) times a trajectory.
``representation`` is ``hulls`` (each link its own convex hull, the default) or
``ellipsoids`` (covers; the default when ``bodies_per_link`` or ``max_offset`` is given).
``max_offset`` (metres) cuts each link's cover until it sticks out of the link's mesh by
at most that much, with ``bodies_per_link`` as the most bodies per link; ``bodies_per_link``
alone fits exactly that many (the smallest union); neither gives
:data:`kcplan.arm.model.DEFAULT_MAX_OFFSET`. A
cylinder's axis is its local z. ``inflation`` is the KC guards' ``eps`` of the ``kc-*``
planners (each body grown by ``1 + eps`` about its centre,
:mod:`kcplan.certification.arm_certifier`); 0, the default, takes
:data:`kcplan.certification.arm_certifier.DEFAULT_KC_INFLATION`. Every field is validated with
the rigid format's one-line errors (:class:`kcplan.world.fields.ScenarioError`).
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from kcplan.arm.attach import Attached, attach
from kcplan.arm.description import BASE_TYPES, DEFAULT_BASE_VELOCITY, PlanarBase
from kcplan.arm.examples import example_robot
from kcplan.arm.kinematics import body_frames
from kcplan.arm.model import (
    LIMIT_TOLERANCE,
    REPRESENTATIONS,
    ArmError,
    ArmModel,
    load_arm,
    urdf_model,
)
from kcplan.arm.srdf import Srdf, read_srdf
from kcplan.world.fields import FieldReader, ScenarioError, read_padding
from kcplan.world.obstacles import MAX_OBSTACLES, Obstacle, parse_obstacle, self_filtered
from kcplan.world.pointcloud import ellipsoid_self_filter_mask, hull_self_filter_mask

__all__ = ["ArmScenario", "arm_scenario_to_dict", "parse_arm_scenario"]


@dataclass(frozen=True, eq=False)
class ArmScenario:
    """A validated planning problem for an arm (see the module docstring).

    ``start`` and ``goal`` are joint vectors in ``arm.joints`` order; ``bounds`` are the
    joint limits, shape ``(2, dof)``.
    """

    name: str
    arm: ArmModel
    start: NDArray[np.float64]
    goal: NDArray[np.float64]
    obstacles: tuple[Obstacle, ...]
    allowed: frozenset
    robot_spec: dict
    inflation: float = 0.0
    description: str = ""
    source: str = "<string>"
    directory: Path = field(default_factory=Path.cwd)
    padding: float = 0.0
    """The clearance (metres) every certified path keeps from every obstacle and point
    (``robot.padding``; MoveIt's link padding, attached parts included; self pairs are not
    padded)."""
    link_padding: Mapping[str, float] = field(default_factory=dict)
    """The clearance (metres) that a link, or an attached part by its name, keeps instead
    of :attr:`padding` (``robot.link_padding``; MoveIt's per-link padding)."""
    dimension = 3

    @property
    def bounds(self) -> NDArray[np.float64]:
        return np.stack([self.arm.lower, self.arm.upper])

    @property
    def robot(self) -> ArmModel:
        return self.arm


def _cylinder(r: FieldReader, spec: Any, index: int) -> Obstacle:
    where = f"obstacles[{index}].cylinder"
    spec = r.mapping(spec, where, ("center", "radius", "height"), ("quaternion",))
    center = r.vector(spec["center"], f"{where}.center", 3)
    radius = r.number(spec["radius"], f"{where}.radius", positive=True)
    height = r.number(spec["height"], f"{where}.height", positive=True)
    R = r.rotation(spec, where, 3)
    return Obstacle("cylinder", index, spec, center, R, np.array([radius, radius, 0.5 * height]))


def _joints(
    r: FieldReader, value: Any, where: str, arm: ArmModel,
    states: Callable[[str, str], dict[str, float]],
) -> NDArray[np.float64]:  # fmt: skip
    spec = r.mapping(value, where, (), ("joints", "state"))
    if ("joints" in spec) == ("state" in spec):
        r.fail(where, "joints (a list of values) or state (a named state of the SRDF)", None,
               "both" if spec else "neither")  # fmt: skip
    if "state" in spec:
        values = states(r.text(spec["state"], f"{where}.state"), f"{where}.state")
        spec = {"joints": [values[name] for name in arm.joints]}
    q = r.vector(spec["joints"], f"{where}.joints", arm.dof)
    q, clamped, outside = arm.clamp(q)
    if outside:
        r.fail(f"{where}.joints", "joint values within the URDF's limits", q.tolist(),
               "; ".join(outside))  # fmt: skip
    if clamped:  # said once, on stderr: the plan starts or ends on the limit
        line = f"{where}.joints: clamped to the URDF's limits (within {LIMIT_TOLERANCE:g})"
        print(f"kcplan: {r.source}: {line}: {'; '.join(clamped)}", file=sys.stderr, flush=True)
    return q


def parse_arm_scenario(data: Any, source: str, directory: Path) -> ArmScenario:
    """Validate parsed YAML of an arm scenario and load its robot.

    Raises
    ------
    ScenarioError
        One line naming the source, the field and what was expected.
    """
    r = FieldReader(source)
    top = r.mapping(
        data, "top level", ("name", "robot", "start", "goal"),
        ("dimension", "description", "obstacles", "allowed", "attached"),
    )  # fmt: skip
    name = r.text(top["name"], "name")
    description = top.get("description", "")
    if not isinstance(description, str):
        r.fail("description", "a string", description)
    if "dimension" in top and (isinstance(top["dimension"], bool) or top["dimension"] != 3):
        r.fail("dimension", "3 (an arm moves in 3D), or no dimension", top["dimension"])
    spec = r.mapping(
        top["robot"], "robot", (),
        ("urdf", "example", "joints", "group", "srdf", "fixed", "package_dirs",
         "representation", "bodies_per_link", "max_offset", "inflation", "padding",
         "link_padding", "base"),
    )  # fmt: skip
    if ("urdf" in spec) == ("example" in spec):
        r.fail("robot", "a urdf (a file) or an example (a robot of example-robot-data)",
               None, f"{'both' if 'urdf' in spec else 'neither'}")  # fmt: skip
    if "example" in spec:
        try:
            urdf, srdf, default_joints = example_robot(r.text(spec["example"], "robot.example"))
        except ArmError as err:
            raise ScenarioError(f"{source}: {err}") from None
        if "srdf" in spec:
            srdf = directory / r.text(spec["srdf"], "robot.srdf")
    else:
        default_joints = ()
        urdf = directory / r.text(spec["urdf"], "robot.urdf")
        srdf = directory / r.text(spec["srdf"], "robot.srdf") if "srdf" in spec else None
        if "joints" not in spec and "group" not in spec:
            r.fail("robot.joints", "the planning group: a list of joint names (or group: a "
                   "group of the SRDF)", None, "none")  # fmt: skip
    for key, path in (("urdf", urdf), ("srdf", srdf)):
        if path is not None and not path.is_file():
            r.fail(f"robot.{key}", f"an existing {key.upper()} file (relative to the scenario)",
                   None, f"{spec.get(key)!r}, which does not exist at {path}")  # fmt: skip
    semantic = _Semantic(r, urdf, srdf)
    base = _base(r, spec["base"], semantic) if "base" in spec else None
    if default_joints and "group" not in spec and "joints" not in spec:
        spec["joints"] = [*(base.joints if base else ()), *default_joints]  # an example's arm
    if "group" in spec:  # the spec keeps the group (written back as it was read)
        if "joints" in spec:
            r.fail("robot.group", "a group or joints, not both", spec["group"])
        joints = list(semantic.joints(r.text(spec["group"], "robot.group"), base))
    else:
        joints = spec["joints"]
    if not isinstance(joints, list) or not all(isinstance(j, str) for j in joints):
        r.fail("robot.joints", "a list of joint names", joints)
    folders = spec.get("package_dirs", [])
    if not isinstance(folders, list) or not all(isinstance(d, str) for d in folders):
        r.fail("robot.package_dirs", "a list of folders (relative to the scenario)", folders)
    package_dirs = [directory / d for d in folders]
    for d, path in zip(folders, package_dirs, strict=True):
        if not path.is_dir():
            r.fail("robot.package_dirs", "existing folders (relative to the scenario)", None,
                   f"{d!r}, which is not a folder at {path}")  # fmt: skip
    fixed = spec.get("fixed", {}) or {}
    if not isinstance(fixed, dict):
        r.fail("robot.fixed", "a mapping of joint names to values", fixed)
    fixed = {str(k): r.number(v, f"robot.fixed.{k}") for k, v in fixed.items()}
    bodies = spec.get("bodies_per_link")
    if bodies is not None and (
        isinstance(bodies, bool) or not isinstance(bodies, int) or not 1 <= bodies <= 32
    ):
        r.fail("robot.bodies_per_link", "an integer from 1 to 32", bodies)
    max_offset = None
    if "max_offset" in spec:
        max_offset = r.number(spec["max_offset"], "robot.max_offset", positive=True)
    representation = spec.get("representation")
    if representation is not None and representation not in REPRESENTATIONS:
        r.fail("robot.representation", f"one of {', '.join(REPRESENTATIONS)}", representation)
    if representation == "hulls" and (bodies is not None or max_offset is not None):
        r.fail("robot.representation", "ellipsoids with bodies_per_link or max_offset",
               representation)  # fmt: skip
    inflation = r.number(spec.get("inflation", 0.0), "robot.inflation")
    if inflation < 0:
        r.fail("robot.inflation", "a number >= 0", inflation)
    try:
        arm = load_arm(
            urdf, joints, srdf=srdf, fixed=fixed, bodies_per_link=bodies, progress=_fit_notice,
            max_offset=max_offset, representation=representation, package_dirs=package_dirs,
            base=base,
        )  # fmt: skip
    except ArmError as err:
        raise ScenarioError(f"{source}: robot: {err}") from None
    held = _attached(r, top.get("attached") or [], directory)
    if held:
        try:
            arm = attach(arm, held)
        except ArmError as err:
            raise ScenarioError(f"{source}: {err}") from None
    states = partial(semantic.state, spec.get("group"), arm.joints)
    start, goal = (_joints(r, top[key], key, arm, states) for key in ("start", "goal"))
    items = top.get("obstacles") or []
    if not isinstance(items, list):
        r.fail("obstacles", "a list of obstacles", items)
    if len(items) > MAX_OBSTACLES:
        r.fail("obstacles", f"at most {MAX_OBSTACLES} obstacles", None, f"{len(items)}")
    obstacles = []
    for i, item in enumerate(items):
        if isinstance(item, dict) and len(item) == 1 and "cylinder" in item:
            obstacles.append(_cylinder(r, item["cylinder"], i))
        else:
            obstacles.append(parse_obstacle(r, item, i, 3, directory))
    obstacles = [
        self_filtered(r, ob, lambda pts, pad: links_mask(arm, start, pts, pad)) for ob in obstacles
    ]
    allowed = _allowed(r, top.get("allowed") or [])
    return ArmScenario(
        name, arm, start, goal, tuple(obstacles), allowed, dict(spec), inflation,
        description, source, directory, read_padding(r, spec), _link_padding(r, spec, arm),
    )  # fmt: skip


class _Semantic:
    """The scenario's SRDF, read when a group or a named state asks for it."""

    def __init__(self, r: FieldReader, urdf: Path, srdf: Path | None) -> None:
        self._r, self._urdf, self._srdf, self._read = r, urdf, srdf, None

    def planar_joint(self) -> str | None:
        """The name of the SRDF's planar virtual joint, if there is an SRDF with one."""
        if self._srdf is None:
            return None
        planar = [v.name for v in self._srdf_of("robot.srdf").virtual_joints if v.kind == "planar"]
        return planar[0] if planar else None

    def _srdf_of(self, field: str) -> Srdf:
        if self._srdf is None:
            self._r.fail(field, "an SRDF to read it from (robot.srdf)", None, "no SRDF")
        if self._read is None:
            try:
                self._read = read_srdf(self._srdf)
            except ArmError as err:
                raise ScenarioError(f"{self._r.source}: robot: {err}") from None
        return self._read

    def joints(self, group: str, base: PlanarBase | None) -> tuple[str, ...]:
        """The joints of ``group``, read against the URDF with the moving ``base``."""
        srdf = self._srdf_of("robot.group")
        try:
            return srdf.group_joints(group, urdf_model(self._urdf, base))
        except ArmError as err:  # the group, or a URDF Pinocchio cannot read
            raise ScenarioError(f"{self._r.source}: robot: {err}") from None

    def state(self, group: str | None, joints: tuple[str, ...], name: str,
              where: str) -> dict[str, float]:  # fmt: skip
        """Named state ``name``: of ``group``, or else of any group that sets ``joints``."""
        srdf = self._srdf_of(where)
        try:
            return srdf.state(name, joints, group)
        except ArmError as err:
            raise ScenarioError(f"{self._r.source}: {where}: {err}") from None


def _base(r: FieldReader, value: Any, semantic: _Semantic | None) -> PlanarBase:
    """``robot.base``: ``{type: planar, bounds: [[xmin, xmax], [ymin, ymax]], name: N,
    velocity: [m/s, rad/s]}`` (:class:`kcplan.arm.description.PlanarBase`);
    the name defaults to the SRDF's planar virtual joint's (else ``base``), so the base's
    joints are named as MoveIt names its variables (``N/x``, ``N/y``, ``N/theta``)."""
    spec = r.mapping(value, "robot.base", ("type", "bounds"), ("name", "velocity"))
    if spec["type"] not in BASE_TYPES:
        r.fail("robot.base.type", f"one of {', '.join(BASE_TYPES)}", spec["type"])
    bounds = spec["bounds"]
    if not (isinstance(bounds, list) and len(bounds) == 2):
        r.fail("robot.base.bounds", "[[xmin, xmax], [ymin, ymax]] (metres)", bounds)
    pairs = []
    for axis, pair in zip("xy", bounds, strict=True):
        low, high = r.vector(pair, f"robot.base.bounds.{axis}", 2)
        if not low < high:
            r.fail(f"robot.base.bounds.{axis}", "[min, max] with min < max (metres)", pair)
        pairs.append((float(low), float(high)))
    velocity = DEFAULT_BASE_VELOCITY
    if "velocity" in spec:
        velocity = tuple(float(v) for v in r.vector(spec["velocity"], "robot.base.velocity", 2,
                                                    positive=True))  # fmt: skip
    name = spec.get("name")
    if name is None:
        name = (semantic.planar_joint() if semantic is not None else None) or "base"
    return PlanarBase(r.text(name, "robot.base.name"), (pairs[0], pairs[1]), velocity)


def _link_padding(r: FieldReader, spec: dict, arm: ArmModel) -> dict[str, float]:
    """``robot.link_padding``: a mapping of a link's (or an attached part's) name to the
    metres (>= 0) its bodies keep from obstacles instead of ``robot.padding``."""
    value = spec.get("link_padding") or {}
    if not isinstance(value, dict):
        r.fail("robot.link_padding", "a mapping of link names to metres", value)
    links = {b.link for b in arm.bodies}
    out = {}
    for name, metres in value.items():
        where = f"robot.link_padding.{name}"
        if name not in links:
            r.fail(where, f"a link with bodies or an attached part ({', '.join(sorted(links))})",
                   name)  # fmt: skip
        out[name] = r.number(metres, where)
        if out[name] < 0:
            r.fail(where, "a clearance of at least 0", metres)
    return out


def links_mask(arm: ArmModel, state: NDArray, points: NDArray, padding: float) -> NDArray:
    """The points within ``padding`` of the arm's bodies at ``state``: each link's hull (and
    an attached part's), or its covering ellipsoids (the self filter of sensed clouds)."""
    frames = body_frames(arm, state)
    on_robot = np.zeros(len(points), dtype=bool)
    hulls = [
        (b.hull.vertices @ f[:3, :3].T + f[:3, 3], b.hull.triangles)
        for b, f in zip(arm.bodies, frames, strict=True)
        if b.hull is not None
    ]
    if hulls:
        on_robot |= hull_self_filter_mask(points, hulls, padding)
    covered = [k for k, b in enumerate(arm.bodies) if b.hull is None]
    if covered:
        on_robot |= ellipsoid_self_filter_mask(
            points, frames[covered, :3, 3], frames[covered, :3, :3],
            np.stack([arm.bodies[k].semi_axes for k in covered]), padding,
        )  # fmt: skip
    return on_robot


def _attached(r: FieldReader, value: Any, directory: Path) -> list[Attached]:
    """The objects the arm holds: ``[{link, name, box|cylinder|sphere|mesh: {...}, touch}]``,
    each shape's fields those of an obstacle, in the link's frame."""
    if not isinstance(value, list):
        r.fail("attached", "a list of objects held by links", value)
    out = []
    for i, item in enumerate(value):
        where = f"attached[{i}]"
        shapes = ("box", "cylinder", "sphere", "mesh")
        spec = r.mapping(item, where, ("link",), ("name", "touch", *shapes))
        kinds = [k for k in shapes if k in spec]
        if len(kinds) != 1:
            r.fail(where, f"one shape of {', '.join(shapes)}", None, ", ".join(kinds) or "none")
        kind = kinds[0]
        if kind == "cylinder":
            shape = _cylinder(r, spec[kind], i)
        else:
            shape = parse_obstacle(r, {kind: spec[kind]}, i, 3, directory)
        touch = spec.get("touch", [])
        if not isinstance(touch, list) or not all(map(_is_text, touch)):
            r.fail(f"{where}.touch", "a list of link names", touch)
        name = r.text(spec.get("name", f"attached{i}"), f"{where}.name")
        out.append(Attached(name, r.text(spec["link"], f"{where}.link"), shape, tuple(touch)))
    return out


def _allowed(r: FieldReader, value: Any) -> frozenset:
    """Link pairs allowed to touch; names outside the robot are kept (MoveIt's matrix
    lists the scene's objects too)."""
    if not isinstance(value, list):
        r.fail("allowed", "a list of link pairs [LINK, LINK]", value)
    pairs = set()
    for k, pair in enumerate(value):
        if not (isinstance(pair, list) and len(pair) == 2 and all(map(_is_text, pair))):
            r.fail(f"allowed[{k}]", "a pair of link names [LINK, LINK]", pair)
        pairs.add(frozenset(pair))
    return frozenset(pairs)


def _fit_notice(line: str) -> None:
    """A link cover that had to be fitted (not cached, nor bundled with kcplan) takes
    seconds, and one that hit the most bodies sticks out more than asked: say so on
    stderr."""
    if not any(word in line for word in ("cached", "bundled")) or "stopped at" in line:
        print(f"kcplan: covering {line}", file=sys.stderr, flush=True)


def _is_text(value: Any) -> bool:
    return isinstance(value, str)


def arm_scenario_to_dict(scenario: ArmScenario) -> dict:
    """The scenario as plain data in the file format."""
    out: dict = {"name": scenario.name}
    if scenario.description:
        out["description"] = scenario.description
    out["robot"] = scenario.robot_spec
    out["start"] = {"joints": scenario.start.tolist()}
    out["goal"] = {"joints": scenario.goal.tolist()}
    out["obstacles"] = [{o.kind: o.spec} for o in scenario.obstacles]
    if scenario.allowed:
        out["allowed"] = sorted(sorted(pair) for pair in scenario.allowed)
    if scenario.arm.attached:
        out["attached"] = [
            {"link": a.link, "name": a.name, a.shape.kind: a.shape.spec}
            | ({"touch": list(a.touch)} if a.touch else {})
            for a in scenario.arm.attached
        ]
    return out
