"""SRDF planning groups, named states and virtual joints (issue 57 item 2): read as MoveIt
builds a JointModelGroup, chosen in a scenario (``robot.group``, ``state: NAME``) and
listed by ``kcplan robot info``; bad ones end in one line and exit 2."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kcplan.arm import ArmError
from kcplan.arm.srdf import read_srdf

PANDA = Path(__file__).resolve().parents[1] / "scenarios" / "arm" / "panda"
ARM = tuple(f"panda_joint{i}" for i in range(1, 8))


@pytest.fixture(scope="module")
def model():
    return pin.buildModelFromUrdf(str(PANDA / "panda.urdf"))


def _srdf(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "robot.srdf"
    path.write_text(f'<?xml version="1.0"?>\n<robot name="panda">\n{body}\n</robot>\n')
    return path


def test_the_pandas_groups_states_and_base(model):
    srdf = read_srdf(PANDA / "panda.srdf")
    assert srdf.group_joints("panda_arm", model) == ARM  # a chain from link0 to link8
    assert srdf.group_joints("panda_arm_hand", model) == ARM  # subgroups; fingers fixed
    with pytest.raises(ArmError, match="group 'hand': expected at least one revolute"):
        srdf.group_joints("hand", model)  # the bundled URDF fixes the fingers
    ready = srdf.state("ready", ARM, "panda_arm")
    assert ready["panda_joint4"] == pytest.approx(-2.356)
    assert srdf.state("ready", ARM) == ready  # found without naming the group
    assert [(v.name, v.kind, v.child_link) for v in srdf.virtual_joints] == [
        ("virtual_joint", "floating", "panda_link0")
    ]


def test_members_resolve_as_moveit_resolves_them(tmp_path, model):
    srdf = read_srdf(_srdf(tmp_path, """
      <group name="links"><link name="panda_link3"/><link name="panda_hand"/></group>
      <group name="joints"><joint name="panda_joint6"/><joint name="panda_joint8"/></group>
      <group name="down"><chain base_link="panda_link2" tip_link="panda_link5"/></group>
      <group name="up"><chain base_link="panda_link5" tip_link="panda_link2"/></group>
      <group name="both"><group name="links"/><group name="joints"/></group>
    """))  # fmt: skip
    # a link brings its parent joint (none when that joint is fixed: the hand's)
    assert srdf.group_joints("links", model) == ("panda_joint3",)
    # a fixed joint has no variable
    assert srdf.group_joints("joints", model) == ("panda_joint6",)
    # a chain: the joints between its links, whichever end is the base; not the base's own
    assert srdf.group_joints("down", model) == ("panda_joint3", "panda_joint4", "panda_joint5")
    assert srdf.group_joints("up", model) == srdf.group_joints("down", model)
    assert srdf.group_joints("both", model) == ("panda_joint3", "panda_joint6")  # URDF order


@pytest.mark.parametrize(
    ("body", "group", "message"),
    [
        ('<group name="a"><group name="b"/></group><group name="b"><group name="a"/></group>',
         "a", "expected subgroups without a cycle, got a -> b -> a"),
        ('<group name="a"><group name="zz"/></group>', "a", "subgroup 'zz' is not a group"),
        ('<group name="a"><joint name="nope"/></group>', "a", "'nope' is not a joint of the URDF"),
        ('<group name="a"><chain base_link="panda_link0" tip_link="nope"/></group>', "a",
         "'nope' is not a link of the URDF"),
        ('<virtual_joint name="base" type="planar" parent_frame="odom" child_link="panda_link0"/>'
         '<group name="a"><joint name="base"/></group>', "a", "is a virtual joint (a moving base)"),
        ('<group name="a"><joint name="panda_joint1"/></group>', "b",
         "group: expected one of the SRDF's groups (a), got 'b'"),
    ],
)  # fmt: skip
def test_a_bad_group_is_one_line(tmp_path, model, body, group, message):
    with pytest.raises(ArmError) as err:
        read_srdf(_srdf(tmp_path, body)).group_joints(group, model)
    assert message in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("<robot", "srdf: expected readable XML"),
        ('<group name="a"><chain base_link="panda_link0"/></group>',
         "chain: expected base_link and tip_link"),
        ('<group_state name="s" group="a"><joint name="panda_joint1" value="up"/></group_state>',
         "joint 'panda_joint1': expected a number, got 'up'"),
        ('<virtual_joint name="v" type="planar"/>', "virtual_joint: expected name, type"),
    ],
)  # fmt: skip
def test_a_malformed_srdf_is_one_line(tmp_path, body, message):
    path = tmp_path / "robot.srdf"
    path.write_text(body if body == "<robot" else f"<robot>{body}</robot>")
    with pytest.raises(ArmError) as err:
        read_srdf(path)
    assert message in str(err.value) and "\n" not in str(err.value)


@settings(max_examples=60, deadline=None)
@given(st.data())
def test_a_chain_is_the_paths_difference(tmp_path_factory, model, data):
    """Any chain between two links of the Panda gives the joints on exactly one of the
    links' paths to the root (Pinocchio's ``supports``, read independently)."""
    links = [f.name for f in model.frames if f.type == pin.FrameType.BODY]
    base, tip = data.draw(st.sampled_from(links)), data.draw(st.sampled_from(links))
    chain = f'<group name="c"><chain base_link="{base}" tip_link="{tip}"/></group>'
    path = _srdf(tmp_path_factory.mktemp("chain"), chain)
    joint = {name: model.frames[model.getFrameId(name, pin.FrameType.BODY)].parentJoint
             for name in links}  # fmt: skip
    expected = (set(model.supports[joint[base]]) ^ set(model.supports[joint[tip]])) - {0}
    srdf = read_srdf(path)
    if not expected:
        with pytest.raises(ArmError, match="expected at least one revolute"):
            srdf.group_joints("c", model)
        return
    got = srdf.group_joints("c", model)
    assert got == tuple(model.names[j] for j in sorted(expected))


def _scenario(tmp_path: Path, robot: str, start: str, goal: str) -> Path:
    path = tmp_path / "g.yaml"
    path.write_text(f"name: g\nrobot: {{urdf: {PANDA / 'panda.urdf'}, {robot}}}\n"
                    f"start: {start}\ngoal: {goal}\nobstacles: []\n")  # fmt: skip
    return path


def test_a_scenario_plans_a_group_between_named_states(tmp_path):
    from kcplan.scenarios import load_scenario

    srdf = read_srdf(PANDA / "panda.srdf")
    scenario = load_scenario(_scenario(tmp_path, f"srdf: {PANDA / 'panda.srdf'}, group: panda_arm",
                                       "{state: ready}", "{state: extended}"))  # fmt: skip
    assert scenario.arm.joints == ARM
    ready = srdf.state("ready", ARM)
    np.testing.assert_allclose(scenario.start, [ready[j] for j in ARM])
    # written back with its group (and the states as values), it reads the same
    from kcplan.scenarios import dump_scenario

    dump_scenario(scenario, tmp_path / "again.yaml")
    again = load_scenario(tmp_path / "again.yaml")
    assert again.arm.joints == ARM and again.robot_spec["group"] == "panda_arm"
    np.testing.assert_allclose(again.start, scenario.start)
    from kcplan.cli import main

    path = _scenario(tmp_path, f"srdf: {PANDA / 'panda.srdf'}, group: panda_arm",
                     "{state: ready}", "{state: extended}")  # fmt: skip
    assert main(["plan", str(path), "--time", "5"]) == 0


@pytest.mark.parametrize(
    ("robot", "start", "message"),
    [
        ("group: panda_arm", "{state: ready}", "robot.group: expected an SRDF to read it from"),
        (f"srdf: {PANDA / 'panda.srdf'}, group: panda_arm, joints: [panda_joint1]",
         "{state: ready}", "robot.group: expected a group or joints, not both"),
        (f"srdf: {PANDA / 'panda.srdf'}, group: panda_arm", "{state: open}",
         "start.state: " + str(PANDA / "panda.srdf") + ": group_state: expected one of the "
         "group 'panda_arm''s named states (extended, ready, transport), got 'open'"),
        (f"srdf: {PANDA / 'panda.srdf'}, group: panda_arm", "{state: ready, joints: [0]}",
         "start: expected joints (a list of values) or state"),
        (f"srdf: {PANDA / 'panda.srdf'}, group: arm", "{state: ready}",
         "robot: " + str(PANDA / "panda.srdf") + ": group: expected one of the SRDF's groups"),
    ],
)  # fmt: skip
def test_a_bad_group_or_state_in_a_scenario_exits_2(tmp_path, capsys, robot, start, message):
    from kcplan.cli import main

    path = _scenario(tmp_path, robot, start, "{state: extended}")
    assert main(["plan", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and message in err


def test_robot_info_lists_the_groups_and_plans_one(tmp_path, capsys):
    from kcplan.cli import main

    urdf, srdf = str(PANDA / "panda.urdf"), str(PANDA / "panda.srdf")
    assert main(["robot", "info", urdf, "--srdf", srdf, "--group", "panda_arm"]) == 0
    out = capsys.readouterr().out
    assert "7 joints in the group" in out
    assert f"  panda_arm: {', '.join(ARM)}" in out
    assert "  hand: not plannable: expected at least one revolute or prismatic joint" in out
    assert "named states (group): ready (panda_arm), extended (panda_arm)" in out
    assert "virtual joint virtual_joint: floating, world to panda_link0" in out
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot")  # one line and exit 2 on the SRDF's path too, no traceback
    assert main(["robot", "info", str(bad), "--srdf", srdf, "--group", "panda_arm"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "bad.urdf: urdf: expected a readable URDF" in err
    assert main(["robot", "info", urdf, "--group", "panda_arm"]) == 2
    assert (
        capsys.readouterr().err.strip()
        == "--group: expected --srdf (the SRDF that defines the group)"
    )
