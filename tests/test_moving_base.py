"""Moving bases and wrapping angles (issue 57 items 1 and 4): a planar base read as three
joints above the URDF's root, continuous joints as revolute joints whose angle wraps;
every edge turns a wrapping angle the shorter way round, in the kernel, the Python
certifier, OMPL's space and the native planner alike, and the certified paths of a PR2
that drives and reaches are free on its meshes. Skipped without example-robot-data."""

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import needs_examples
from hypothesis import given, settings
from hypothesis import strategies as st

from kcplan.arm import ArmError
from kcplan.arm.description import PlanarBase, read_description, unwrapped, wrapped
from kcplan.arm.examples import example_folder
from kcplan.arm.model import load_arm, movable_joints
from kcplan.arm.verify import verify_arm_path
from kcplan.planning.problem import plan
from kcplan.scenarios import load_scenario, parse_scenario
from kcplan.world import ScenarioError

ARM = Path(__file__).resolve().parents[1] / "scenarios" / "arm"
DOORWAY = ARM / "example_pr2_doorway.yaml"


BASE = PlanarBase("world_joint", ((-3.0, 3.0), (-2.0, 2.0)))
ARM_JOINTS = [f"r_{j}_joint" for j in ("shoulder_pan", "shoulder_lift", "upper_arm_roll",
                                       "elbow_flex", "forearm_roll", "wrist_flex",
                                       "wrist_roll")]  # fmt: skip

URDF = """<robot name="r">
  <link name="a"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="b"><collision><origin xyz="0.5 0 0"/>
    <geometry><box size="0.2 0.1 0.1"/></geometry></collision></link>
  <joint name="spin" type="{kind}"><parent link="a"/><child link="b"/>
    <axis xyz="0 0 1"/>{limit}</joint>
</robot>"""


def _urdf(tmp_path, kind="continuous", limit=""):
    path = tmp_path / "r.urdf"
    path.write_text(URDF.format(kind=kind, limit=limit))
    return path


@pytest.fixture(scope="module")
def pr2():  # every test that asks for it is marked needs_examples
    folder = example_folder() / "pr2_description"
    return load_arm(folder / "urdf/pr2.urdf", [*BASE.joints, "torso_lift_joint", *ARM_JOINTS],
                    srdf=folder / "srdf/pr2.srdf", base=BASE)  # fmt: skip


def test_a_continuous_joint_is_a_revolute_one_whose_angle_wraps(tmp_path):
    urdf = _urdf(tmp_path)
    description = read_description(urdf)
    assert description.wrapping == ("spin",) and description.base is None
    arm = load_arm(urdf, ["spin"])
    assert arm.kinds == ("revolute",) and arm.wraps.tolist() == [True]
    assert arm.lower[0] == -math.pi and arm.upper[0] == math.pi
    assert arm.within_limits([7.0])  # any finite angle
    assert not arm.within_limits([math.nan])
    q, clamped, outside = arm.clamp([3 * math.pi / 2])
    assert q[0] == pytest.approx(-math.pi / 2) and not clamped and not outside
    # the edge from 3 to -3 turns 2 pi - 6 the shorter way, through pi
    assert arm.edge_end([3.0], [-3.0])[0] == pytest.approx(3.0 + 2 * math.pi - 6.0)
    assert arm.edge_state([3.0], [-3.0], 0.5)[0] == pytest.approx(math.pi)
    assert arm.body_speeds([3.0], [-3.0]) == pytest.approx(
        arm.body_speeds([0.0], [2 * math.pi - 6.0]))
    # a revolute joint with limits does not wrap, and the file is read as it is
    limited = _urdf(tmp_path, "revolute", '<limit lower="-1" upper="1" effort="1" velocity="1"/>')
    assert read_description(limited).xml is None
    assert load_arm(limited, ["spin"]).wraps is None


@pytest.mark.parametrize("kind, named", [("floating", "a floating joint"),
                                         ("planar", "a planar joint")])
