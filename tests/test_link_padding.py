"""A link's own padding (issue 55, item 5: ``robot.link_padding``, MoveIt's per-link
padding): the kernel takes it off that link's clearances alone, the planner keeps it, and
the independent mesh verifier checks it, link by link."""

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from kcplan import plan
from kcplan.arm import ArmWorld
from kcplan.cli import main
from kcplan.scenarios import load_scenario
from kcplan.world.fields import ScenarioError

ROOT = Path(__file__).resolve().parents[1]
BOX = ROOT / "scenarios" / "arm" / "box_1.yaml"
HAND = ("panda_hand", "panda_leftfinger", "panda_rightfinger")


@pytest.fixture(scope="module")
def box():
    return load_scenario(BOX)


def _bodies(arm, links) -> list[int]:
    return [k for k, b in enumerate(arm.bodies) if b.link in links]


def test_the_kernel_takes_a_links_padding_off_its_own_clearances_alone(box):
    bare = ArmWorld(box.arm, box.obstacles, allowed=box.allowed)
    padded = ArmWorld(box.arm, box.obstacles, allowed=box.allowed, padding=0.001,
                      link_padding={"panda_hand": 0.01})  # fmt: skip
    hand = _bodies(box.arm, {"panda_hand"})
    for q in (box.start, box.goal):
        free, _ = bare.kernel.safe_clearances(q.tolist())
        kept, _ = padded.kernel.safe_clearances(q.tolist())
        for k, (a, b) in enumerate(zip(free, kept, strict=True)):
            pad = 0.01 if k in hand else 0.001
            assert b == pytest.approx(max(a - pad, 0.0), abs=1e-12), k
    scene = padded.kernel.scene
    assert [scene.padding_of(k) for k in range(len(box.arm.bodies))] == [
        0.01 if k in hand else 0.001 for k in range(len(box.arm.bodies))
    ]
    # a ball that stands for several bodies keeps the largest padding of all
    assert scene.padding_of(len(box.arm.bodies) + 5) == 0.01
    # setting the padding again undoes the links' own
    scene.padding = 0.002
    assert scene.padding_of(hand[0]) == 0.002


def test_a_link_nearer_than_its_padding_collides(box):
    """At the goal the hand is a few millimetres from the box: padded by more than its
    clearance it collides, the other links padded as much do not make it collide."""
    bare = ArmWorld(box.arm, box.obstacles, allowed=box.allowed)
    free, _ = bare.kernel.safe_clearances(box.goal.tolist())
    hand = _bodies(box.arm, HAND)
    near = min(free[k] for k in hand)
    others = {b.link for k, b in enumerate(box.arm.bodies) if k not in hand}
    far = min(free[k] for k in range(len(free)) if k not in hand)
    assert 0 < near < far  # the test's premise
    pad = 0.5 * (near + far)
    hand_padded = ArmWorld(box.arm, box.obstacles, allowed=box.allowed,
                           link_padding=dict.fromkeys(HAND, pad))  # fmt: skip
    rest_padded = ArmWorld(box.arm, box.obstacles, allowed=box.allowed,
                           link_padding=dict.fromkeys(others, 0.99 * far))  # fmt: skip
    assert hand_padded.kernel.in_collision(box.goal.tolist())
    assert not rest_padded.kernel.in_collision(box.goal.tolist())


def test_a_planned_path_keeps_each_links_padding_on_the_meshes(box):
    # the wrist's link 5 keeps 4 cm (an unpadded path may pass nearer: one did);
    # the hand, which the goal puts within millimetres of the box, keeps nothing
    padded = dataclasses.replace(box, link_padding={"panda_link5": 0.04})
    result = plan(padded, time_limit=20, seed=1)
    assert result.solved
    check = result.verify()  # PlanResult.verify reads the scenario's link_padding
    assert not check.collides, check
    assert check.min_clearance < 0.04  # the other links came nearer: link 5 alone kept it
    # the verifier sees a link's own padding: the same path is too near for 30 cm
    too_much = dataclasses.replace(padded, link_padding={"panda_link5": 0.3})
    assert dataclasses.replace(result, problem=too_much).verify().collides


def _yaml(tmp_path: Path, link_padding) -> Path:
    data = yaml.safe_load(BOX.read_text())
    data["robot"]["link_padding"] = link_padding
    for key, value in data["robot"].items():  # robot paths relative to the original
        if key in ("urdf", "srdf"):
            data["robot"][key] = str((BOX.parent / value).resolve())
    path = tmp_path / "box_padded.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_the_scenario_reads_link_padding(tmp_path):
    scenario = load_scenario(_yaml(tmp_path, {"panda_link4": 0.02}))
    assert scenario.link_padding == {"panda_link4": 0.02}


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ({"panda_link99": 0.01}, "robot.link_padding.panda_link99: expected a link with bodies"),
        ({"panda_link4": -0.01}, "robot.link_padding.panda_link4: expected a clearance of at "),
        ({"panda_link4": "far"}, "robot.link_padding.panda_link4: expected a finite number"),
        ([0.01], "robot.link_padding: expected a mapping of link names to metres"),
    ],
)
def test_bad_link_padding_is_one_line_and_exit_2(tmp_path, capsys, value, message):
    path = _yaml(tmp_path, value)
    with pytest.raises(ScenarioError, match=message.replace(".", r"\.")):
        load_scenario(path)
    assert main(["plan", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0] and str(path) in err[0]


def test_kcplan_verify_names_the_links_padding(tmp_path, capsys):
    path = _yaml(tmp_path, {"panda_link4": 0.3})
    states = np.stack([load_scenario(BOX).start, load_scenario(BOX).goal])
    out = tmp_path / "path.json"
    joints = list(load_scenario(BOX).arm.joints)
    out.write_text(json.dumps({"joints": joints, "states": states.tolist()}))
    assert main(["verify", str(path), str(out)]) == 1
    said = capsys.readouterr().out
    assert "CLOSER THAN THE PADDING 0 (panda_link4 0.3)" in said
