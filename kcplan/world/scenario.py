"""Scenario files of rigid robots: the YAML format and its validating reader. What every
scenario format shares lives below it: the file's YAML and the one-line errors of
:class:`~kcplan.world.fields.FieldReader` in :mod:`kcplan.world.fields`, obstacles in
:mod:`kcplan.world.obstacles` (both re-exported here). An arm's scenario is
:mod:`kcplan.arm.scenario`'s; :mod:`kcplan.scenarios` reads and writes either,
dispatching on the robot's kind in one place. This module knows nothing of arms but how
to recognise one's file (:func:`is_arm_data`).

A scenario is one planning problem: a robot made of one or more ellipses (2D) or
ellipsoids (3D) (:class:`kcplan.geometry.robot.Robot`), a box for the robot's origin, a
start and a goal pose, and obstacles. The format is documented in ``scenarios/README.md``.
Every error names the file, the field and what was expected::

    scenarios/x.yaml: obstacles[3].box.size: expected 2 positive numbers, got [4, -1]

Poses are flat vectors (see :mod:`kcplan.geometry.pose`): ``[x, y, yaw]`` in 2D and
``[x, y, z, qx, qy, qz, qw]`` in 3D. Lengths are in the scenario's own unit; angles in
radians.

Sensed obstacles (3D): a ``pointcloud`` (a PLY, PCD, XYZ or NPY file, or listed points)
and a ``depth`` image seen through a pinhole camera are read, cropped and thinned by
:mod:`kcplan.world.pointcloud`; each kept point is a ball of the cloud's planning radius
(``point_radius + spacing``).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml
from numpy.typing import NDArray

from kcplan.files import write_text_atomic
from kcplan.geometry.pose import quaternion_matrix
from kcplan.geometry.robot import MAX_BODIES, Body, Robot
from kcplan.world.fields import (
    MAX_SCENARIO_BYTES,
    FieldReader,
    ScenarioError,
    read_padding,
    read_scenario_data,
)
from kcplan.world.obstacles import (
    MAX_CLOUD_POINTS,
    MAX_OBSTACLES,
    MAX_POLYGON_VERTICES,
    Obstacle,
    parse_obstacle,
    self_filtered,
)
from kcplan.world.pointcloud import ellipsoid_self_filter_mask

if TYPE_CHECKING:
    from kcplan.cover.solid import Solid

__all__ = [
    "DEFAULT_INFLATION",
    "MAX_CLOUD_POINTS",
    "MAX_SCENARIO_BYTES",
    "MAX_OBSTACLES",
    "MAX_POLYGON_VERTICES",
    "FieldReader",
    "Obstacle",
    "Scenario",
    "ScenarioError",
    "as_rigid_scenario",
    "is_arm_data",
    "parse_obstacle",
    "self_filtered",
    "parse_rigid_scenario",
    "read_padding",
    "read_scenario_data",
    "scenario_to_dict",
    "write_scenario_yaml",
]

DEFAULT_INFLATION = 0.1
"""Guard inflation used when ``robot.inflation`` is absent: guard = 1.1 x robot."""
DEFAULT_COVER_BODIES = 4
"""Bodies of the cover of ``robot.mesh`` when ``robot.bodies`` is absent."""


@dataclass(frozen=True, eq=False)
class Scenario:
    """A validated planning problem (see the module docstring for conventions)."""

    name: str
    dimension: int
    bounds: NDArray[np.float64]  # shape (2, n): low, high for the robot's origin
    robot: Robot
    inflation: float
    start: NDArray[np.float64]
    goal: NDArray[np.float64]
    obstacles: tuple[Obstacle, ...]
    description: str = ""
    source: str = "<string>"
    directory: Path = field(default_factory=Path.cwd)
    part: Solid | None = None
    """The robot's own part (:class:`kcplan.cover.Solid`) when the robot is the cover of
    a mesh (``robot: {mesh: ...}``), else None; ``kcplan verify --mesh`` checks it."""
    padding: float = 0.0
    """The clearance every certified path keeps from every obstacle and point, in the
    scenario's unit (``robot.padding``; MoveIt's link padding)."""

    @property
    def semi_axes(self) -> NDArray[np.float64]:
        """The semi-axes of a one-body robot (:attr:`Robot.semi_axes`; raises
        ``ValueError`` for a robot of several bodies)."""
        return self.robot.semi_axes


def _mesh_robot(r: FieldReader, spec: dict, n: int, directory: Path) -> tuple[Robot, Any]:
    """``robot: {mesh: FILE, bodies: K, scale: S, hull: false}``: the cover of the part
    (:func:`kcplan.cover.cache.cached_cover`) and the part itself."""
    from kcplan.cover.cache import cached_cover
    from kcplan.cover.solid import SolidError

    name = r.text(spec["mesh"], "robot.mesh")
    path = (directory / name).resolve()
    if not path.is_file():
        r.fail("robot.mesh", "an existing mesh or outline file (relative to the scenario)",
               name, f"{name!r}, which does not exist at {path}")  # fmt: skip
    count = spec.get("bodies", DEFAULT_COVER_BODIES)
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_BODIES:
        r.fail("robot.bodies", f"an integer 1 to {MAX_BODIES} (the cover's bodies)", count)
    scale = r.number(spec.get("scale", 1.0), "robot.scale", positive=True)
    hull = spec.get("hull", False)
    if not isinstance(hull, bool):
        r.fail("robot.hull", "true or false", hull)
    try:
        cover, _ = cached_cover(path, count, scale, hull=hull)
    except SolidError as err:
        raise ScenarioError(f"{r.source}: robot.mesh: {err}") from None
    if cover.solid.dimension != n:
        r.fail("robot.mesh", f"a {n}D part", name, f"{name!r}, a {cover.solid.dimension}D part")
    return cover.robot, cover.solid


def _robot(r: FieldReader, value: Any, n: int, directory: Path) -> tuple[Robot, float, Any]:
    """The ``robot`` mapping: the robot (``semi_axes``: one body at the origin,
    ``bodies``, or a ``mesh`` to cover), its guard inflation and the mesh's part (or
    None)."""
    spec = r.mapping(value, "robot", (), ("semi_axes", "bodies", "mesh", "scale", "hull",
                                          "inflation", "padding"))  # fmt: skip
    inflation = r.number(spec.get("inflation", DEFAULT_INFLATION), "robot.inflation", True)
    if "mesh" in spec:
        if "semi_axes" in spec:
            r.fail("robot", "semi_axes or mesh, not both", value)
        robot, part = _mesh_robot(r, spec, n, directory)
        return robot, inflation, part
    for key in ("scale", "hull"):
        if key in spec:
            raise ScenarioError(f"{r.source}: robot.{key}: only allowed with robot.mesh")
    if ("semi_axes" in spec) == ("bodies" in spec):
        r.fail("robot", "exactly one of semi_axes (one body), bodies (a list) and mesh", value)
    if "semi_axes" in spec:
        axes = r.vector(spec["semi_axes"], "robot.semi_axes", n, True)
        return Robot.single(axes), inflation, None
    items = spec["bodies"]
    if not isinstance(items, list) or not items or len(items) > MAX_BODIES:
        r.fail("robot.bodies", f"a list of 1 to {MAX_BODIES} bodies", items)
    angle = "yaw" if n == 2 else "quaternion"
    bodies = []
    for i, item in enumerate(items):
        where = f"robot.bodies[{i}]"
        body = r.mapping(item, where, ("semi_axes",), ("position", angle))
        axes = r.vector(body["semi_axes"], f"{where}.semi_axes", n, positive=True)
        pose = r.pose({"position": [0.0] * n} | body, where, n, ignore=("semi_axes",))
        bodies.append(Body(axes, pose))
    return Robot(bodies), inflation, None


def is_arm_data(data: Any) -> bool:
    """Whether parsed scenario YAML describes an arm (its robot names a ``urdf`` or an
    ``example``): :mod:`kcplan.scenarios` reads it with :mod:`kcplan.arm.scenario`."""
    robot = data.get("robot") if isinstance(data, dict) else None
    return isinstance(robot, dict) and ("urdf" in robot or "example" in robot)


def parse_rigid_scenario(
    data: Any, source: str = "<string>", directory: Path | None = None
) -> Scenario:
    """Validate parsed YAML of a rigid robot's scenario and build a :class:`Scenario` (the
    format only; :func:`kcplan.scenarios.parse_scenario` reads every kind of robot and
    checks that the start and goal are free).

    Parameters
    ----------
    data : object
        What ``yaml.safe_load`` returned.
    source : str
        Name used at the start of error messages (normally the file path).
    directory : Path, optional
        Directory that mesh paths are relative to (default: the working directory).

    Raises
    ------
    ScenarioError
        One-line message naming the source, the field and what was expected.
    """
    r = FieldReader(source)
    directory = Path.cwd() if directory is None else directory
    if is_arm_data(data):
        r.fail("robot", "a rigid robot (an arm's scenario is read by kcplan.scenarios)",
               data["robot"])  # fmt: skip
    top = r.mapping(
        data,
        "top level",
        ("name", "dimension", "bounds", "robot", "start", "goal"),
        ("description", "obstacles"),
    )
    name = r.text(top["name"], "name")
    description = top.get("description", "")
    if not isinstance(description, str):
        r.fail("description", "a string", description)
    n = top["dimension"]
    if isinstance(n, bool) or n not in (2, 3):
        r.fail("dimension", "2 or 3", n)
    b = r.mapping(top["bounds"], "bounds", ("low", "high"))
    low, high = r.vector(b["low"], "bounds.low", n), r.vector(b["high"], "bounds.high", n)
    if not (low < high).all():
        r.fail("bounds", "low < high in every coordinate", top["bounds"])
    robot, inflation, part = _robot(r, top["robot"], n, directory)
    padding = read_padding(r, top["robot"])
    poses = {}
    for key in ("start", "goal"):
        pose = r.pose(top[key], key, n)
        if not ((low <= pose[:n]) & (pose[:n] <= high)).all():
            r.fail(
                f"{key}.position",
                f"a point inside bounds {low.tolist()}..{high.tolist()}",
                pose[:n].tolist(),
            )
        poses[key] = pose
    items = top.get("obstacles", [])
    if items is None:
        items = []
    if not isinstance(items, list):
        r.fail("obstacles", "a list of obstacles", items)
    if len(items) > MAX_OBSTACLES:
        r.fail("obstacles", f"at most {MAX_OBSTACLES} obstacles", None, f"{len(items)}")
    obstacles = tuple(parse_obstacle(r, item, i, n, directory) for i, item in enumerate(items))
    if n == 3:
        obstacles = tuple(
            self_filtered(r, ob, lambda pts, pad: _bodies_mask(robot, poses["start"], pts, pad))
            for ob in obstacles
        )
    scenario = Scenario(
        name,
        n,
        np.stack([low, high]),
        robot,
        inflation,
        poses["start"],
        poses["goal"],
        obstacles,
        description,
        source,
        directory,
        part,
        padding,
    )
    return scenario


def _bodies_mask(robot: Robot, pose: NDArray, points: NDArray, padding: float) -> NDArray:
    """The points within ``padding`` of the robot's ellipsoids at ``pose`` (3D)."""
    placed = robot.body_poses(pose)
    rotations = np.stack([quaternion_matrix(p[3:]) for p in placed])
    axes = np.stack([b.semi_axes for b in robot.bodies])
    return ellipsoid_self_filter_mask(points, placed[:, :3], rotations, axes, padding)


