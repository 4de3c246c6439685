"""Planning against sensed points (issue 55): paths certified against every point's ball
and re-checked on the robot's own geometry with every point as an FCL ball (independent
of the kernel's tree), the self filter, the padding kept and verified, and the time split
of ``kcplan plan``."""

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from kcplan import plan
from kcplan.cli import main
from kcplan.scenarios import load_scenario
from kcplan.views.arm import obstacle_mesh
from kcplan.world.obstacles import Obstacle
from kcplan.world.pointcloud import sample_surface_points

ROOT = Path(__file__).resolve().parents[1]
POINT_RADIUS = 0.0025


def _cloud(points: np.ndarray, radius: float) -> Obstacle:
    return Obstacle(kind="pointcloud", index=0, spec={}, center=np.zeros(3),
                    rotation=np.eye(3), extents=np.full(3, radius),
                    vertices=np.ascontiguousarray(points, dtype=float))  # fmt: skip


@pytest.fixture(scope="module")
def box_cloud():
    """box_1's seven objects as 400 surface points each (2,800 points)."""
    scenario = load_scenario(ROOT / "scenarios" / "arm" / "box_1.yaml")
    points = np.concatenate([
        sample_surface_points(*obstacle_mesh(ob), 400, seed=i)
        for i, ob in enumerate(scenario.obstacles)
    ])  # fmt: skip
    return dataclasses.replace(scenario, obstacles=(_cloud(points, POINT_RADIUS),))


@pytest.mark.parametrize("planner", ["kc-rrtconnect-lazy", "kc-rrtconnect"])
def test_an_arm_plans_through_points_and_the_path_is_free_of_every_ball(box_cloud, planner):
    result = plan(box_cloud, planner, time_limit=20, seed=2)
    assert result.solved
    check = result.verify()  # the links' own meshes against every point as an FCL ball
    assert not check.collides and check.min_clearance > 0
    assert set(result.timing) == {"build", "plan", "simplify"}  # no file was read


def test_the_padding_is_kept_on_the_meshes(box_cloud):
    result = plan(box_cloud, time_limit=20, seed=3, padding=0.01)
    assert result.solved
    check = result.verify(padding=0.01)
    assert not check.collides and check.min_clearance >= 0.01
    # the same path is too close for a larger padding: the verifier sees it
    assert result.verify(padding=check.min_clearance + 0.005).collides


def test_a_rigid_robot_keeps_its_padding_from_points():
    scenario = load_scenario(ROOT / "scenarios" / "3d" / "box_field_cloud.yaml")
    result = plan(scenario, "kc-rrtconnect", time_limit=20, seed=1, padding=0.5)
    assert result.solved
    check = result.verify()
    assert not check.collides and check.min_clearance >= 0.5


def _rigid_yaml(tmp_path: Path, cloud: dict) -> Path:
    data = {
        "name": "points", "dimension": 3,
        "bounds": {"low": [-5, -5, -5], "high": [5, 5, 5]},
        "robot": {"semi_axes": [0.5, 0.3, 0.2]},
        "start": {"position": [-3, 0, 0], "quaternion": [0, 0, 0, 1]},
        "goal": {"position": [3, 0, 0], "quaternion": [0, 0, 0, 1]},
        "obstacles": [{"pointcloud": cloud}],
    }  # fmt: skip
    path = tmp_path / "points.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_the_self_filter_removes_the_robots_own_points_and_counts_them(tmp_path):
    # a wall at x = 0 and points on the robot's surface at its start (x = -3)
    wall = [[0.0, float(y), float(z)] for y in np.linspace(-1, 1, 9) for z in np.linspace(-1, 1, 9)]
    u = np.random.default_rng(0).normal(size=(50, 3))
    on_robot = (u / np.linalg.norm(u, axis=1)[:, None]) * [0.5, 0.3, 0.2] + [-3.0, 0, 0]
    path = _rigid_yaml(tmp_path, {"points": wall + on_robot.tolist(), "point_radius": 0.01,
                                  "self_filter": 0.02})  # fmt: skip
    scenario = load_scenario(path)
    (ob,) = scenario.obstacles
    assert ob.cloud.self_filtered == 50 and len(ob.vertices) == 81
    # a padding that takes every point is refused on its field
    path = _rigid_yaml(tmp_path, {"points": on_robot.tolist(), "point_radius": 0.01,
                                  "self_filter": 0.02})  # fmt: skip
    assert main(["validate", str(path)]) == 2


def test_plan_prints_the_time_split_and_writes_it(tmp_path, capsys):
    out = tmp_path / "p.json"
    code = main(["plan", str(ROOT / "scenarios" / "arm" / "table_pick_1_depth.yaml"), "--seed",
                 "1", "-o", str(out)])  # fmt: skip
    assert code == 0
    text = capsys.readouterr().out
    assert "(320x240 depth image): " in text and " on the robot dropped, " in text
    split = next(line for line in text.splitlines() if line.startswith("time split"))
    assert [part.split()[0] for part in split.split(": ", 1)[1].split(", ")] == [
        "read", "filter", "build", "plan", "simplify"
    ]  # fmt: skip
    timing = json.loads(out.read_text())["timing"]
    assert set(timing) == {"read", "filter", "build", "plan", "simplify"}
    assert all(v >= 0 for v in timing.values())
    # verified on the meshes against the image's points, then asked for more clearance
    assert main(["verify", str(ROOT / "scenarios" / "arm" / "table_pick_1_depth.yaml"),
                 str(out)]) == 0  # fmt: skip
    assert main(["verify", str(ROOT / "scenarios" / "arm" / "table_pick_1_depth.yaml"),
                 str(out), "--padding", "0.5"]) == 1  # fmt: skip
    assert "CLOSER THAN THE PADDING 0.5" in capsys.readouterr().out


def test_padding_on_a_sampling_planner_is_refused(capsys):
    code = main(["plan", str(ROOT / "scenarios" / "3d" / "box_field_cloud.yaml"), "--planner",
                 "rrtconnect", "--padding", "0.1"])  # fmt: skip
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--padding: kept by the kc-* and ca-* planners only" in err[0]


def test_the_verifiers_point_surface_measures_every_point_from_below():
    """kcplan.arm.verify.point_triangles: one FCL surface of the points, whose distance to
    a shape is each point's to within POINT_TRIANGLE, from below."""
    import fcl

    from kcplan.arm.verify import POINT_TRIANGLE, point_triangles

    rng = np.random.default_rng(5)
    points = rng.uniform(-1, 1, (400, 3))
    surface = fcl.CollisionObject(point_triangles(points))
    box = fcl.Box(0.3, 0.2, 0.1)
    for _ in range(20):
        at = rng.uniform(-1.5, 1.5, 3)
        obj = fcl.CollisionObject(box, fcl.Transform(at))
        d = fcl.distance(obj, surface, fcl.DistanceRequest(), fcl.DistanceResult())
        local = np.abs(points - at) - [0.15, 0.1, 0.05]  # exact point-to-box distances
        exact = np.linalg.norm(np.maximum(local, 0.0), axis=1)
        exact[(local <= 0).all(axis=1)] = 0.0
        assert exact.min() - POINT_TRIANGLE - 1e-9 <= max(d, 0.0) <= exact.min() + 1e-9