def test_a_group_joint_kcplan_cannot_plan_is_named_by_its_urdf_kind(tmp_path, kind, named):
    # the message of a scenario's joints and of an SRDF group's (kcplan.arm.model.plannable_joint)
    with pytest.raises(ArmError, match=rf"r\.urdf: joints: 'spin' is {named}; expected "
                                       r"revolute or prismatic joints with limits"):  # fmt: skip
        load_arm(_urdf(tmp_path, kind), ["spin"])


def test_a_base_on_a_urdf_whose_root_moves_is_refused(tmp_path):
    urdf = _urdf(tmp_path, "floating")
    with pytest.raises(ArmError, match=r"r\.urdf: robot\.base: expected a URDF whose root "
                                       r"does not move already, got the 'spin' joint of "
                                       r"type floating"):  # fmt: skip
        load_arm(urdf, ["base/x"], base=PlanarBase("base", ((0, 1), (0, 1))))
    (tmp_path / "named.urdf").write_text(URDF.format(kind="continuous", limit="").replace(
        'name="spin"', 'name="base/theta"'))
    with pytest.raises(ArmError, match=r"robot\.base: the base's joints take the names "
                                       r"\['base/theta'\]"):  # fmt: skip
        load_arm(tmp_path / "named.urdf", ["base/x"], base=PlanarBase("base", ((0, 1), (0, 1))))


def test_the_kernel_and_the_python_unwrap_an_edge_alike(tmp_path):
    from kcplan._kernel import kernel_chain

    urdf = _urdf(tmp_path)
    base = PlanarBase("base", ((-1, 1), (-1, 1)))
    arm = load_arm(urdf, [*base.joints, "spin"], base=base)
    assert arm.joints == ("base/x", "base/y", "base/theta", "spin")
    assert arm.wraps.tolist() == [False, False, True, True]
    chain = kernel_chain(arm)

    @settings(max_examples=200, deadline=None)
    @given(st.lists(st.floats(-1, 1), min_size=2, max_size=2),
           st.lists(st.floats(-1, 1), min_size=2, max_size=2),
           st.lists(st.floats(-math.pi, math.pi), min_size=4, max_size=4))  # fmt: skip
    def same(a, b, angles):
        q1, q2 = np.array([*a, *angles[:2]]), np.array([*b, *angles[2:]])
        end = np.array(chain.edge_end(q1.tolist(), q2.tolist()))
        np.testing.assert_allclose(end, arm.edge_end(q1, q2), atol=1e-12)
        np.testing.assert_array_equal(end[:2], q2[:2])  # the base's slides do not wrap
        turn = end[2:] - q1[2:]
        assert (np.abs(turn) <= math.pi + 1e-12).all()  # the shorter way
        np.testing.assert_allclose(wrapped(turn - (q2[2:] - q1[2:])), 0.0, atol=1e-9)
        assert chain.admits(end.tolist())  # an unwrapped angle is any finite angle

    same()
    assert not chain.admits([2.0, 0.0, 0.0, 0.0])  # the base's bounds hold
    np.testing.assert_allclose(unwrapped([0, 0, 3.0, 0], [0, 0, -3.0, 0], arm.wraps),
                               [0, 0, 2 * math.pi - 3.0, 0])  # fmt: skip


@needs_examples
def test_the_base_joints_are_named_as_moveit_names_them(pr2):
    assert pr2.joints[:3] == ("world_joint/x", "world_joint/y", "world_joint/theta")
    assert pr2.kinds[:3] == ("prismatic", "prismatic", "revolute")
    wraps = dict(zip(pr2.joints, pr2.wraps, strict=True))
    assert wraps["world_joint/theta"] and wraps["r_forearm_roll_joint"]
    assert wraps["r_wrist_roll_joint"] and not wraps["world_joint/x"]
    assert not wraps["r_elbow_flex_joint"]
    np.testing.assert_array_equal(pr2.lower[:2], [-3.0, -2.0])
    np.testing.assert_array_equal(pr2.upper[:2], [3.0, 2.0])
    # the base's speed limits are its joints' (the URDF has none for a virtual joint)
    v = [pr2.model.velocityLimit[pr2.model.joints[pr2.model.getJointId(n)].idx_v]
         for n in BASE.joints]  # fmt: skip
    assert v == [0.5, 0.5, 1.0]
    folder = example_folder() / "pr2_description"
    assert movable_joints(folder / "urdf/pr2.urdf", BASE)[:3] == list(BASE.joints)


