"""The stock peers of arms (issue 25, item 6): ``rrtconnect-pin``, a Python ``isValid`` on
Pinocchio's ``computeCollisions`` over the same ellipsoid cover, and the stock planners
that check an edge every 1/32 rad (``rrtconnect-32``, ``prm-32``)."""

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import assert_planner_refused

from kcplan.arm.world import ArmWorld
from kcplan.cli import main
from kcplan.planning.names import ARM_ONLY, JOINT_STEP
from kcplan.planning.pin_checker import PinChecker
from kcplan.planning.problem import PLANNERS
from kcplan.planning.setups import ArmSetup
from kcplan.scenarios import load_scenario

ROOT = Path(__file__).resolve().parents[1]
ARM = ROOT / "scenarios" / "arm"
CORRIDOR = ROOT / "scenarios" / "2d" / "narrow_corridor.yaml"
CUBE_OBJ = "\n".join(
    [f"v {x} {y} {z}" for x in (-0.1, 0.1) for y in (-0.1, 0.1) for z in (-0.1, 0.1)]
    # corner 4 i + 2 j + k + 1 has signs (i, j, k); outward triangles
    + [f"f {a} {b} {c}" for a, b, c in ((1, 2, 4), (1, 4, 3), (5, 7, 8), (5, 8, 6),
                                        (1, 5, 6), (1, 6, 2), (3, 4, 8), (3, 8, 7),
                                        (1, 3, 7), (1, 7, 5), (2, 6, 8), (2, 8, 4))]
)  # fmt: skip


EVERY_KIND = """{"obstacles": [
  {"convex": {"vertices": [[0.4, 0.2, 0.3], [0.7, 0.2, 0.3], [0.5, 0.6, 0.3], [0.5, 0.4, 0.8]]}},
  {"mesh": {"file": "cube.obj", "position": [-0.4, 0.3, 0.5], "scale": 2.0,
            "quaternion": [0.0, 0.0, 0.38268343, 0.92387953]}},
  {"ellipsoid": {"center": [0.0, -0.5, 0.4], "semi_axes": [0.3, 0.1, 0.2],
                 "quaternion": [0.2, 0.1, 0.0, 0.9746794]}},
  {"sphere": {"center": [0.3, -0.3, 0.9], "radius": 0.15}},
  {"box": {"center": [-0.4, -0.4, 0.3], "size": [0.3, 0.2, 0.5],
           "quaternion": [0.1, 0.3, 0.2, 0.9273618]}},
  {"cylinder": {"center": [0.0, 0.5, 1.0], "radius": 0.1, "height": 0.4,
                "quaternion": [0.5, 0.0, 0.0, 0.8660254]}}]}"""
"""One obstacle of every 3D kind about the Panda (scenario fields, as JSON)."""


@pytest.fixture(scope="module")
def table_pick():
    return load_scenario(ARM / "table_pick_1.yaml")


def _verdicts(checker, states) -> list[bool]:
    return [bool(checker.in_collision(q)) for q in states]


def test_pin_checker_agrees_with_the_arm_world_on_an_mbm_scene(table_pick):
    """240 random Panda states in MBM's table_pick 1: Pinocchio's computeCollisions on the
    cover says exactly what ArmWorld (python-fcl) says, and both verdicts occur."""
    arm = table_pick.arm
    world = ArmWorld(arm, table_pick.obstacles, allowed=table_pick.allowed)
    checker = PinChecker(arm, table_pick.obstacles, table_pick.allowed)
    assert checker.self_pairs == len(world.self_pairs) > 0
    assert checker.obstacle_pairs == len(arm.bodies) * len(table_pick.obstacles) > 0
    states = np.random.default_rng(25).uniform(arm.lower, arm.upper, size=(240, arm.dof))
    ours, reference = _verdicts(checker, states), _verdicts(world, states)
    assert ours == reference
    assert 50 <= sum(ours) <= 190, sum(ours)  # colliding and free states both present
    assert checker.calls == 240
    # the obstacles take part: without them, fewer states collide
    alone = PinChecker(arm, (), table_pick.allowed)
    assert sum(_verdicts(alone, states)) < sum(ours)
    assert not checker.in_collision(table_pick.start) and not checker.in_collision(table_pick.goal)
    with pytest.raises(ValueError, match="7 finite joint values"):
        checker.in_collision([0.0] * 6)


