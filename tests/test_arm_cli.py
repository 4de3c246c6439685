"""Arm scenarios (kcplan.arm.scenario) through the command line: import mbm, plan, verify,
and their one-line errors."""

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from kcplan.cli import main
from kcplan.scenarios import load_scenario
from kcplan.world import ScenarioError

ROOT = Path(__file__).resolve().parents[1]
ARM = ROOT / "scenarios" / "arm"
MBM = ROOT.parent / "shared" / "data" / "external" / "mbm" / "panda" / "problems.tar.bz2"
GROUP = [f"panda_joint{i}" for i in range(1, 8)]
READY = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]


def _robot() -> dict:
    """The bundled Panda, one ellipsoid per link."""
    panda = ARM / "panda"
    return {
        "urdf": str(panda / "panda.urdf"),
        "srdf": str(panda / "panda.srdf"),
        "joints": GROUP,
        "bodies_per_link": 1,
    }


def _scenario(tmp_path, **changes) -> Path:
    """A one-body-per-link Panda scenario (the bundled robot), with ``changes``."""
    data = {
        "name": "reach",
        "robot": _robot(),
        "start": {"joints": READY},
        "goal": {"joints": [1.64, -0.18, -2.46, -0.78, 1.21, 1.28, 1.13]},
        "obstacles": [
            {"box": {"center": [0.55, 0.0, 0.25], "size": [0.3, 0.6, 0.04]}},
            {
                "cylinder": {
                    "center": [0.3, -0.45, 0.6],
                    "radius": 0.05,
                    "height": 0.3,
                    "quaternion": [0.0, 0.0, 0.0, 1.0],
                }
            },
        ],
    }
    for key, value in changes.items():
        if "." in key:
            outer, inner = key.split(".")
            data[outer] = {**data[outer], inner: value}
        else:
            data[key] = value
    path = tmp_path / f"reach{len(list(tmp_path.glob('reach*.yaml')))}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.fixture
def scenario_file(tmp_path):
    return lambda **changes: _scenario(tmp_path, **changes)


