"""Robots of several ellipsoids: the lever bound, body placement, the multi-body world, the
scenario format, and the soundness of every certificate on random multi-body edges."""

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import assert_planner_refused
from hypothesis import given, settings
from hypothesis import strategies as st

from kcplan.certification.certifier import CERTIFICATE_SETS, EdgeCertifier
from kcplan.geometry.pose import Edge, pose_frame
from kcplan.geometry.robot import MAX_BODIES, Body, Robot
from kcplan.geometry.rotations import exp_rotation
from kcplan.planning.names import SINGLE_ELLIPSOID_ONLY
from kcplan.planning.problem import PLANNERS
from kcplan.planning.verify import verify_path
from kcplan.scenarios import dump_scenario, load_scenario, parse_scenario
from kcplan.world import CollisionWorld, ScenarioError
from kcplan.world.clutter import random_pose, random_robot, random_scenario

L_SHAPE = {
    "bodies": [
        {"semi_axes": [5.0, 1.2], "position": [0, 0], "yaw": 0.0},
        {"semi_axes": [3.0, 1.2], "position": [-3.8, 2.6], "yaw": 1.5708},
    ],
    "inflation": 0.1,
}


def scenario_data(robot: dict, n: int = 2, obstacles=()) -> dict:
    return {
        "name": "multi",
        "dimension": n,
        "bounds": {"low": [-50] * n, "high": [50] * n},
        "robot": robot,
        "start": {"position": [0] * n},
        "goal": {"position": [30] + [0] * (n - 1)},
        "obstacles": list(obstacles),
    }


# ------------------------------------------------------------- the lever bound


def support(body_axes, body_pose, R, normal, n):
    """``h(n) = n . R p + |A R_k^T R^T n|`` for a body at the robot pose ``(R, 0)``."""
    Rk, p = pose_frame(body_pose, n)
    return float(normal @ (R @ p) + np.linalg.norm(body_axes * (Rk.T @ R.T @ normal)))


@settings(max_examples=300, deadline=None)
@given(
    n=st.sampled_from([2, 3]),
    seed=st.integers(0, 2**32 - 1),
    angle=st.floats(1e-4, 1.0),
)
def test_support_of_an_offset_body_turns_no_faster_than_its_lever(n, seed, angle):
    """``|h_k(n; R exp(phi w)) - h_k(n; R)| <= (|p_k| + a_max - a_min) phi`` for every
    direction, start orientation, rotation axis and offset (module docstring of
    :mod:`kcplan.certification.certificates.ball`)."""
    rng = np.random.default_rng(seed)
    body = random_robot(rng, n, 1, offset=5.0).bodies[0]
    R = pose_frame(random_pose(rng, n, 0, 1), n)[0]
    if n == 2:
        turn = exp_rotation([angle], 2)
    else:
        axis = rng.normal(size=3)
        turn = exp_rotation(angle * axis / np.linalg.norm(axis), 3)
    normal = rng.normal(size=n)
    normal /= np.linalg.norm(normal)
    before = support(body.semi_axes, body.pose, R, normal, n)
    after = support(body.semi_axes, body.pose, R @ turn, normal, n)
    assert abs(after - before) <= body.lever * angle * (1 + 1e-9) + 1e-12


def test_body_poses_place_every_point_of_every_body():
    """A point ``p_k + R_k A u`` of body ``k`` in the robot frame lands at
    ``t + R (p_k + R_k A u)``: the body pose ``(R R_k, t + R p_k)`` says the same."""
    rng = np.random.default_rng(4)
    for n in (2, 3):
        robot = random_robot(rng, n, 4)
        pose = random_pose(rng, n, -10, 10)
        R, t = pose_frame(pose, n)
        for body, world_pose in zip(robot.bodies, robot.body_poses(pose), strict=True):
            Rk, pk = pose_frame(body.pose, n)
            Rw, tw = pose_frame(world_pose, n)
            u = rng.normal(size=n)
            local = pk + Rk @ (body.semi_axes * u)
            assert np.allclose(t + R @ local, tw + Rw @ (body.semi_axes * u))
        assert robot.reach >= max(np.linalg.norm(b.position) for b in robot.bodies)


def test_core_radius_and_single_body():
    assert Robot.single([5.0, 3.5]).core_radius == 3.5
    assert Robot.single([5.0, 3.5]).is_single
    origin_outside = Robot([Body(np.array([1.0, 0.5]), np.array([3.0, 0.0, 0.0]))])
    assert origin_outside.core_radius == 0.0 and not origin_outside.is_single
    with pytest.raises(ValueError, match="one body centred at the robot's origin"):
        origin_outside.semi_axes  # noqa: B018
    with pytest.raises(ValueError, match="at most 32 bodies"):
        Robot([origin_outside.bodies[0]] * (MAX_BODIES + 1))


# ------------------------------------------------------------- the world


