"""Obstacles of every scenario format: :class:`Obstacle` and how a scenario's
``obstacles`` entry is read (:func:`parse_obstacle`), sensed clouds and depth images
included (read, cropped and thinned by :mod:`kcplan.world.pointcloud`; each kept point a
ball of the cloud's planning radius ``point_radius + spacing``) and their self filter
(:func:`self_filtered`). Used by the rigid format (:mod:`kcplan.world.scenario`) and the
arm's (:mod:`kcplan.arm.scenario`) alike.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from kcplan.geometry.polygon import convex_pieces
from kcplan.world.fields import MAX_MAGNITUDE, FieldReader, ScenarioError, _show
from kcplan.world.mesh import convex_hull, read_mesh
from kcplan.world.pointcloud import (
    CLOUD_KINDS,
    CloudInfo,
    PointCloudError,
    crop_box_mask,
    crop_sphere_mask,
    drop_nonfinite,
    read_depth_image,
    read_point_file,
    unproject_depth,
    voxel_filter,
)

__all__ = [
    "CLOUD_FIELDS",
    "DEFAULT_DEPTH_SCALE",
    "MAX_CLOUD_POINTS",
    "MAX_CONVEX_VERTICES",
    "MAX_OBSTACLES",
    "MAX_POLYGON_VERTICES",
    "OBSTACLE_KINDS",
    "Obstacle",
    "parse_obstacle",
    "self_filtered",
]


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


OBSTACLE_KINDS = {
    2: ("box", "ellipse", "circle", "polygon"),
    3: ("box", "ellipsoid", "sphere", "convex", "mesh", "pointcloud", "depth"),
}


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

    @cached_property
    def vertex_box(self) -> NDArray[np.float64]:
        """The box of :attr:`vertices`, ``[low, high]``, shape (2, n), found once (a
        column at a time: numpy's reduction along axis 0 of an ``(N, 3)`` array costs 15x
        as much, 3 ms for 70,000 points)."""
        if self.vertices is None:
            raise ValueError(f"{self.label}: has no vertices")
        columns = self.vertices.T
        return np.array([[c.min() for c in columns], [c.max() for c in columns]])


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
