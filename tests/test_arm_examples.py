"""Arms of example-robot-data by name (kcplan.arm.examples, issue 39): the bundled
scenarios of three arms beyond the Panda and the UR5 plan, and every path is free on the
links' own meshes. Skipped where the optional extra (kcplan[robots]) is not installed."""

from pathlib import Path

import numpy as np
import pytest

from kcplan.arm import ArmError
from kcplan.arm.examples import EXAMPLE_ARMS, example_folder
from kcplan.arm.verify import verify_arm_path
from kcplan.planning.problem import plan
from kcplan.scenarios import load_scenario, parse_scenario
from kcplan.world import ScenarioError

ARM = Path(__file__).resolve().parents[1] / "scenarios" / "arm"

try:
    example_folder()
    INSTALLED = True
except ArmError:
    INSTALLED = False
needs_examples = pytest.mark.skipif(not INSTALLED, reason="example-robot-data not installed")


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
def test_an_example_is_a_checked_robot_field(tmp_path):
    base = {"name": "e", "start": {"joints": [0.0] * 6}, "goal": {"joints": [0.0] * 6}}
    for robot, message in (
        ({"example": "nope"}, r"robot.example: expected one of panda, ur10, ur3, ur5, xarm7"),
        ({"example": "ur3", "urdf": "x.urdf"}, r"robot: expected a urdf .* or an example"),
    ):
        with pytest.raises(ScenarioError, match=message):
            parse_scenario({**base, "robot": robot}, "e.yaml", tmp_path, check=False)
    scenario = parse_scenario({**base, "robot": {"example": "ur3"}}, "e.yaml", tmp_path)
    assert scenario.arm.dof == 6 and Path(scenario.arm.urdf).name == "ur3_joint_limited_robot.urdf"