@pytest.mark.parametrize("n", [2, 3])
def test_multibody_world_is_the_union_of_its_bodies(n):
    """Collision and clearance of the robot against one single-body world per body,
    placed at the body's own world pose (an independent placement)."""
    rng = np.random.default_rng(50 + n)
    robot = random_robot(rng, n, 3)
    scenario = random_scenario(rng, n, robot, 8, half_width=20.0)
    world = CollisionWorld(scenario)
    singles = [CollisionWorld(scenario, b.semi_axes) for b in robot.bodies]
    hits = 0
    for _ in range(200):
        pose = random_pose(rng, n, -18, 18)
        body_poses = robot.body_poses(pose)
        expected = [w.in_collision(p) for w, p in zip(singles, body_poses, strict=True)]
        assert world.in_collision(pose) == any(expected)
        hits += any(expected)
        each = world.body_clearances(pose)
        for d, w, p in zip(each, singles, body_poses, strict=True):
            assert d == pytest.approx(w.clearance(p), rel=1e-4, abs=1e-9)  # GJK iterates
        regions = world.free_regions(pose, 3.0)
        assert len(regions) == 3
        if any(expected):
            assert all(r.clearance == 0.0 for r in regions)
        else:
            for region, d in zip(regions, each, strict=True):
                assert region.clearance <= d + 1e-9
    assert 20 < hits < 180
    assert world.counters["distance_queries"] >= 200
    assert sum(world.body_query_counts) == world.counters["body_queries"]


# ------------------------------------------------------------- soundness


# the ball-only ablation (ca) is a study: kc's soundness runs in the ten-minute suite
@pytest.mark.parametrize("certificates", [pytest.param("ca", marks=pytest.mark.study), "kc"])
# the 3D half of the edges in the suite, all of them in the study (the same worlds, more
# edges each)
@pytest.mark.parametrize(
    "n, edges_per_world, least_rejected",
    [pytest.param(2, 50, 100, marks=pytest.mark.study), (3, 30, 30),
     pytest.param(2, 100, 100, marks=pytest.mark.study),
     pytest.param(3, 60, 40, marks=pytest.mark.study)],
)  # fmt: skip
def test_accepted_multibody_edges_are_free(certificates, n, edges_per_world, least_rejected):
    """Thousands of random edges of random robots of 2 to 4 bodies (the origin often
    outside every body, so offset bodies swing on long arcs) near thin rotated walls:
    every accepted edge is free under gap-free verification (clearances and the robot's
    reach only, independent of every certificate) and under dense collision sampling."""
    rng = np.random.default_rng(200 + n)
    accepted = rejected_with_collision = turning = 0
    for _ in range(20):
        robot = random_robot(rng, n, int(rng.integers(2, 5)))
        world = CollisionWorld(random_scenario(rng, n, robot, int(rng.integers(3, 8))))
        certifier = EdgeCertifier(world, certificates=CERTIFICATE_SETS[certificates])
        for _ in range(edges_per_world):
            p1 = random_pose(rng, n, -22, 22)
            if world.in_collision(p1):
                continue
            p2 = p1.copy()
            p2[:n] += rng.normal(0, rng.choice([0.5, 3.0, 10.0]), n)
            p2[n:] = random_pose(rng, n, 0, 1)[n:]
            edge = Edge(p1, p2, n)
            ok = certifier.check(p1, p2)
            dense = world.in_collision_many([edge.pose(s) for s in np.linspace(0, 1, 300)])
            if ok:
                accepted += 1
                turning += edge.rotation_speed > 0.5
                assert not dense.any()
                assert not verify_path(world, [p1, p2]).collides
            elif dense.any():
                rejected_with_collision += 1
    assert accepted > 400 and turning > 300
    assert rejected_with_collision > least_rejected


def test_the_paper_polytope_is_refused_for_several_bodies():
    world = CollisionWorld(parse_scenario(scenario_data(L_SHAPE), check=False))
    with pytest.raises(ValueError, match="'polytope' .* needs one body centred"):
        EdgeCertifier(world, certificates=("polytope",))


def test_every_planner_of_the_paper_polytope_is_listed_as_single_ellipsoid_only():
    polytope = {n for n, spec in PLANNERS.items() if "polytope" in (spec.certificates or ())}
    assert polytope == set(SINGLE_ELLIPSOID_ONLY)


@pytest.mark.parametrize("name", sorted(SINGLE_ELLIPSOID_ONLY))
def test_the_paper_planners_refuse_several_bodies_with_one_line(name, tmp_path, capsys):
    """kc-*-paper on the two-body L robot: one line and exit 2 from `kcplan plan` and
    `kcplan bench` (nothing written), a ValueError from plan(), never a traceback
    (test_cli_fuzz found it)."""
    door = Path(__file__).parent.parent / "scenarios" / "2d" / "l_robot_door.yaml"
    why = SINGLE_ELLIPSOID_ONLY[name]
    line = (
        f"{door}: --planner: {name}: {why}, which needs one ellipsoid centred at the "
        "robot's origin; this robot is not (use the kc-* planners)"
    )
    assert_planner_refused(door, name, line, why, tmp_path, capsys)