@needs_examples
def test_the_chain_bounds_every_point_of_a_driving_robot(pr2):
    """The base's slides and turn are joints of the chain: over random edges that drive,
    turn across the wrap and move the arm, no hull vertex moves farther between two close
    states than the speed bound says (finite differences, the bound's own check), and a
    link far from the base's axis pays for its lever."""
    from kcplan.arm.bounds import point_speeds

    rng = np.random.default_rng(7)
    rho = point_speeds(pr2)
    theta = pr2.joints.index("world_joint/theta")
    tips = [k for k, b in enumerate(pr2.bodies) if b.link.startswith("r_gripper")]
    base = [k for k, b in enumerate(pr2.bodies) if b.link == "base_link"]
    assert rho[tips, theta].min() > 2 * rho[base, theta].max()  # the lever
    assert (rho[:, :2] == 1.0).all()  # every body slides with the base
    for _ in range(12):
        q1 = rng.uniform(pr2.lower, pr2.upper)
        q2 = rng.uniform(pr2.lower, pr2.upper)
        q1[theta], q2[theta] = 3.0, -3.0 + rng.uniform(-0.1, 0.1)  # across the wrap
        speeds = pr2.body_speeds(q1, q2)
        h = 1e-3
        for s in np.linspace(0.0, 1.0 - h, 7):
            a = pr2.body_frames(pr2.edge_state(q1, q2, s))
            b = pr2.body_frames(pr2.edge_state(q1, q2, s + h))
            for k, body in enumerate(pr2.bodies):
                if body.hull is None:
                    continue
                v = body.hull.vertices
                there = v @ b[k][:3, :3].T + b[k][:3, 3]
                moved = np.linalg.norm(there - (v @ a[k][:3, :3].T + a[k][:3, 3]), axis=1).max()
                assert moved <= h * speeds[k] * (1 + 1e-9) + 1e-12


@needs_examples
@pytest.mark.parametrize("planner", ["kc-rrtconnect-lazy-native", "kc-rrtconnect"])
def test_the_pr2_drives_through_the_doorway_free_on_its_meshes(planner):
    scenario = load_scenario(DOORWAY)  # start and goal checked free
    arm = scenario.arm
    assert arm.base is not None and arm.dof == 11
    result = plan(scenario, planner, time_limit=20.0, seed=1)
    assert result.solved
    states = np.array(result.states).reshape(-1, arm.dof)
    check = verify_arm_path(arm, scenario.obstacles, states)
    assert not check.collides and check.queries > 0
    x = arm.joints.index("world_joint/x")
    assert states[0, x] < -0.1 and states[-1, x] > 0.1  # through the wall's doorway


@needs_examples
@pytest.mark.parametrize("planner", ["kc-rrtconnect-lazy-native", "kc-rrtconnect"])
def test_a_turn_across_the_wrap_goes_the_shorter_way(tmp_path, planner):
    """From yaw 3.0 to -3.0 in an empty room: the path turns 0.28 rad through pi, not 6
    rad back through 0 (OMPL's SO(2) part; the native planner's own distance)."""
    data = _doorway(start_yaw=3.0, goal_yaw=-3.0)
    data["obstacles"] = []
    data["start"]["joints"][:2] = [0.0, 0.0]
    data["goal"]["joints"][:2] = [0.3, 0.0]
    scenario = parse_scenario(data, str(tmp_path / "turn.yaml"), ARM)
    result = plan(scenario, planner, time_limit=10.0, seed=2)
    assert result.solved
    arm = scenario.arm
    theta = arm.joints.index("world_joint/theta")
    path = arm.continuous(np.array(result.states).reshape(-1, arm.dof))
    turned = np.abs(np.diff(path[:, theta])).sum()
    assert turned == pytest.approx(2 * math.pi - 6.0, abs=1e-9)
    assert (np.abs(np.array(result.states)[:, theta]) <= math.pi + 1e-12).all()


