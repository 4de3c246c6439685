"""The bundled scenarios of sensed scenes (issue 55): a point cloud and a depth image.

From scenes already bundled, made the way their sensors would see them:

- ``arm/box_1_cloud.yaml``: the MotionBenchMaker ``box_1`` problem with its seven boxes
  and cylinder replaced by ``--points`` surface samples of each (VAMP's evaluation takes
  10,000 per object), as a binary PLY (``arm/clouds/box_1.ply``), point radius 2.5 mm;
- ``arm/table_pick_1_depth.yaml``: ``table_pick_1`` seen by a 320 x 240 depth camera above
  and in front of the table (16-bit PNG, millimetres, ``arm/clouds/table_pick_1_depth.png``),
  the arm at its start in the picture too, so that the scenario's self filter (10 mm) has
  the arm's own surface to remove, as MoveIt's does;
- ``3d/box_field_cloud.yaml``: the rigid ``box_field`` (an ellipsoid through 40 rotated
  boxes) with its boxes as ``--points / 10`` surface samples each
  (``3d/clouds/box_field.ply``), for KC against points.

The depth image is rendered by splatting dense surface samples of every object (and of the
arm's links' hulls at the start) into the image and keeping the nearest per pixel (a
z-buffer): a pixel no sample reaches is 0, which the reader skips, as a sensor's holes.
Each scenario is written only after ``kcplan.plan`` solved it (seed 1) and its path
passed :func:`kcplan.arm.verify` on the links' meshes against the points (or the rigid
verifier)::

    python scripts/make_cloud_scenarios.py [--points 10000] [-o scenarios]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from kcplan.arm.kinematics import body_frames
from kcplan.planning.problem import plan
from kcplan.scenarios import load_scenario
from kcplan.views.arm import obstacle_mesh
from kcplan.world.pointcloud import sample_surface_points

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
POINT_RADIUS = 0.0025  # metres: VAMP's point radius
CAMERA = {"width": 320, "height": 240, "fx": 280.0, "fy": 280.0, "cx": 159.5, "cy": 119.5}


def surface_cloud(obstacles, per_object: int, seed: int) -> np.ndarray:
    """``per_object`` surface samples of each obstacle, shape (k * per_object, 3)."""
    return np.concatenate([
        sample_surface_points(*obstacle_mesh(ob), per_object, seed=seed + i)
        for i, ob in enumerate(obstacles)
    ])  # fmt: skip


def write_ply(points: np.ndarray, path: Path) -> None:
    """A binary PLY of the points (trimesh's writer)."""
    import trimesh

    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.PointCloud(points).export(path, file_type="ply", encoding="binary")


def look_at(eye, target) -> tuple[np.ndarray, list[float]]:
    """The ROS optical frame at ``eye`` looking at ``target`` (z forward, x right, y down,
    the world's z up): its rotation (columns: the frame's axes) and quaternion
    ``[x, y, z, w]``."""
    from scipy.spatial.transform import Rotation

    z = np.asarray(target, float) - np.asarray(eye, float)
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    R = np.column_stack([x, y, z])
    return R, Rotation.from_matrix(R).as_quat().tolist()


def render_depth(points: np.ndarray, eye, R: np.ndarray) -> np.ndarray:
    """The depth image (metres, 0 where nothing is seen) of surface samples seen from a
    pinhole camera at ``eye`` with optical frame ``R`` (:data:`CAMERA`)."""
    local = (points - eye) @ R
    ahead = local[:, 2] > 1e-3
    local = local[ahead]
    u = np.rint(CAMERA["fx"] * local[:, 0] / local[:, 2] + CAMERA["cx"]).astype(int)
    v = np.rint(CAMERA["fy"] * local[:, 1] / local[:, 2] + CAMERA["cy"]).astype(int)
    seen = (u >= 0) & (u < CAMERA["width"]) & (v >= 0) & (v < CAMERA["height"])
    depth = np.full((CAMERA["height"], CAMERA["width"]), np.inf)
    np.minimum.at(depth, (v[seen], u[seen]), local[seen, 2])
    depth[~np.isfinite(depth)] = 0.0
    return depth


def write_depth_png(depth: np.ndarray, path: Path, scale: float = 0.001) -> None:
    """A 16-bit PNG of ``depth / scale`` (millimetres for 0.001)."""
    from PIL import Image

    path.parent.mkdir(parents=True, exist_ok=True)
    pixels = np.clip(np.rint(depth / scale), 0, 65535).astype(np.uint16)
    Image.fromarray(pixels).save(path)


def arm_surface(scenario, count: int, seed: int) -> np.ndarray:
    """Surface samples of the arm's link hulls at the start, ``count`` per link."""
    frames = body_frames(scenario.arm, scenario.start)
    out = []
    for k, (body, frame) in enumerate(zip(scenario.arm.bodies, frames, strict=True)):
        if body.hull is None:
            continue
        local = sample_surface_points(body.hull.vertices, body.hull.triangles, count, seed=seed + k)
        out.append(local @ frame[:3, :3].T + frame[:3, 3])
    return np.concatenate(out)


def solved_and_clean(path: Path) -> str:
    """Plan the written scenario (seed 1) and verify the path: a one-line verdict."""
    scenario = load_scenario(path)
    result = plan(scenario, seed=1, time_limit=20)
    if not result.solved:
        raise SystemExit(f"make_cloud_scenarios.py: {path.name}: not solved")
    check = result.verify()
    if check.collides:
        raise SystemExit(f"make_cloud_scenarios.py: {path.name}: the path collides: {check}")
    clouds = "; ".join(ob.cloud.summary() for ob in scenario.obstacles if ob.cloud is not None)
    return (f"{path.name}: solved in {result.time * 1e3:.1f} ms, clearance "
            f"{check.min_clearance:.3g} (the scenario's unit) checked without gaps; {clouds}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=10_000, help="surface samples per object")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("-o", "--output", type=Path, default=SCENARIOS, help="scenarios folder")
    args = parser.parse_args(argv)
    out = args.output
    from kcplan.scenarios import dump_scenario
    from kcplan.world.fields import read_scenario_data

    # box_1 as a cloud
    box = load_scenario(SCENARIOS / "arm" / "box_1.yaml")
    write_ply(surface_cloud(box.obstacles, args.points, args.seed), out / "arm/clouds/box_1.ply")
    data, _, _ = read_scenario_data(SCENARIOS / "arm" / "box_1.yaml")
    data = _relocated(data, SCENARIOS / "arm", out / "arm")
    data["name"] = "box_1_cloud"
    data["description"] = (f"MotionBenchMaker's box_1 (Apache-2.0) sensed as {args.points:,} "
                           "surface points per object, VAMP's way; made by "
                           "scripts/make_cloud_scenarios.py")  # fmt: skip
    data["obstacles"] = [{"pointcloud": {"file": "clouds/box_1.ply", "point_radius": POINT_RADIUS}}]
    dump_scenario(data, out / "arm" / "box_1_cloud.yaml")
    print(solved_and_clean(out / "arm" / "box_1_cloud.yaml"), flush=True)

    # table_pick_1 through a depth camera, the arm in the picture
    table = load_scenario(SCENARIOS / "arm" / "table_pick_1.yaml")
    eye = np.array([1.3, -0.9, 0.9])
    R, quaternion = look_at(eye, [0.35, 0.35, 0.0])
    samples = np.concatenate([
        surface_cloud(table.obstacles, 40 * args.points, args.seed),
        arm_surface(table, 4 * args.points, args.seed),
    ])  # fmt: skip
    write_depth_png(render_depth(samples, eye, R), out / "arm/clouds/table_pick_1_depth.png")
    data, _, _ = read_scenario_data(SCENARIOS / "arm" / "table_pick_1.yaml")
    data = _relocated(data, SCENARIOS / "arm", out / "arm")
    data["name"] = "table_pick_1_depth"
    data["description"] = ("MotionBenchMaker's table_pick_1 (Apache-2.0) seen by one depth "
                           "camera (320 x 240, the arm in view and filtered out); made by "
                           "scripts/make_cloud_scenarios.py")  # fmt: skip
    data["obstacles"] = [{"depth": {
        "image": "clouds/table_pick_1_depth.png",
        "intrinsics": {k: CAMERA[k] for k in ("fx", "fy", "cx", "cy")},
        "depth_scale": 0.001, "max_range": 3.0, "point_radius": POINT_RADIUS,
        "position": eye.tolist(), "quaternion": quaternion, "self_filter": 0.01,
    }}]  # fmt: skip
    dump_scenario(data, out / "arm" / "table_pick_1_depth.yaml")
    print(solved_and_clean(out / "arm" / "table_pick_1_depth.yaml"), flush=True)

    # a rigid ellipsoid through a field of sensed boxes
    field = load_scenario(SCENARIOS / "3d" / "box_field.yaml")
    cloud = surface_cloud(field.obstacles, max(args.points // 10, 1), args.seed)
    write_ply(cloud, out / "3d/clouds/box_field.ply")
    data, _, _ = read_scenario_data(SCENARIOS / "3d" / "box_field.yaml")
    data["name"] = "box_field_cloud"
    data["description"] = (f"box_field's 40 boxes as {max(args.points // 10, 1):,} surface "
                           "points each; made by scripts/make_cloud_scenarios.py")  # fmt: skip
    data["obstacles"] = [{"pointcloud": {"file": "clouds/box_field.ply", "point_radius": 0.05}}]
    dump_scenario(data, out / "3d" / "box_field_cloud.yaml")
    print(solved_and_clean(out / "3d" / "box_field_cloud.yaml"), flush=True)
    return 0


def _relocated(data: dict, source: Path, target: Path) -> dict:
    """An arm scenario's robot files made relative to ``target`` instead of ``source``."""
    import os

    robot = dict(data["robot"])
    for key in ("urdf", "srdf"):
        if key in robot:
            robot[key] = os.path.relpath((source / robot[key]).resolve(), target.resolve())
    return {**data, "robot": robot}


if __name__ == "__main__":
    sys.exit(main())
