"""Import the Highway RoadMap (HRM) benchmark maps into kcplan scenarios.

HRM (Ruan, Poblete, Wu, Ma, Chirikjian, "Efficient Path Planning in Narrow Passages for
Robots With Ellipsoidal Components", IEEE T-RO 2022; github.com/ChirikjianLab/hrm) ships
its maps as CSV in ``resources/2D`` and ``resources/3D`` (format in its
``resources/readme.md``): an arena and obstacles as superellipses ``a, b, e, cx, cy,
theta`` (3D superquadrics ``a, b, c, e1, e2, cx, cy, cz, axis, angle``), robots as
ellipses/ellipsoids relative to a base body, and start/goal rows (superquadric settings
add joint angles of HRM's articulated robots after the 7 pose columns; they are ignored,
the robots are rigid here).

Conversion (a path free in the converted map is free in the original):
- obstacles with ``e = 1`` (ellipses, ellipsoids) are exact FCL primitives; other
  superellipses become the circumscribed polygon of 256 tangent lines, which contains
  the shape (:mod:`kcplan.maps.superquadric`), 3D superquadrics (any exponents
  ``0 < e1, e2 < 2``) the circumscribed polytope of 1500 tangent planes as a ``convex``
  obstacle (an FCL convex solid: a robot cannot hide inside it, as it could in a mesh);
- the arena (the robot must stay inside it): in 2D the region outside the inscribed
  polygon of 512 boundary points is filled with convex wedge obstacles reaching past the
  bounds by more than the robot's size; in 3D the inscribed polytope's surface is a mesh
  obstacle written beside the YAML, and the bounds for the robot's centre are the box
  inscribed in the arena, so a robot that does not touch the surface is inside;
- the robot (``robot_{name}_{n}D.csv``; default ``single_body`` in 2D, ``rabbit`` in 3D)
  keeps every body: row 1 is the base at the robot's origin, further rows are rigid
  bodies relative to it (:mod:`kcplan.geometry.robot`).
The geometric error of each approximation (an upper bound of the distance between the
polygon or polytope and the true shape) is written into the scenario's description.
"""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path

import numpy as np

from kcplan.geometry.robot import MAX_BODIES, Body, Robot
from kcplan.geometry.rotations import exp_rotation
from kcplan.maps import MapImportError
from kcplan.maps.superquadric import bounding_polytopes
from kcplan.world.mesh import write_stl

__all__ = ["HRM_MAPS", "HRM_ROBOTS", "hrm_maps", "hrm_robots", "import_hrm"]

ROUNDING_MARGIN = 1e-6
"""Outer shapes are scaled by ``1 + margin``, inner ones by ``1 - margin`` (about their own
centre) before writing, so rounding to 9 decimals in YAML or to float32 in STL cannot move
a tangent edge or face across the true shape."""
OBSTACLE_NORMALS = 256
OBSTACLE_NORMALS_3D = 1500
ARENA_NORMALS_2D = 512
ARENA_NORMALS_3D = 1500


HRM_MAPS = {
    2: (
        "ellipse_cluttered",
        "ellipse_gym_maze",
        "ellipse_maze",
        "ellipse_sparse",
        "superellipse_NAO_lab",
        "superellipse_cluttered",
        "superellipse_maze1",
        "superellipse_maze2",
        "superellipse_maze3",
        "superellipse_sparse",
    ),
    3: (
        "ellipsoid_cluttered",
        "ellipsoid_maze",
        "ellipsoid_sparse",
        "superquadrics_cluttered",
        "superquadrics_home",
        "superquadrics_maze",
        "superquadrics_narrow",
        "superquadrics_sparse",
        "superquadrics_tunnel",
    ),
}
"""The maps of HRM's resources (commit 435b943), by dimension."""
HRM_ROBOTS = {
    2: ("NAO_silhouette", "S_shape", "rabbit", "single_body"),
    3: ("chair", "rabbit", "rabbit2", "snake", "tree"),
}
"""The robots of HRM's resources, by dimension (snake and tree as rigid bodies)."""
DEFAULT_ROBOT = {2: "single_body", 3: "rabbit"}


def hrm_maps(resources: str | os.PathLike, dimension: int) -> list[str]:
    """Map names present in ``RESOURCES/{2D,3D}`` (``env_{name}_{n}D_arena.csv``)."""
    folder = Path(resources) / f"{dimension}D"
    suffix = f"_{dimension}D_arena.csv"
    return sorted(p.name[4 : -len(suffix)] for p in folder.glob(f"env_*{suffix}"))