def _doorway(start_yaw: float, goal_yaw: float) -> dict:
    import yaml

    data = yaml.safe_load(DOORWAY.read_text())
    data["start"]["joints"][2] = start_yaw
    data["goal"]["joints"][2] = goal_yaw
    return data


@needs_examples
@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"bounds": [[1.0, 1.0], [-2.0, 2.0]]},
         r"robot\.base\.bounds\.x: expected \[min, max\] with min < max"),
        ({"bounds": [[-3.0, 3.0]]}, r"robot\.base\.bounds: expected \[\[xmin, xmax\]"),
        ({"type": "floating"}, r"robot\.base\.type: expected one of planar"),
        ({"velocity": [0.5, 0.0]}, r"robot\.base\.velocity"),
    ],
)  # fmt: skip
def test_bad_bases_are_one_line_errors(tmp_path, change, message):
    data = _doorway(3.0, 0.0)
    data["robot"]["base"] = {**data["robot"]["base"], **change}
    with pytest.raises(ScenarioError, match=message):
        parse_scenario(data, str(tmp_path / "bad.yaml"), ARM)


@needs_examples
def test_a_group_with_the_virtual_joint_plans_the_base(tmp_path):
    data = _doorway(3.0, 0.0)
    robot = data["robot"]
    del robot["joints"]
    robot["group"] = "base"  # the SRDF's group of the planar virtual joint alone
    data["start"]["joints"] = data["start"]["joints"][:3]
    data["goal"]["joints"] = data["goal"]["joints"][:3]
    scenario = parse_scenario(data, str(tmp_path / "g.yaml"), ARM)
    assert scenario.arm.joints == BASE.joints
    del robot["base"]
    with pytest.raises(ScenarioError, match=r"'world_joint' is a virtual joint \(a moving "
                                            r"base\); expected robot\.base"):  # fmt: skip
        parse_scenario(data, str(tmp_path / "g.yaml"), ARM)
    robot["base"] = {"type": "planar", "bounds": [[-3, 3], [-2, 2]]}
    robot["group"] = "nope"
    with pytest.raises(ScenarioError, match=r"group: expected one of the SRDF's groups"):
        parse_scenario(data, str(tmp_path / "g.yaml"), ARM)


@needs_examples
def test_the_compound_space_reads_and_writes_what_the_kernel_checks(pr2):
    from ompl import base as ob

    from kcplan.planning.states import joint_reader, joint_space, set_joint_state

    space = joint_space(pr2.lower, pr2.upper, pr2.wraps)
    assert isinstance(space, ob.CompoundStateSpace)
    assert space.getSubspaceCount() == 6  # x y | theta | torso, 4 arm | roll | flex | roll
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda s: True)
    si.setup()
    state = si.allocState()
    q = np.linspace(-0.5, 0.5, pr2.dof)
    q[2] = 3.5  # written as 3.5 - 2 pi
    set_joint_state(state, q, pr2.wraps)
    read = np.array(joint_reader(pr2.dof, pr2.wraps)(state))
    expected = q.copy()
    expected[2] = 3.5 - 2 * math.pi
    np.testing.assert_allclose(read, expected, atol=1e-12)