def test_pin_checker_builds_every_obstacle_kind(tmp_path, table_pick):
    """Each 3D obstacle kind alone (self-collision off), 200 random states: the same
    verdicts as python-fcl, and every obstacle is hit."""
    (tmp_path / "cube.obj").write_text(CUBE_OBJ + "\n")
    robot = dict(table_pick.robot_spec)
    robot["urdf"] = str(ARM / robot["urdf"])
    robot["srdf"] = str(ARM / robot["srdf"])
    start = {"joints": table_pick.start.tolist()}
    head = {"name": "every_kind", "robot": robot, "start": start, "goal": start}
    path = tmp_path / "every_kind.yaml"
    path.write_text(json.dumps(head | json.loads(EVERY_KIND)))
    scenario = load_scenario(path)
    arm = scenario.arm
    links = {b.link for b in arm.bodies}
    every_pair = {frozenset(p) for p in itertools.combinations(links, 2)}
    states = np.random.default_rng(6).uniform(arm.lower, arm.upper, size=(200, arm.dof))
    kinds = []
    for ob in scenario.obstacles:
        checker = PinChecker(arm, [ob], every_pair)
        assert checker.self_pairs == 0
        ours = _verdicts(checker, states)
        assert ours == _verdicts(ArmWorld(arm, [ob], allowed=every_pair), states), ob.kind
        assert 1 <= sum(ours) < 200, (ob.kind, sum(ours))
        kinds.append(ob.kind)
    assert kinds == ["convex", "mesh", "ellipsoid", "sphere", "box", "cylinder"]


def test_rrtconnect_pin_plans_table_pick_1(tmp_path, capsys):
    out = tmp_path / "path.json"
    argv = ["plan", str(ARM / "table_pick_1.yaml"), "--planner", "rrtconnect-pin",
            "--seed", "1", "--time", "20", "-o", str(out)]  # fmt: skip
    assert main(argv) == 0
    assert "solved by rrtconnect-pin" in capsys.readouterr().out
    result = json.loads(out.read_text())
    assert result["solved"] and result["planner"] == "rrtconnect-pin"
    assert result["counters"]["checker_calls"] > 0
    assert result["counters"]["collision_queries"] == 0  # python-fcl was not asked
    scenario = load_scenario(ARM / "table_pick_1.yaml")
    states = np.array(result["states"])
    assert np.allclose(states[0], scenario.start) and np.allclose(states[-1], scenario.goal)


@pytest.mark.parametrize("name", sorted(ARM_ONLY))
def test_arm_only_planners_refuse_a_rigid_robot_with_one_line(name, tmp_path, capsys):
    why = f"for arms only: {ARM_ONLY[name]}"
    line = f"{CORRIDOR}: --planner: {name}: {why}; this robot is rigid"
    assert_planner_refused(CORRIDOR, name, line, why, tmp_path, capsys)


@pytest.mark.parametrize("name", ["rrtconnect-32", "prm-32"])
def test_the_32_planners_check_an_edge_every_32nd_of_a_radian(name, table_pick):
    """OMPL's resolution is a fraction of the space's maximum extent (the L2 diagonal of
    the joint box): the -32 planners set it to (1/32) / extent, so that OMPL's discrete
    validator checks an edge of length d at ceil(32 d) states."""
    setup = ArmSetup(table_pick, PLANNERS[name], None)
    space, si = setup.space, setup.si
    extent = space.getMaximumExtent()
    arm = table_pick.arm
    assert math.isclose(extent, float(np.linalg.norm(arm.upper - arm.lower)), rel_tol=1e-12)
    assert extent > 13.0  # the Panda's joint box: OMPL's default step would be 0.134 rad
    assert PLANNERS[name].joint_step == JOINT_STEP == 1 / 32
    assert si.getStateValidityCheckingResolution() == pytest.approx((1 / 32) / extent, 1e-12)
    calls = [0]

    def valid(_state) -> bool:
        calls[0] += 1
        return True

    si.setStateValidityChecker(valid)
    si.setup()
    assert space.getLongestValidSegmentLength() == pytest.approx(1 / 32, 1e-12)
    a, b = si.allocState(), si.allocState()
    q = table_pick.start
    for j in range(arm.dof):
        a[j], b[j] = float(q[j]), float(q[j] + (0.3 if j in (0, 3) else 0.0))
    assert si.checkMotion(a, b)
    assert calls[0] == math.ceil(32 * math.hypot(0.3, 0.3)) == 14
    stock = ArmSetup(table_pick, PLANNERS[name.removesuffix("-32")], None)
    assert stock.si.getStateValidityCheckingResolution() == pytest.approx(0.01)  # OMPL's