def hrm_robots(resources: str | os.PathLike, dimension: int) -> list[str]:
    """Robot names present in ``RESOURCES/{2D,3D}`` (``robot_{name}_{n}D.csv``)."""
    folder = Path(resources) / f"{dimension}D"
    suffix = f"_{dimension}D.csv"
    return sorted(p.name[6 : -len(suffix)] for p in folder.glob(f"robot_*{suffix}"))


def _rows(path: Path, width: int, extra: bool = False) -> np.ndarray:
    """The numeric rows of an HRM CSV file, ``width`` columns each (``extra``: at least
    ``width``, the first ``width`` kept)."""
    if not path.is_file():
        raise MapImportError(f"{path}: cannot read the file: no such file")
    rows = []
    with open(path, newline="") as fh:
        for i, row in enumerate(csv.reader(fh), start=1):
            if not row or all(not c.strip() for c in row):
                continue
            try:
                values = [float(c) for c in row]
            except ValueError:
                raise MapImportError(
                    f"{path}: row {i}: expected {width} numbers, got {row}"
                ) from None
            wrong = len(values) < width if extra else len(values) != width
            if wrong or not all(math.isfinite(v) for v in values):
                what = f"at least {width}" if extra else f"{width}"
                raise MapImportError(f"{path}: row {i}: expected {what} finite numbers, got {row}")
            rows.append(values[:width])
    if not rows:
        raise MapImportError(f"{path}: expected at least one row, got an empty file")
    return np.array(rows)


def _resolve(resources: Path, name: str, dimension: int) -> str:
    names = hrm_maps(resources, dimension)
    if name in names:
        return name
    matches = [m for m in names if m.split("_", 1)[1] == name]
    if len(matches) == 1:
        return matches[0]
    choices = ", ".join(names) or f"none found in {resources / f'{dimension}D'}"
    why = "ambiguous" if matches else "unknown"
    raise MapImportError(
        f"--map: {why} map {name!r} for dimension {dimension}; expected one of {choices}"
    )


def _axis_angle_quaternion(axis: np.ndarray, angle: float) -> list[float]:
    norm = np.linalg.norm(axis)
    if norm == 0.0 or angle == 0.0:
        return [0.0, 0.0, 0.0, 1.0]
    k = axis / norm
    s = math.sin(angle / 2.0)
    return [float(k[0] * s), float(k[1] * s), float(k[2] * s), math.cos(angle / 2.0)]


def _round(values) -> list[float]:
    return [round(float(v), 9) for v in np.ravel(values)]


def import_hrm(
    resources: str | os.PathLike,
    name: str,
    dimension: int,
    output: str | os.PathLike,
    inflation: float = 0.1,
    robot: str | None = None,
) -> dict:
    """Convert one HRM map with one of HRM's robots into a scenario dict (and, in 3D,
    write the arena mesh).

    Parameters
    ----------
    resources : path
        HRM's ``resources`` folder (with ``2D/`` and ``3D/``).
    name : str
        Map name, full (``ellipse_sparse``) or its map type when unique (``sparse``).
    dimension : {2, 3}
    output : path
        Where the scenario YAML will be written; the 3D arena mesh is written beside it
        as ``<stem>.arena.stl`` (atomically) and referenced relatively.
    inflation : float
        The robot's guard inflation recorded in the scenario.
    robot : str, optional
        HRM's robot (:data:`HRM_ROBOTS`); default ``single_body`` (2D), ``rabbit`` (3D).

    Returns
    -------
    dict
        The scenario (see ``scenarios/README.md``); ``error`` notes in ``description``.
    """
    root = Path(resources)
    if dimension not in (2, 3):
        raise MapImportError(f"--dimension: expected 2 or 3, got {dimension}")
    name = _resolve(root, name, dimension)
    folder = root / f"{dimension}D"
    robot = DEFAULT_ROBOT[dimension] if robot is None else robot
    robots = hrm_robots(root, dimension)
    if robot not in robots:
        choices = ", ".join(robots) or f"none found in {folder}"
        raise MapImportError(
            f"--robot: unknown robot {robot!r} for dimension {dimension}; expected one of {choices}"
        )
    if dimension == 2:
        return _import_2d(folder, name, robot, inflation)
    return _import_3d(folder, name, robot, Path(output), inflation)


def _read_map(folder: Path, name: str, robot: str, n: int):
    """Robot spec and description, arena row, obstacle file and rows, start/goal rows."""
    shape, pose = (6, 3) if n == 2 else (12, 7)  # CSV widths (HRM's resources/readme.md)
    obstacles = folder / f"env_{name}_{n}D_obstacle.csv"
    return (
        *_robot(folder / f"robot_{robot}_{n}D.csv", robot, n),
        _rows(folder / f"env_{name}_{n}D_arena.csv", shape)[0],
        obstacles,
        _rows(obstacles, shape),
        _rows(folder / f"setting_{name}_{n}D.csv", pose, extra=True),
    )


