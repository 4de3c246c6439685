"""Arms of example-robot-data by name (kcplan.arm.examples, issue 39): the bundled
scenarios of three arms beyond the Panda and the UR5 plan, and every path is free on the
links' own meshes. Skipped where the optional extra (kcplan[robots]) is not installed."""

from pathlib import Path

import numpy as np
import pytest
from conftest import needs_examples

from kcplan.arm.examples import EXAMPLE_ARMS
from kcplan.arm.verify import verify_arm_path
from kcplan.planning.problem import plan
from kcplan.scenarios import load_scenario, parse_scenario
from kcplan.world import ScenarioError

ARM = Path(__file__).resolve().parents[1] / "scenarios" / "arm"



@needs_examples
@pytest.mark.parametrize("name", ["ur3", "ur10", "xarm7"])
def test_the_bundled_example_arms_plan_on_their_meshes(name):
    scenario = load_scenario(ARM / f"example_{name}.yaml")  # start and goal checked free
    assert scenario.arm.joints == EXAMPLE_ARMS[name][2]
    assert all(b.hull is not None for b in scenario.arm.bodies if b.link != "ee_link")
    result = plan(scenario, "kc-rrtconnect", time_limit=20.0, seed=1, simplify=False)
    assert result.solved
    states = np.array(result.states).reshape(-1, scenario.arm.dof)
    check = verify_arm_path(scenario.arm, scenario.obstacles, states)
    assert not check.collides and check.queries > 0


@needs_examples
def test_two_arms_on_one_torso_plan_at_once():
    """Baxter (issue 57 item 2): a tree of two branches, its 14 joints one group; the pairs
    across the arms are checked, and the certified path of both arms at once is free on
    the links' own meshes (Collada, read as Pinocchio read them)."""
    scenario = load_scenario(ARM / "example_baxter.yaml")  # start and goal checked free
    arm = scenario.arm
    assert arm.joints == EXAMPLE_ARMS["baxter"][2] and arm.dof == 14
    side = {i: b.link.split("_")[0] for i, b in enumerate(arm.bodies)}
    across = [(i, j) for i, j in arm.self_pairs
              if {side[i], side[j]} == {"left", "right"}]  # fmt: skip
    assert len(across) >= 20  # left against right, both ways along the tree
    result = plan(scenario, time_limit=20.0, seed=1)  # the default: the compiled lazy planner
    assert result.solved
    states = np.array(result.states).reshape(-1, arm.dof)
    check = verify_arm_path(arm, scenario.obstacles, states, allowed=scenario.allowed)
    assert not check.collides and check.queries > 0


@needs_examples
def test_an_example_is_a_checked_robot_field(tmp_path):
    base = {"name": "e", "start": {"joints": [0.0] * 6}, "goal": {"joints": [0.0] * 6}}
    for robot, message in (
        ({"example": "nope"},
         r"robot.example: expected one of baxter, panda, pr2, ur10, ur3, ur5, xarm7"),
        ({"example": "ur3", "urdf": "x.urdf"}, r"robot: expected a urdf .* or an example"),
    ):
        with pytest.raises(ScenarioError, match=message):
            parse_scenario({**base, "robot": robot}, "e.yaml", tmp_path, check=False)
    scenario = parse_scenario({**base, "robot": {"example": "ur3"}}, "e.yaml", tmp_path)
    assert scenario.arm.dof == 6 and Path(scenario.arm.urdf).name == "ur3_joint_limited_robot.urdf"
