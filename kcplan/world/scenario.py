"""Scenario files of rigid robots: the YAML format, its validating reader, and the pieces
every scenario format shares (the file's YAML, :class:`FieldReader`'s one-line errors,
obstacles). An arm's scenario is :mod:`kcplan.arm.scenario`'s; :mod:`kcplan.scenarios`
reads and writes either, dispatching on the robot's kind in one place. This module knows
nothing of arms but how to recognise one's file (:func:`is_arm_data`).

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

import math
import os
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml
from numpy.typing import NDArray

from kcplan.files import load_yaml, write_text_atomic
from kcplan.geometry.polygon import convex_pieces
from kcplan.geometry.pose import quaternion_matrix, wrap_angle
from kcplan.geometry.robot import MAX_BODIES, Body, Robot
from kcplan.geometry.rotations import exp_rotation
from kcplan.world.mesh import convex_hull, read_mesh
from kcplan.world.pointcloud import (
    CLOUD_KINDS,
    CloudInfo,
    PointCloudError,
    crop_box_mask,
    crop_sphere_mask,
    drop_nonfinite,
    ellipsoid_self_filter_mask,
    read_depth_image,
    read_point_file,
    unproject_depth,
    voxel_filter,
)

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
MAX_SCENARIO_BYTES = 16 * 2**20
"""Largest scenario file read, in bytes (protects against inputs that exhaust memory)."""
MAX_OBSTACLES = 100_000
"""Largest number of obstacles in one scenario."""
MAX_POLYGON_VERTICES = 500
"""Largest number of vertices of one polygon (decomposition is quadratic)."""
MAX_CONVEX_VERTICES = 20_000
"""Largest number of points of one ``convex`` obstacle."""
MAX_CLOUD_POINTS = 5_000_000
"""Largest number of points one ``pointcloud`` or ``depth`` obstacle keeps (after cropping
and its voxel filter), and of points listed inline."""
DEFAULT_DEPTH_SCALE = 0.001
"""Metres per unit of a 16-bit depth PNG when ``depth.depth_scale`` is absent (mm)."""
MAX_MAGNITUDE = 1e9
"""Largest absolute value of any number in a scenario; FCL crashes on values near 1e300."""
MIN_POSITIVE = 1e-9
"""Smallest size (side, semi-axis, radius, scale, inflation) accepted."""
DEFAULT_COVER_BODIES = 4
"""Bodies of the cover of ``robot.mesh`` when ``robot.bodies`` is absent."""
QUATERNION_TOLERANCE = 1e-2
"""Quaternions with | |q| - 1 | up to this are normalised; larger deviations are errors."""

OBSTACLE_KINDS = {
    2: ("box", "ellipse", "circle", "polygon"),
    3: ("box", "ellipsoid", "sphere", "convex", "mesh", "pointcloud", "depth"),
}


class ScenarioError(ValueError):
    """An invalid scenario; ``str(err)`` is one line ``FILE: FIELD: expected ..., got ...``."""


@dataclass(frozen=True, eq=False)
class Obstacle:
    """One obstacle, in world coordinates.

    Attributes
    ----------
    kind : str
        ``box``, ``ellipse``, ``circle``, ``polygon`` (2D) or ``box``, ``ellipsoid``,
        ``sphere``, ``convex``, ``mesh``, ``pointcloud``, ``depth`` (3D; an arm's scene
        adds ``cylinder``).
    index : int
        Position in the scenario's obstacle list.
    spec : dict
        The validated fields as written in the file (used to write the scenario back).
    center : ndarray, shape (n,)
        Centre (box, ellipse, ellipsoid, circle, sphere), mesh position, or the sensor's
        position (pointcloud, depth: the cloud's frame, a depth camera's optical frame).
    rotation : ndarray, shape (n, n)
        Orientation of the obstacle frame (the sensor's, for clouds) in the world.
    extents : ndarray, shape (n,)
        Half side lengths (box), semi-axes (ellipse, ellipsoid), the radius repeated
        (circle, sphere; pointcloud, depth: the planning radius of every point,
        ``point_radius + spacing``); zeros for polygons and meshes.
    pieces : tuple of ndarray
        Polygon: convex pieces ``(m_i, 2)`` in world coordinates; box (2D): its rectangle;
        convex: its hull's vertices ``(v, 3)``.
    vertices, triangles : ndarray or None
        Mesh and convex: world-frame vertices ``(v, 3)`` and (outward) triangles
        ``(t, 3)``; a convex obstacle keeps only its hull. Pointcloud and depth: the kept
        points in the world frame, ``(N, 3)`` float64, C-contiguous, and no triangles.
    cloud : CloudInfo or None
        Pointcloud and depth: what the points went through (read, dropped, cropped,
        filtered, the radius; :class:`kcplan.world.pointcloud.CloudInfo`); the self
        filter's padding (``self_filter``) is only stored there, for the world builder.
        None for other kinds.
    """

    kind: str
    index: int
    spec: dict
    center: NDArray[np.float64]
    rotation: NDArray[np.float64]
    extents: NDArray[np.float64]
    pieces: tuple = ()
    vertices: NDArray[np.float64] | None = None
    triangles: NDArray[np.int32] | None = None
    cloud: CloudInfo | None = None

    @property
    def label(self) -> str:
        """``obstacles[i] (kind)``, as used in error messages."""
        return f"obstacles[{self.index}] ({self.kind})"


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


def _show(value: Any, limit: int = 60) -> str:
    """A short one-line rendering of a YAML value for error messages."""

    def render(v: Any, depth: int = 0) -> str:
        if depth > 3:
            return "..."
        if isinstance(v, bool) or v is None:
            return str(v).lower() if v is not None else "null"
        if isinstance(v, float):
            return (
                "nan"
                if math.isnan(v)
                else ("inf" if v > 0 else "-inf")
                if math.isinf(v)
                else repr(v)
            )
        if isinstance(v, str):
            return repr(v)
        if isinstance(v, list):
            return (
                "["
                + ", ".join(render(x, depth + 1) for x in v[:8])
                + (", ...]" if len(v) > 8 else "]")
            )
        if isinstance(v, dict):
            items = [
                f"{render(k, depth + 1)}: {render(x, depth + 1)}" for k, x in list(v.items())[:6]
            ]
            return "{" + ", ".join(items) + (", ...}" if len(v) > 6 else "}")
        return repr(v)

    text = " ".join(render(value).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


class FieldReader:
    """Typed access to parsed YAML with errors that name the file and field."""

    def __init__(self, source: str):
        self.source = source

    def fail(self, where: str, expected: str, value: Any = None, got: str | None = None):
        got = got if got is not None else _show(value)
        raise ScenarioError(f"{self.source}: {where}: expected {expected}, got {got}")

    def mapping(self, value: Any, where: str, required: tuple, optional: tuple = ()) -> dict:
        if not isinstance(value, dict):
            self.fail(where, f"a mapping with keys {', '.join(required + optional)}", value)
        for key in value:
            if key not in required + optional:
                allowed = ", ".join(required + optional)
                raise ScenarioError(
                    f"{self.source}: {where}: unknown key {key!r}; expected one of {allowed}"
                )
        for key in required:
            if key not in value:
                raise ScenarioError(f"{self.source}: {where}: missing required key {key!r}")
        return value

    @staticmethod
    def _ok(x: float | None, positive: bool) -> bool:
        if x is None or not math.isfinite(x) or abs(x) > MAX_MAGNITUDE:
            return False
        return x >= MIN_POSITIVE if positive else True

    def number(self, value: Any, where: str, positive: bool = False) -> float:
        what = "a positive number" if positive else "a finite number"
        x = self._float(value)
        if not self._ok(x, positive):
            self.fail(where, what + self._range_note([x], positive), value)
        return x

    @staticmethod
    def _range_note(xs: list, positive: bool) -> str:
        """Mention the magnitude limits only when a finite number broke them."""
        finite = [x for x in xs if x is not None and math.isfinite(x) and (x > 0 or not positive)]
        if any(abs(x) > MAX_MAGNITUDE or (positive and x < MIN_POSITIVE) for x in finite):
            low = f"{MIN_POSITIVE:g} to " if positive else "at most "
            return f" (magnitude {low}{MAX_MAGNITUDE:g})"
        return ""

    @staticmethod
    def _float(value: Any) -> float | None:
        if isinstance(value, bool):
            return None
        if isinstance(value, (int, float)):
            return float(value)
        if isinstance(value, str):  # YAML 1.1 reads "1e3" as a string
            try:
                return float(value)
            except ValueError:
                return None
        return None

    def vector(self, value: Any, where: str, n: int, positive: bool = False) -> NDArray:
        kind = "positive numbers" if positive else "finite numbers"
        if not isinstance(value, list) or len(value) != n:
            self.fail(where, f"{n} {kind}", value)
        xs = [self._float(v) for v in value]
        if not all(self._ok(x, positive) for x in xs):
            self.fail(where, f"{n} {kind}" + self._range_note(xs, positive), value)
        return np.array(xs, dtype=float)

    def points(self, value: Any, where: str, n: int, least: int, most: int) -> NDArray:
        """A list of ``least`` to ``most`` points of ``n`` coordinates, shape ``(k, n)``."""
        if not isinstance(value, list) or not least <= len(value) <= most:
            coordinates = "[x, y]" if n == 2 else "[x, y, z]"
            self.fail(
                where,
                f"a list of {least} to {most} points {coordinates}",
                value,
                f"{len(value)} points" if isinstance(value, list) else None,
            )
        return np.array([self.vector(v, f"{where}[{i}]", n) for i, v in enumerate(value)])

    def text(self, value: Any, where: str) -> str:
        if not isinstance(value, str) or not value.strip():
            self.fail(where, "a non-empty string", value)
        return value

    def quaternion(self, value: Any, where: str) -> NDArray:
        q = self.vector(value, where, 4)
        norm = float(np.linalg.norm(q))
        if abs(norm - 1.0) > QUATERNION_TOLERANCE:
            self.fail(
                where,
                "a unit quaternion [qx, qy, qz, qw]",
                value,
                f"{_show(value)} with norm {norm:.4g}",
            )
        return q / norm

    def rotation(self, spec: dict, where: str, n: int) -> NDArray:
        """Rotation matrix from an optional ``yaw`` (2D) or ``quaternion`` (3D) field."""
        if n == 2:
            return exp_rotation([self.number(spec.get("yaw", 0.0), f"{where}.yaw")], 2)
        q = self.quaternion(spec.get("quaternion", [0.0, 0.0, 0.0, 1.0]), f"{where}.quaternion")
        return quaternion_matrix(q)

    def pose(self, value: Any, where: str, n: int, ignore: tuple = ()) -> NDArray:
        """``{position, yaw | quaternion}`` as a flat pose; ``ignore`` lists other keys the
        caller has read."""
        angle = "yaw" if n == 2 else "quaternion"
        spec = self.mapping(value, where, ("position",), (angle, *ignore))
        position = self.vector(spec["position"], f"{where}.position", n)
        if n == 2:  # OMPL's SO(2) holds [-pi, pi]: a yaw of 7.0 would be an invalid state
            yaw = float(wrap_angle(self.number(spec.get("yaw", 0.0), f"{where}.yaw")))
            return np.append(position, yaw)
        q = self.quaternion(spec.get("quaternion", [0.0, 0.0, 0.0, 1.0]), f"{where}.quaternion")
        return np.concatenate([position, q])


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


def parse_obstacle(r: FieldReader, value: Any, index: int, n: int, directory: Path) -> Obstacle:
    where = f"obstacles[{index}]"
    kinds = OBSTACLE_KINDS[n]
    if not isinstance(value, dict) or len(value) != 1:
        r.fail(where, f"a mapping with one key, the obstacle type ({', '.join(kinds)})", value)
    ((kind, spec),) = value.items()
    if kind not in kinds:
        other = OBSTACLE_KINDS[5 - n]
        hint = f" ({kind!r} is a {5 - n}D obstacle)" if kind in other else ""
        raise ScenarioError(
            f"{r.source}: {where}: unknown obstacle type {kind!r}{hint}; "
            f"expected one of {', '.join(kinds)} in {n}D"
        )
    where = f"{where}.{kind}"
    if kind in CLOUD_KINDS:
        return _cloud_obstacle(r, kind, spec, where, index, directory)
    angle = ("yaw",) if n == 2 else ("quaternion",)
    eye, zeros = np.eye(n), np.zeros(n)
    if kind == "box":
        spec = r.mapping(spec, where, ("center", "size"), angle)
        center = r.vector(spec["center"], f"{where}.center", n)
        half = 0.5 * r.vector(spec["size"], f"{where}.size", n, positive=True)
        R = r.rotation(spec, where, n)
        pieces = ()
        if n == 2:
            corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * half
            pieces = (center + corners @ R.T,)
        return Obstacle(kind, index, spec, center, R, half, pieces)
    if kind in ("ellipse", "ellipsoid"):
        spec = r.mapping(spec, where, ("center", "semi_axes"), angle)
        center = r.vector(spec["center"], f"{where}.center", n)
        axes = r.vector(spec["semi_axes"], f"{where}.semi_axes", n, positive=True)
        return Obstacle(kind, index, spec, center, r.rotation(spec, where, n), axes)
    if kind in ("circle", "sphere"):
        spec = r.mapping(spec, where, ("center", "radius"))
        center = r.vector(spec["center"], f"{where}.center", n)
        radius = r.number(spec["radius"], f"{where}.radius", positive=True)
        return Obstacle(kind, index, spec, center, eye, np.full(n, radius))
    if kind == "polygon":
        spec = r.mapping(spec, where, ("vertices",))
        pts = r.points(spec["vertices"], f"{where}.vertices", 2, 3, MAX_POLYGON_VERTICES)
        try:
            pieces = tuple(convex_pieces(pts))
        except ValueError as err:
            raise ScenarioError(f"{r.source}: {where}.vertices: {err}") from None
        return Obstacle(kind, index, spec, pts.mean(axis=0), eye, zeros, pieces)
    if kind == "convex":
        spec = r.mapping(spec, where, ("vertices",), ("position", "quaternion"))
        local = r.points(spec["vertices"], f"{where}.vertices", 3, 4, MAX_CONVEX_VERTICES)
        position = r.vector(spec.get("position", [0.0, 0.0, 0.0]), f"{where}.position", 3)
        R = r.rotation(spec, where, 3)
        try:
            vertices, triangles = convex_hull(position + local @ R.T)
        except ValueError as err:
            raise ScenarioError(f"{r.source}: {where}.vertices: {err}") from None
        return Obstacle(kind, index, spec, position, R, zeros, (vertices,), vertices, triangles)
    # mesh
    spec = r.mapping(spec, where, ("file",), ("scale", "position", "quaternion"))
    name = r.text(spec["file"], f"{where}.file")
    path = (directory / name).resolve()
    if not path.is_file():
        r.fail(
            f"{where}.file",
            "an existing mesh file (relative to the scenario)",
            name,
            f"{name!r}, which does not exist at {path}",
        )
    scale = r.number(spec.get("scale", 1.0), f"{where}.scale", positive=True)
    position = r.vector(spec.get("position", [0.0, 0.0, 0.0]), f"{where}.position", 3)
    R = r.rotation(spec, where, 3)
    try:
        local, triangles = read_mesh(path)
    except (OSError, ValueError) as err:
        raise ScenarioError(f"{r.source}: {where}.file: {err}") from None
    world = position + (scale * local) @ R.T
    return Obstacle(kind, index, spec, position, R, zeros, (), world, triangles)


CLOUD_FIELDS = ("position", "quaternion", "spacing", "crop", "self_filter")
"""Optional fields of both sensed obstacles (``pointcloud`` and ``depth``)."""


def _existing_file(r: FieldReader, value: Any, where: str, what: str, directory: Path) -> Path:
    """The file a scenario field names, relative to the scenario's directory."""
    name = r.text(value, where)
    path = (directory / name).resolve()
    if not path.is_file():
        r.fail(where, f"an existing {what} (relative to the scenario)", name,
               f"{name!r}, which does not exist at {path}")  # fmt: skip
    return path


def _crop(r: FieldReader, value: Any, where: str) -> tuple:
    """``crop: {min, max}`` (a box) or ``{center, radius}`` (a ball): ``("box", low,
    high)`` or ``("ball", centre, radius)``."""
    spec = r.mapping(value, where, (), ("min", "max", "center", "radius"))
    if set(spec) == {"min", "max"}:
        low = r.vector(spec["min"], f"{where}.min", 3)
        high = r.vector(spec["max"], f"{where}.max", 3)
        if not (low < high).all():
            r.fail(where, "min < max in every coordinate", value)
        return ("box", low, high)
    if set(spec) == {"center", "radius"}:
        centre = r.vector(spec["center"], f"{where}.center", 3)
        return ("ball", centre, r.number(spec["radius"], f"{where}.radius", positive=True))
    r.fail(where, "{min, max} (a box) or {center, radius} (a ball)", value)


def _cloud_obstacle(
    r: FieldReader, kind: str, value: Any, where: str, index: int, directory: Path
) -> Obstacle:
    """A ``pointcloud`` or ``depth`` obstacle: the points read (or unprojected), moved
    into the scenario frame by the sensor's pose, cropped there and thinned by the voxel
    filter; every kept point is a ball of radius ``point_radius + spacing``. A depth
    image's points are in metres: its scenario's unit must be the metre."""
    if kind == "pointcloud":
        spec = r.mapping(value, where, ("point_radius",), ("file", "points", *CLOUD_FIELDS))
        if ("file" in spec) == ("points" in spec):
            r.fail(where, "exactly one of file and points", None,
                   "both" if "file" in spec else "neither")  # fmt: skip
    else:
        spec = r.mapping(value, where, ("image", "intrinsics", "max_range", "point_radius"),
                         ("depth_scale", *CLOUD_FIELDS))  # fmt: skip
    point_radius = r.number(spec["point_radius"], f"{where}.point_radius", positive=True)
    position = r.vector(spec.get("position", [0.0, 0.0, 0.0]), f"{where}.position", 3)
    R = r.rotation(spec, where, 3)
    spacing = 0.0
    if "spacing" in spec:
        spacing = r.number(spec["spacing"], f"{where}.spacing", positive=True)
    crop = _crop(r, spec["crop"], f"{where}.crop") if "crop" in spec else None
    padding = None
    if "self_filter" in spec:
        padding = r.number(spec["self_filter"], f"{where}.self_filter")
        if padding < 0:
            r.fail(f"{where}.self_filter", "a padding of at least 0", spec["self_filter"])
    started = time.perf_counter()
    if kind == "depth":
        field_ = f"{where}.image"
        local, source = _depth_points(r, spec, where, directory)
    elif "file" in spec:
        field_ = f"{where}.file"
        path = _existing_file(r, spec["file"], field_, "point-cloud file", directory)
        try:
            local = read_point_file(path)
        except PointCloudError as err:
            raise ScenarioError(f"{r.source}: {field_}: {err}") from None
        source = spec["file"]
    else:
        field_ = f"{where}.points"
        local = r.points(spec["points"], field_, 3, 1, MAX_CLOUD_POINTS)
        source = "inline"
    read = len(local)
    if read == 0:
        r.fail(field_, "a cloud of at least one point", None, "an empty cloud")
    local, nonfinite = drop_nonfinite(local)
    if len(local) == 0:
        r.fail(field_, "at least one finite point", None,
               f"{read:,} points, all NaN or infinite")  # fmt: skip
    largest = float(np.abs(local).max())
    if largest > MAX_MAGNITUDE:
        r.fail(field_, f"coordinates of magnitude at most {MAX_MAGNITUDE:g}", None, f"{largest:g}")
    points = position + local @ R.T
    read_seconds = time.perf_counter() - started
    started = time.perf_counter()
    cropped = 0
    if crop is not None:
        shape, a, b = crop
        inside = crop_box_mask(points, a, b) if shape == "box" else crop_sphere_mask(points, a, b)
        cropped = int(len(points) - np.count_nonzero(inside))
        if cropped == len(points):
            got = f"{_show(spec['crop'])}, outside which all {len(points):,} points lie"
            r.fail(f"{where}.crop", "a region that keeps at least one point", None, got)
        points = points[inside]
    before = len(points)
    if spacing > 0:
        try:
            points = voxel_filter(points, spacing)
        except ValueError as err:  # a spacing too fine for the cloud's extent
            raise ScenarioError(f"{r.source}: {where}.spacing: {err}") from None
    if len(points) > MAX_CLOUD_POINTS:
        r.fail(field_, f"at most {MAX_CLOUD_POINTS:,} points after cropping and filtering",
               None, f"{len(points):,} (a larger spacing thins the cloud)")  # fmt: skip
    info = CloudInfo(
        source=source,
        points_read=read,
        nonfinite=nonfinite,
        cropped=cropped,
        filtered=before - len(points),
        point_radius=point_radius,
        spacing=spacing,
        radius=point_radius + spacing,
        read_seconds=read_seconds,
        filter_seconds=time.perf_counter() - started,
        self_filter=padding,
    )
    points = np.ascontiguousarray(points, dtype=np.float64)
    extents = np.full(3, info.radius)
    return Obstacle(kind, index, spec, position, R, extents, (), points, None, cloud=info)


def _depth_points(
    r: FieldReader, spec: dict, where: str, directory: Path
) -> tuple[NDArray[np.float64], str]:
    """A ``depth`` obstacle's points in the camera's optical frame and its source name."""
    intrinsics = r.mapping(spec["intrinsics"], f"{where}.intrinsics", ("fx", "fy", "cx", "cy"))
    fx, fy, cx, cy = (
        r.number(intrinsics[k], f"{where}.intrinsics.{k}", positive=k.startswith("f"))
        for k in ("fx", "fy", "cx", "cy")
    )
    max_range = r.number(spec["max_range"], f"{where}.max_range", positive=True)
    path = _existing_file(r, spec["image"], f"{where}.image", "depth image", directory)
    png = path.suffix.lower() == ".png"
    if "depth_scale" in spec and not png:
        raise ScenarioError(f"{r.source}: {where}.depth_scale: only allowed with a 16-bit PNG "
                            "image (a .npy image is in metres)")  # fmt: skip
    scale = r.number(spec.get("depth_scale", DEFAULT_DEPTH_SCALE), f"{where}.depth_scale", True)
    try:
        depth = read_depth_image(path, scale)
    except PointCloudError as err:
        raise ScenarioError(f"{r.source}: {where}.image: {err}") from None
    points = unproject_depth(depth, fx, fy, cx, cy, max_range)
    height, width = depth.shape
    if len(points) == 0:
        r.fail(f"{where}.image", f"a pixel with a depth in (0, max_range {max_range:g}]",
               None, f"none of its {width}x{height} pixels")  # fmt: skip
    return points, f"{spec['image']} ({width}x{height} depth image)"


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


def read_padding(r: FieldReader, robot: Any) -> float:
    """``robot.padding``: a number >= 0 (default 0), the clearance kept from obstacles."""
    value = robot.get("padding", 0.0) if isinstance(robot, dict) else 0.0
    padding = r.number(value, "robot.padding")
    if padding < 0:
        r.fail("robot.padding", "a clearance of at least 0", value)
    return padding


def _bodies_mask(robot: Robot, pose: NDArray, points: NDArray, padding: float) -> NDArray:
    """The points within ``padding`` of the robot's ellipsoids at ``pose`` (3D)."""
    placed = robot.body_poses(pose)
    rotations = np.stack([quaternion_matrix(p[3:]) for p in placed])
    axes = np.stack([b.semi_axes for b in robot.bodies])
    return ellipsoid_self_filter_mask(points, placed[:, :3], rotations, axes, padding)


def self_filtered(r: FieldReader, obstacle: Obstacle, mask_of) -> Obstacle:
    """``obstacle`` without the points that lie on the robot itself, when it is a sensed
    cloud whose scenario asks for a self filter (MoveIt's, for the robot at its start).

    ``mask_of(points, padding)`` tells which points lie within ``padding`` of the robot
    (each robot kind its own: ellipsoids, or an arm's links). The points removed are
    counted in :attr:`CloudInfo.self_filtered`; a filter that would leave no point is an
    error on the obstacle's ``self_filter`` field.
    """
    info = obstacle.cloud
    if info is None or info.self_filter is None:
        return obstacle
    started = time.perf_counter()
    on_robot = mask_of(obstacle.vertices, info.self_filter)
    removed = int(np.count_nonzero(on_robot))
    if removed == len(obstacle.vertices):
        r.fail(f"obstacles[{obstacle.index}].{obstacle.kind}.self_filter",
               "a padding that leaves some point off the robot", None,
               f"{info.self_filter:g}, within which all {removed:,} points lie")  # fmt: skip
    seconds = time.perf_counter() - started
    return replace(
        obstacle,
        vertices=np.ascontiguousarray(obstacle.vertices[~on_robot]),
        cloud=replace(info, self_filtered=removed, filter_seconds=info.filter_seconds + seconds),
    )


def read_scenario_data(path: str | os.PathLike) -> tuple[Any, str, Path]:
    """Read a scenario file's YAML: ``(data, source, directory)``, ``source`` the path as
    given (for messages), ``directory`` the file's folder (mesh paths are relative to it);
    any robot's (:func:`kcplan.scenarios.load_scenario` parses it).

    Parameters
    ----------
    path : path-like
        A YAML file in the format of ``scenarios/README.md``.

    Raises
    ------
    ScenarioError
        For a file that is unreadable, too large, not YAML, or has YAML syntax errors
        (with line and column).
    """
    source = os.fspath(path)
    p = Path(path)
    try:
        size = p.stat().st_size
        if size > MAX_SCENARIO_BYTES:
            raise ScenarioError(
                f"{source}: expected a scenario file of at most {MAX_SCENARIO_BYTES} bytes, "
                f"got {size} bytes"
            )
        raw = p.read_bytes()
    except OSError as err:
        raise ScenarioError(f"{source}: cannot read the file: {err.strerror or err}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ScenarioError(f"{source}: expected a UTF-8 YAML text file, got binary data") from None
    try:
        data = load_yaml(text)
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark or err.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        problem = err.problem or err.context or "invalid YAML"
        raise ScenarioError(f"{source}: {where}YAML syntax error: {problem}") from None
    except (yaml.YAMLError, RecursionError) as err:
        raise ScenarioError(f"{source}: YAML syntax error: {type(err).__name__}") from None
    return data, source, p.resolve().parent


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