def as_rigid_scenario(value: Scenario | str | os.PathLike) -> Scenario:
    """The rigid robot's scenario a rigid-only entry point (such as
    :class:`kcplan.world.CollisionWorld`) was given: ``value`` itself when it is a
    :class:`Scenario`, the file it names when it is a path (``str`` or ``os.PathLike``).

    Raises
    ------
    TypeError
        For anything else, an arm's scenario or file among them, saying what is expected.
    ScenarioError
        For a path whose file is not a valid scenario.
    """
    if isinstance(value, (str, os.PathLike)):
        data, source, directory = read_scenario_data(value)
        if is_arm_data(data):
            raise TypeError(f"scenario: {source}: expected a rigid robot of ellipsoids, got "
                            "an arm (an arm's scene is a kcplan.arm.ArmWorld)")  # fmt: skip
        value = parse_rigid_scenario(data, source, directory)
    if isinstance(value, Scenario):
        return value
    if hasattr(value, "arm"):
        raise TypeError(
            f"scenario: {value.source}: expected a rigid robot of ellipsoids, got an "
            f"{value.arm.describe()} (an arm's scene is a kcplan.arm.ArmWorld)"
        )
    raise TypeError(
        "scenario: expected a kcplan Scenario or the path of a scenario file (str or "
        f"os.PathLike), got {type(value).__name__}"
    )


def scenario_to_dict(scenario: Scenario) -> dict:
    """The scenario as plain data in the file format (numbers as floats)."""
    n = scenario.dimension

    def pose(p: NDArray) -> dict:
        out = {"position": p[:n].tolist()}
        if n == 2:
            out["yaw"] = float(p[2])
        else:
            out["quaternion"] = p[3:].tolist()
        return out

    out = {"name": scenario.name}
    if scenario.description:
        out["description"] = scenario.description
    out |= {
        "dimension": n,
        "bounds": {"low": scenario.bounds[0].tolist(), "high": scenario.bounds[1].tolist()},
        "robot": scenario.robot.to_spec()
        | {"inflation": scenario.inflation}
        | ({"padding": scenario.padding} if scenario.padding else {}),
        "start": pose(scenario.start),
        "goal": pose(scenario.goal),
        "obstacles": [{o.kind: o.spec} for o in scenario.obstacles],
    }
    return out


def write_scenario_yaml(data: dict, path: str | os.PathLike) -> None:
    """Write a scenario's plain data as YAML, atomically (temporary file, then rename)."""
    write_text_atomic(
        path, yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=100)
    )