def test_an_arm_scenario_is_read(scenario_file):
    scenario = load_scenario(scenario_file())
    assert scenario.arm.joints == tuple(GROUP) and scenario.dimension == 3
    assert scenario.start.tolist() == READY
    kinds = [o.kind for o in scenario.obstacles]
    assert kinds == ["box", "cylinder"]
    assert scenario.obstacles[1].extents.tolist() == pytest.approx([0.05, 0.05, 0.15])
    assert scenario.bounds.shape == (2, 7) and scenario.bounds[1, 5] == pytest.approx(3.8223)


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"robot.joints": GROUP[:6] + ["nope"]}, r"robot: .*joints: 'nope' is not a joint"),
        ({"robot.joints": GROUP + ["panda_joint1"]}, r"robot: .*'panda_joint1' is named twice"),
        ({"robot.joints": []}, r"robot: .*joints: expected at least one joint"),
        ({"robot.urdf": "none.urdf"}, r"robot.urdf: expected an existing URDF file"),
        ({"robot.bodies_per_link": 0}, r"robot.bodies_per_link: expected an integer from 1"),
        ({"start": {"joints": READY[:6]}}, r"start.joints: expected 7 finite numbers"),
        (
            {"goal": {"joints": [0.0, 0.0, 0.0, 0.5, 0.0, 1.0, 0.0]}},
            r"goal.joints: expected joint values within the URDF's limits, got panda_joint4 "
            r"0.5 > 0.0873",
        ),
        (
            {"obstacles": [{"cylinder": {"center": [0, 0, 0], "radius": -1, "height": 1}}]},
            r"obstacles\[0\].cylinder.radius: expected a positive number",
        ),
        ({"allowed": [["panda_hand"]]}, r"allowed\[0\]: expected a pair of link names"),
        ({"dimension": 2}, r"dimension: expected 3 \(an arm moves in 3D\)"),
    ],
)
def test_bad_arm_scenarios_exit_2_with_one_line(scenario_file, capsys, changes, message):
    path = scenario_file(**changes)
    assert main(["plan", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith(str(path)), err
    with pytest.raises(ScenarioError, match=message):
        load_scenario(path)


def test_a_start_that_the_cover_makes_collide_is_refused(scenario_file, capsys):
    bent = [0.0, -0.3, 0.0, -1.6, 0.0, 2.2, 0.785]  # link5's body meets the hand's
    path = scenario_file(start={"joints": bent})
    assert main(["plan", str(path)]) == 2
    err = capsys.readouterr().err
    assert "start: the arm's cover touches an obstacle or itself, its meshes do not" in err
    assert "(robot.representation: hulls (the default) may free it)" in err
    hulls = {key: value for key, value in _robot().items() if key != "bodies_per_link"}
    load_scenario(scenario_file(start={"joints": bent}, robot=hulls))  # its hulls are free
    dipped = [0.0, 0.6, 0.0, -1.6, 0.0, 2.2, 0.785]  # the hand's mesh in the table
    path = scenario_file(start={"joints": dipped}, robot=hulls)
    assert main(["plan", str(path)]) == 2
    err = capsys.readouterr().err
    assert "start: the arm's links touch an obstacle or each other (on their own" in err
    assert err.strip().endswith("collision meshes too): panda_hand and an obstacle"), err
    allowed = scenario_file(
        start={"joints": bent},
        allowed=[["panda_link5", "panda_hand"], ["panda_link5", "panda_link7"]],
    )
    load_scenario(allowed)  # the scene allows those links to touch: no error


def test_plan_then_verify_an_arm_path(scenario_file, tmp_path, capsys):
    path, out = scenario_file(), tmp_path / "path.json"
    argv = ["plan", str(path), "--seed", "2", "--time", "10", "--no-simplify", "-o", str(out)]
    code = main(argv)
    assert code == 0, capsys.readouterr()
    assert "reach: solved by kc-rrtconnect" in capsys.readouterr().out
    data = json.loads(out.read_text())
    assert data["joints"] == GROUP and data["backend"] == "kernel"
    states = np.array(data["states"])
    assert states.shape[1] == 7 and np.allclose(states[0], READY)
    assert main(["verify", str(path), str(out)]) == 0
    assert "clean: the links' meshes" in capsys.readouterr().out
    # the same file with another group order is refused; a state outside the limits too
    data["joints"] = GROUP[::-1]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    assert main(["verify", str(path), str(bad)]) == 2
    assert "joints: expected the scenario's planning group" in capsys.readouterr().err
    data["joints"], data["states"][1][3] = GROUP, 0.5
    bad.write_text(json.dumps(data))
    assert main(["verify", str(path), str(bad)]) == 2
    assert "states[1]: expected joint values within the limits" in capsys.readouterr().err
    assert main(["plan", str(path), "--plot", str(tmp_path / "v.png"), "--guards"]) == 2
    assert "--guards: not available for arms" in capsys.readouterr().err


def test_verify_finds_a_path_through_the_board(scenario_file, tmp_path, capsys):
    """A straight joint-space edge whose meshes meet the scene midway: exit 1."""
    path = scenario_file(obstacles=[])
    q1 = [-1.04, 1.68, 0.97, -0.74, 1.68, 3.64, 0.98]
    q2 = [-0.76, 1.3, 1.64, -0.31, 2.39, 3.82, 0.55]
    out = tmp_path / "p.json"
    out.write_text(json.dumps({"joints": GROUP, "states": [q1, q2]}))
    assert main(["verify", str(path), str(out)]) == 0  # no obstacles: clean
    capsys.readouterr()
    path = scenario_file(
        obstacles=[
            {"box": {"center": [0.0, 0.0, -0.16], "size": [2, 2, 0.02]}},
            {"box": {"center": [0.55, 0.0, 0.25], "size": [0.3, 0.6, 0.04]}},
            {"sphere": {"center": [0.3, -0.45, 0.6], "radius": 0.08}},
        ]
    )
    assert main(["verify", str(path), str(out)]) == 1
    assert "COLLISION of the links' meshes on edge 0" in capsys.readouterr().out


def test_import_mbm_writes_the_bundled_problem(tmp_path, capsys):
    out = tmp_path / "box_1.yaml"
    argv = [
        "import",
        "mbm",
        "--archive",
        str(MBM),
        "--problem",
        "box",
        "--index",
        "1",
        "--urdf",
        str(ARM / "panda" / "panda.urdf"),
        "--srdf",
        str(ARM / "panda" / "panda.srdf"),
        "-o",
        str(out),
    ]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "box_1, arm of 7 joints (11 bodies), 7 obstacles, 34 allowed" in printed
    mine = yaml.safe_load(out.read_text())
    bundled = yaml.safe_load((ARM / "box_1.yaml").read_text())
    for key in ("start", "goal", "obstacles", "allowed"):
        assert mine[key] == bundled[key]
    assert Path(out.parent / mine["robot"]["urdf"]).resolve() == (ARM / "panda" / "panda.urdf")
    assert main(argv[:6] + argv[8:]) == 2  # no --index
    assert "--archive: expected --problem and --index" in capsys.readouterr().err
    assert main([*argv[:7], "101", *argv[8:]]) == 2
    assert "expected one box scene 101, found 0" in capsys.readouterr().err
    # an offset cover: the scenario says so (a loose one here, 2 bodies at most: quick)
    offset = [*argv[:-2], "--max-offset", "0.08", "--bodies-per-link", "2", "-o", str(out)]
    assert main(offset) == 0, capsys.readouterr().err
    robot = yaml.safe_load(out.read_text())["robot"]
    assert robot["max_offset"] == 0.08 and robot["bodies_per_link"] == 2
    assert main([*argv[:-2], "--max-offset", "-1", "-o", str(out)]) == 2
    assert "--max-offset" in capsys.readouterr().err


def test_the_bundled_arm_scenarios_load_with_free_starts_and_goals():
    for path in sorted(ARM.glob("*.yaml")):
        if path.name.startswith("example_"):  # other arms: tests/test_arm_examples.py
            continue
        scenario = load_scenario(path)  # checks start and goal for the arm (its links' hulls)
        assert scenario.arm.dof == 7 and len(scenario.arm.bodies) == 11


def test_bench_runs_and_verifies_arm_planners(tmp_path, capsys):
    """kcplan bench on a bundled MBM problem: both planners solve it and every path is
    re-checked on the links' meshes (the summary's colliding column)."""
    out = tmp_path / "bench"
    argv = ["bench", str(ARM / "box_1.yaml"), "--planners", "kc-rrtconnect,rrtconnect",
            "--runs", "1", "--time", "20", "--no-simplify", "--progress-interval", "0",
            "-o", str(out)]  # fmt: skip
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "2 of 2 runs finished: 2 solved, 0 failed, 0 returned paths collide" in printed
    records = [json.loads(line) for line in (out / "runs.jsonl").read_text().splitlines()]
    assert all(r["collides"] is False and r["verify_queries"] > 0 for r in records)


def test_the_rigid_world_refuses_arms_with_one_line(capsys):
    from kcplan.world import CollisionWorld

    box = ARM / "box_1.yaml"
    with pytest.raises(TypeError, match="expected a rigid robot of ellipsoids, got an arm"):
        CollisionWorld(box)
    assert main(["validate", str(box)]) == 0
    assert "robot arm of 7 joints, 11 bodies (panda.urdf)" in capsys.readouterr().out


def test_a_state_a_hair_outside_a_limit_is_clamped_and_said_once(scenario_file, capsys):
    """Issue 39: a value within LIMIT_TOLERANCE of a limit (data sets write pi where the
    URDF writes 3.14159) is moved onto the limit and reported once; farther out, the error
    shows every digit of the value and of the limit."""
    from kcplan.arm.model import LIMIT_TOLERANCE

    upper = 0.0873  # panda_joint4's upper limit in the bundled URDF
    near = [0.0, -0.3, 0.0, upper + 0.5 * LIMIT_TOLERANCE, 0.0, 1.6, 0.785]
    scenario = load_scenario(scenario_file(goal={"joints": near}))
    assert scenario.goal[3] == upper and scenario.goal.tolist()[:3] == near[:3]
    err = capsys.readouterr().err
    assert err.count("clamped") == 1
    said = f"goal.joints: clamped to the URDF's limits (within 1e-05): panda_joint4 {near[3]!r}"
    assert f"{said} -> 0.0873" in err
    far = [*near[:3], upper + 2 * LIMIT_TOLERANCE, *near[4:]]
    path = scenario_file(goal={"joints": far})
    assert main(["plan", str(path)]) == 2
    assert f"got panda_joint4 {far[3]!r} > 0.0873" in capsys.readouterr().err


TWIN_ARMS = """<robot name="twins">
  <link name="base"/>
  <link name="left"><collision><geometry><box size="0.2 0.05 0.3"/></geometry></collision></link>
  <link name="right"><collision><geometry><box size="0.05 0.2 0.3"/></geometry></collision></link>
  <joint name="j_left" type="revolute"><parent link="base"/><child link="left"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j_right" type="revolute"><parent link="base"/><child link="right"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""
"""Two links turning about one axis, each holding it: in contact at every configuration,
and no SRDF to say so (as a gripper's two halves an SRDF forgot)."""


def test_a_pair_in_contact_everywhere_is_named_with_the_line_that_allows_it(tmp_path, capsys):
    urdf = tmp_path / "twins.urdf"
    urdf.write_text(TWIN_ARMS)
    assert main(["robot", "info", str(urdf)]) == 0
    out = capsys.readouterr().out
    assert ("in contact at every configuration tried (32 random ones within the limits): "
            "[left, right]; a scenario must allow them: allowed: [[left, right]]"
            ) in out  # fmt: skip
    scenario = {"name": "twins", "robot": {"urdf": "twins.urdf", "joints": ["j_left", "j_right"]},
                "start": {"joints": [0.0, 0.0]}, "goal": {"joints": [0.5, -0.5]},
                "obstacles": []}  # fmt: skip
    path = tmp_path / "twins.yaml"
    path.write_text(yaml.safe_dump(scenario))
    assert main(["plan", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (f"{path}: start: left and right touch at every configuration tried (32 "
                   "random ones within the limits): the SRDF does not disable the pair; allow "
                   "it in the scenario with allowed: [[left, right]]")  # fmt: skip
    path.write_text(yaml.safe_dump(scenario | {"allowed": [["left", "right"]]}))
    assert main(["plan", str(path), "--seed", "1"]) == 0