def test_region_beats_the_ball_along_a_wall_with_two_bodies():
    """An L-shaped robot sliding along a corridor: the planes of both bodies certify a long
    stretch (up to the horizon, here 40) that the clearance balls cover in steps of
    about twice the clearance (1.8)."""
    walls = [
        {"box": {"center": [0, -4.0], "size": [100, 2]}},
        {"box": {"center": [0, 8.6], "size": [100, 2]}},
    ]
    world = CollisionWorld(parse_scenario(scenario_data(L_SHAPE, obstacles=walls)))
    counts = {}
    for name in ("ca", "kc"):
        certifier = EdgeCertifier(world, certificates=CERTIFICATE_SETS[name], horizon=40.0)
        assert certifier.check(np.array([-30.0, 0.0, 0.0]), np.array([30.0, 0.0, 0.0]))
        counts[name] = certifier.counters["guards"]
    assert counts["kc"] <= 3 and counts["ca"] > 10 * counts["kc"]


# ------------------------------------------------------------- the scenario format


def test_bodies_load_dump_and_reload(tmp_path):
    scenario = parse_scenario(scenario_data(L_SHAPE))
    assert len(scenario.robot) == 2 and not scenario.robot.is_single
    assert scenario.robot.bodies[1].position.tolist() == [-3.8, 2.6]
    with pytest.raises(ValueError, match="2 bodies"):
        scenario.semi_axes  # noqa: B018
    path = tmp_path / "multi.yaml"
    dump_scenario(scenario, path)
    again = load_scenario(path)
    for a, b in zip(scenario.robot.bodies, again.robot.bodies, strict=True):
        assert np.array_equal(a.semi_axes, b.semi_axes) and np.allclose(a.pose, b.pose)
    one = load_scenario_text(tmp_path, {"semi_axes": [2.0, 1.0]})
    assert one.robot.is_single and one.semi_axes.tolist() == [2.0, 1.0]
    three = parse_scenario(
        scenario_data({"bodies": [{"semi_axes": [1, 1, 1], "quaternion": [0, 0, 1, 0]}]}, 3)
    )
    assert np.allclose(three.robot.bodies[0].pose, [0, 0, 0, 0, 0, 1, 0])


def load_scenario_text(tmp_path, robot):
    path = tmp_path / "one.yaml"
    dump_scenario(scenario_data(robot), path)
    return load_scenario(path)


@pytest.mark.parametrize(
    "robot, message",
    [
        ({"bodies": []}, "robot.bodies: expected a list of 1 to 32 bodies, got []"),
        (
            {"bodies": [{"semi_axes": [1, 1]}] * 33},
            "robot.bodies: expected a list of 1 to 32 bodies",
        ),
        (
            {"semi_axes": [1, 1], "bodies": [{"semi_axes": [1, 1]}]},
            "robot: expected exactly one of semi_axes (one body), bodies (a list) and mesh",
        ),
        ({"inflation": 0.1}, "robot: expected exactly one of semi_axes"),
        (
            {"bodies": [{"semi_axes": [1, 1]}, {"semi_axes": [1, 1]}, {"semi_axes": [1, -2]}]},
            "robot.bodies[2].semi_axes: expected 2 positive numbers, got [1, -2]",
        ),
        (
            {"bodies": [{"semi_axes": [1, 1], "position": [0, 0, 0]}]},
            "robot.bodies[0].position: expected 2 finite numbers",
        ),
        (
            {"bodies": [{"semi_axes": [1, 1], "quaternion": [0, 0, 0, 1]}]},
            "robot.bodies[0]: unknown key 'quaternion'; expected one of semi_axes, position, yaw",
        ),
        ({"bodies": [[1, 1]]}, "robot.bodies[0]: expected a mapping with keys semi_axes"),
    ],
)
def test_bad_bodies_get_one_line_naming_the_field(robot, message):
    with pytest.raises(ScenarioError) as err:
        parse_scenario(scenario_data(robot), "f.yaml")
    assert str(err.value).startswith("f.yaml: " + message)
    assert "\n" not in str(err.value)


def test_start_in_collision_names_the_obstacle_for_an_offset_body():
    """Only the offset arm touches the obstacle at the start: the loader still sees it."""
    post = {"circle": {"center": [-3.8, 2.6], "radius": 0.5}}
    with pytest.raises(ScenarioError, match=r"start: the robot collides with obstacles\[0\]"):
        parse_scenario(scenario_data(L_SHAPE, obstacles=[post]), "f.yaml")
    assert not math.isnan(Robot.of([1.0, 2.0]).reach)