@needs_examples
def test_an_mbm_request_that_moves_the_base_imports_and_plans(tmp_path, capsys):
    """MoveIt's names (issue 57 item 1): the start's base is the multi-DOF joint state's
    transform, the goal names ``world_joint/x``, ``/y``, ``/theta``, and the base's bounds
    are the request's workspace."""
    import yaml

    from kcplan.cli import main

    folder = example_folder() / "pr2_description"
    scene = {"world": {"collision_objects": [{
        "id": "wall", "primitives": [{"type": "box", "dimensions": [0.1, 1.0, 2.0]}],
        "primitive_poses": [{"position": [0.0, 1.2, 1.0], "orientation": [0, 0, 0, 1]}],
    }]}}  # fmt: skip
    half = math.sin(1.5)  # a start turned 3 rad about z
    request = {
        "workspace_parameters": {"min_corner": [-2, -1.5, -1], "max_corner": [2, 1.5, 2]},
        "start_state": {
            "joint_state": {"name": ["torso_lift_joint"], "position": [0.1]},
            "multi_dof_joint_state": {
                "joint_names": ["world_joint"],
                "transforms": [{"translation": [-1.0, 0.2, 0.0],
                                "rotation": [0.0, 0.0, half, math.cos(1.5)]}],  # fmt: skip
            },
        },
        "goal_constraints": [{"joint_constraints": [
            {"joint_name": name, "position": value}
            for name, value in (("world_joint/x", 1.0), ("world_joint/y", -0.2),
                                ("world_joint/theta", -3.0), ("torso_lift_joint", 0.2))
        ]}],
    }  # fmt: skip
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump(scene))
    (tmp_path / "request.yaml").write_text(yaml.safe_dump(request))
    out = tmp_path / "pr2.yaml"
    argv = ["import", "mbm", str(tmp_path / "scene.yaml"), str(tmp_path / "request.yaml"),
            "--urdf", str(folder / "urdf/pr2.urdf"), "--srdf", str(folder / "srdf/pr2.srdf"),
            "-o", str(out)]  # fmt: skip
    assert main(argv) == 0
    written = yaml.safe_load(out.read_text())
    assert written["robot"]["base"] == {"type": "planar", "name": "world_joint",
                                        "bounds": [[-2.0, 2.0], [-1.5, 1.5]]}  # fmt: skip
    np.testing.assert_allclose(written["start"]["joints"], [-1.0, 0.2, 3.0, 0.1], atol=1e-12)
    scenario = load_scenario(out)
    result = plan(scenario, time_limit=10.0, seed=1)
    assert result.solved
    states = np.array(result.states).reshape(-1, scenario.arm.dof)
    assert not verify_arm_path(scenario.arm, scenario.obstacles, states).collides
    del request["workspace_parameters"]
    (tmp_path / "request.yaml").write_text(yaml.safe_dump(request))
    assert main(argv) == 2
    assert "workspace_parameters: expected the bounds of the base world_joint" in (
        capsys.readouterr().err)


def test_pair_proofs_are_cached_on_disk_for_the_arm_as_the_kernel_reads_it(tmp_path, monkeypatch):
    """A PR2's 1,044 pairs take seconds to prove: the proofs are kept per machine, keyed by
    everything the kernel reads; the same robot loaded again finds them in memory, a new
    process reads them back alike, and an arm with other limits is proven anew."""
    from kcplan._kernel import arm_digest, kernel_chain
    from kcplan.arm import pairs as pairs_module

    monkeypatch.setenv("KCPLAN_CACHE_DIR", str(tmp_path))
    urdf = _urdf(tmp_path, "revolute", '<limit lower="-3" upper="3" effort="1" velocity="1"/>')
    urdf.write_text(urdf.read_text().replace(
        "</robot>", '<link name="d"><collision><origin xyz="0.95 0 0"/><geometry><box '
        'size="0.1 0.1 0.1"/></geometry>'
        '</collision></link><joint name="bend" type="revolute"><parent link="b"/><child '
        'link="d"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/><limit lower="-3.14" upper="3.14" '
        'effort="1" velocity="1"/></joint></robot>'))  # fmt: skip
    arm = load_arm(urdf, ["spin", "bend"])
    first = pairs_module.prove_pairs(arm)
    assert [p.verdict for p in first] == ["touches"]  # d folds back onto a
    assert len(list((tmp_path / "pairs").glob("*.npz"))) == 1
    calls, reads, read = [], [], pairs_module._read
    monkeypatch.setattr(pairs_module, "_write", lambda *a: calls.append(a))
    monkeypatch.setattr(pairs_module, "_read", lambda *a: reads.append(a) or read(*a))
    # the same robot loaded again in this process: one arm to the kernel, from memory
    reloaded = load_arm(urdf, ["spin", "bend"])
    assert reloaded is not arm and arm_digest(reloaded) == arm_digest(arm)
    assert kernel_chain(reloaded) is kernel_chain(arm)
    assert pairs_module.prove_pairs(reloaded) == first and not reads and not calls
    monkeypatch.setattr(pairs_module, "_PROOFS", {})  # a new process: from disk
    again = pairs_module.prove_pairs(load_arm(urdf, ["spin", "bend"]))
    assert again == first and len(reads) == 1 and not calls
    narrow = urdf.read_text().replace('lower="-3.14" upper="3.14"', 'lower="-0.5" upper="0.5"')
    (tmp_path / "narrow.urdf").write_text(narrow)
    other = pairs_module.prove_pairs(load_arm(tmp_path / "narrow.urdf", ["spin", "bend"]))
    assert [p.verdict for p in other] == ["apart"] and len(calls) == 1  # proven anew