def _robot(path: Path, name: str, n: int) -> tuple[dict, str, float]:
    """The scenario's ``robot`` fields (without inflation), a description, and the
    robot's reach (largest distance of a robot point from its origin)."""
    rows = _rows(path, 6 if n == 2 else 12)
    if len(rows) > MAX_BODIES:
        raise MapImportError(f"{path}: expected at most {MAX_BODIES} bodies, got {len(rows)}")
    bodies = []
    for i, row in enumerate(rows, start=1):
        axes = row[:n]
        exponents = row[2:3] if n == 2 else row[3:5]
        if not (axes > 0).all() or not np.all(exponents == 1.0):
            raise MapImportError(
                f"{path}: row {i}: expected an ellipse/ellipsoid (positive semi-axes, "
                f"exponents 1), got {row.tolist()}"
            )
        if n == 2:
            pose = [*row[3:5], row[5]]
        else:
            pose = [*row[5:8], *_axis_angle_quaternion(row[8:11], row[11])]
        bodies.append(Body(np.array(_round(axes)), np.array(_round(pose))))
    robot = Robot(bodies)
    shape = "ellipse" if n == 2 else "ellipsoid"
    sizes = "; ".join(" x ".join(f"{v:g}" for v in b.semi_axes) for b in bodies)
    text = f"Robot: HRM's {name}, {len(bodies)} {shape}{'s' * (len(bodies) > 1)} ({sizes})."
    spec = robot.to_spec()
    return spec, text, robot.reach


def _import_2d(folder: Path, name: str, robot_name: str, inflation: float) -> dict:
    robot, robot_text, reach, arena, obstacles_csv, rows, setting = _read_map(
        folder, name, robot_name, 2
    )
    obstacles, worst = [], 0.0
    for i, (a, b, e, cx, cy, theta) in enumerate(rows, start=1):
        if not 0 < e < 2 or a <= 0 or b <= 0:
            raise MapImportError(f"{obstacles_csv}: row {i}: expected a, b > 0 and 0 < e < 2")
        if e == 1.0:
            obstacles.append(
                {
                    "ellipse": {
                        "center": _round([cx, cy]),
                        "semi_axes": _round([a, b]),
                        "yaw": float(theta),
                    }
                }
            )
            continue
        bp = bounding_polytopes([a, b], e, OBSTACLE_NORMALS)
        worst = max(worst, bp.error)
        world = (1 + ROUNDING_MARGIN) * bp.outer @ exp_rotation([theta], 2).T + [cx, cy]
        obstacles.append({"polygon": {"vertices": [_round(v) for v in world]}})
    walls, arena_error, low, high = _arena_walls_2d(arena, reach)
    description = (
        f"HRM map {name} (2D), imported from github.com/ChirikjianLab/hrm (GPL-3.0 data). "
        f"{robot_text} "
        + (
            f"Superellipse obstacles as circumscribed {OBSTACLE_NORMALS}-gons (within "
            f"{worst:.3g} of the true shape); "
            if worst
            else "Obstacles are ellipses (exact); "
        )
        + f"arena {arena[0]:g} x {arena[1]:g} (e = {arena[2]:g}) kept by wedge walls outside "
        f"its inscribed {ARENA_NORMALS_2D}-gon (within {arena_error:.3g})."
    )
    return {
        "name": f"hrm_{name}_{robot_name}_2d",
        "description": description,
        "dimension": 2,
        "bounds": {"low": _round(low), "high": _round(high)},
        "robot": robot | {"inflation": inflation},
        "start": {"position": _round(setting[0, :2]), "yaw": float(setting[0, 2])},
        "goal": {"position": _round(setting[1, :2]), "yaw": float(setting[1, 2])},
        "obstacles": obstacles + walls,
    }


def _arena_walls_2d(arena: np.ndarray, robot_size: float):
    """Wedges outside the arena's inscribed polygon, reaching past its box by 2 robot sizes."""
    a, b, e, cx, cy, theta = arena
    bp = bounding_polytopes([a, b], e, ARENA_NORMALS_2D)
    ring = (1 - ROUNDING_MARGIN) * bp.inner  # counter-clockwise, centred at the origin
    reach = (max(a, b) + 2.0 * robot_size) / min(np.linalg.norm(ring, axis=1))
    R, c = exp_rotation([theta], 2), np.array([cx, cy])
    walls = []
    for p, q in zip(ring, np.roll(ring, -1, axis=0), strict=True):
        quad = np.array([p, reach * p, reach * q, q]) @ R.T + c
        walls.append({"polygon": {"vertices": [_round(v) for v in quad]}})
    world = ring @ R.T + c
    return walls, bp.error, world.min(axis=0), world.max(axis=0)


def _import_3d(folder: Path, name: str, robot_name: str, output: Path, inflation: float) -> dict:
    robot, robot_text, _, arena, obstacles_csv, rows, setting = _read_map(
        folder, name, robot_name, 3
    )
    obstacles, worst = [], 0.0
    for i, row in enumerate(rows, start=1):
        abc, (e1, e2), centre, axis, angle = row[:3], row[3:5], row[5:8], row[8:11], row[11]
        if not (0 < e1 < 2 and 0 < e2 < 2):
            raise MapImportError(
                f"{obstacles_csv}: row {i}: expected exponents 0 < e1, e2 < 2 (a convex "
                f"superquadric), got {e1:g}, {e2:g}"
            )
        quaternion = _axis_angle_quaternion(axis, angle)
        if e1 == e2 == 1.0:
            obstacles.append(
                {
                    "ellipsoid": {
                        "center": _round(centre),
                        "semi_axes": _round(abc),
                        "quaternion": _round(quaternion),
                    }
                }
            )
            continue
        bp = bounding_polytopes(abc, (e1, e2), OBSTACLE_NORMALS_3D)
        worst = max(worst, bp.error)
        vertices = [_round(v) for v in (1 + ROUNDING_MARGIN) * bp.outer]
        obstacles.append(
            {
                "convex": {
                    "vertices": vertices,
                    "position": _round(centre),
                    "quaternion": _round(quaternion),
                }
            }
        )
    stem = output.name.removesuffix(".yaml").removesuffix(".yml")
    abc, (e1, e2), centre, axis, angle = arena[:3], arena[3:5], arena[5:8], arena[8:11], arena[11]
    if e1 != e2 or not 0 < e1 < 2:
        raise MapImportError(
            f"{folder / f'env_{name}_3D_arena.csv'}: row 1: expected equal "
            f"exponents 0 < e1 = e2 < 2, got {e1:g}, {e2:g}"
        )
    if angle != 0.0:
        raise MapImportError(
            f"{folder / f'env_{name}_3D_arena.csv'}: row 1: expected an "
            f"axis-aligned arena (angle 0), got angle {angle:g}"
        )
    bp = bounding_polytopes(abc, e1, ARENA_NORMALS_3D)
    mesh = f"{stem}.arena.stl"
    write_stl(output.parent / mesh, (1 - ROUNDING_MARGIN) * bp.inner, bp.inner_faces)
    obstacles.append({"mesh": {"file": mesh, "position": _round(centre)}})
    # the largest box of half-sizes s * abc inside |x/a|^p + |y/b|^p + |z/c|^p <= 1
    s = 3.0 ** (-e1 / 2.0) * (1.0 - 1e-9)
    inner_box = s * abc
    # ... and inside the inscribed polytope: shrink until every box corner is inside it
    hull_planes = _face_planes((1 - ROUNDING_MARGIN) * bp.inner, bp.inner_faces)
    corners = np.array(np.meshgrid(*[[-1, 1]] * 3)).reshape(3, -1).T * inner_box
    while np.any(corners @ hull_planes[:, :3].T > hull_planes[:, 3]):
        inner_box *= 0.999
        corners *= 0.999
    quats = [_axis_angle_quaternion(r[3:6], r[6]) for r in setting]
    description = (
        f"HRM map {name} (3D), imported from github.com/ChirikjianLab/hrm (GPL-3.0 data). "
        f"{robot_text} Arena {abc[0]:g} x {abc[1]:g} x "
        f"{abc[2]:g} (e = {e1:g}) as the surface of its inscribed polytope (within "
        f"{bp.error:.3g}), robot centre confined to the box inside it"
        + (
            f"; superquadric obstacles as circumscribed convex polytopes of "
            f"{OBSTACLE_NORMALS_3D} planes (within {worst:.3g})"
            if worst
            else ""
        )
        + "."
    )
    return {
        "name": f"hrm_{name}_{robot_name}_3d",
        "description": description,
        "dimension": 3,
        "bounds": {"low": _round(centre - inner_box), "high": _round(centre + inner_box)},
        "robot": robot | {"inflation": inflation},
        "start": {"position": _round(setting[0, :3]), "quaternion": _round(quats[0])},
        "goal": {"position": _round(setting[1, :3]), "quaternion": _round(quats[1])},
        "obstacles": obstacles,
    }


def _face_planes(points: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """``[n, d]`` per outward-oriented triangle: inside means ``n . x <= d``."""
    A, B, C = points[faces[:, 0]], points[faces[:, 1]], points[faces[:, 2]]
    n = np.cross(B - A, C - A)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return np.column_stack([n, np.einsum("fi,fi->f", n, A)])