def test_robot_info_reads_a_base_that_drives(tmp_path, capsys):
    from kcplan.cli import main

    urdf = _urdf(tmp_path)
    assert main(["robot", "info", str(urdf), "--base", "-1", "2", "-3", "4"]) == 0
    out = capsys.readouterr().out
    assert "base base: planar, x in [-1, 2] m, y in [-3, 4] m, at most 0.5 m/s and 1 rad/s; " \
        "joints base/x, base/y, base/theta (the yaw wraps)" in out
    assert "  base/x: prismatic [-1.0, 2.0]\n" in out
    assert "  base/theta: revolute [-3.141592653589793, 3.141592653589793] (an angle that " \
        "wraps" in out
    assert "  spin: revolute [-3.141592653589793, 3.141592653589793] (an angle that wraps" in out
    assert main(["robot", "info", str(urdf), "--base", "1", "1", "-3", "4"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["--base: expected XMIN < XMAX and YMIN < YMAX (metres), got "
                   "[1.0, 1.0, -3.0, 4.0]"]  # fmt: skip


@pytest.mark.parametrize(
    ("kind", "bounds", "message"),
    [
        ("continuous", [[1.0, 1.0], [-1.0, 1.0]],
         r"robot\.base\.bounds\.x: expected \[min, max\] with min < max \(metres\)"),
        ("floating", [[-1.0, 1.0], [-1.0, 1.0]],
         r"robot: .*r\.urdf: robot\.base: expected a URDF whose root does not move already, "
         r"got the 'spin' joint of type floating"),
    ],
)  # fmt: skip
def test_a_bad_base_is_one_line_and_exit_2(tmp_path, capsys, kind, bounds, message):
    import re

    import yaml

    from kcplan.cli import main

    _urdf(tmp_path, kind)
    scenario = {"name": "bad", "robot": {"urdf": "r.urdf", "joints": ["base/x", "base/y"],
                                         "base": {"type": "planar", "bounds": bounds}},
                "start": {"joints": [0.0, 0.0]}, "goal": {"joints": [0.5, 0.0]}}  # fmt: skip
    (tmp_path / "bad.yaml").write_text(yaml.safe_dump(scenario))
    assert main(["plan", str(tmp_path / "bad.yaml"), "-o", str(tmp_path / "p.json")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and re.search(message, err[0]), err
    assert not (tmp_path / "p.json").exists()


def test_pair_proofs_in_threads_are_the_proofs_in_one(monkeypatch):
    """Many pairs are proven on every core, each part on its own world: the verdicts,
    boxes and clearances are those of one thread (each pair's samples are seeded by its
    place in the whole list)."""
    from conftest import PANDA, PANDA_GROUP

    from kcplan._kernel import _core, kernel_chain
    from kcplan.arm import pairs as pairs_module

    arm = load_arm(PANDA / "panda.urdf", PANDA_GROUP)  # no SRDF: 40 pairs
    pairs = [(int(i), int(j)) for i, j in arm.self_pairs]
    chain = kernel_chain(arm)
    one = _core.prove_pairs_apart(_core.ArmWorld(chain, pairs, 0.0, 0.0), 300)
    monkeypatch.setattr(pairs_module, "PARALLEL_PAIRS", 1)
    monkeypatch.setattr(pairs_module.os, "cpu_count", lambda: 3)  # parts of 14, 14, 12
    threaded = pairs_module._prove(_core, chain, pairs, 300)
    assert [p[:3] for p in threaded] == [p[:3] for p in one]
    assert {p[0] for p in one} >= {"apart", "touches"}  # both kinds of verdict compared
