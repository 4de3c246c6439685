"""Arm robots from URDF (kcplan.arm): the chain, its limits and its link covers."""

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import trimesh
from conftest import _examples_installed
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kcplan.arm import (
    ArmError,
    body_frames,
    carries,
    joint_frames,
    load_arm,
    pair_speeds,
    speeds,
)

ROOT = Path(__file__).resolve().parents[1]
PANDA = ROOT / "scenarios" / "arm" / "panda"
GROUP = [f"panda_joint{i}" for i in range(1, 8)]


@pytest.fixture(scope="module")
def panda(tmp_path_factory):
    cache = tmp_path_factory.mktemp("covers")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("KCPLAN_CACHE_DIR", str(cache))
        return load_arm(PANDA / "panda.urdf", GROUP, srdf=PANDA / "panda.srdf", bodies_per_link=1)


def test_the_panda_group_its_limits_and_its_bodies(panda):
    assert panda.dof == 7 and panda.joints == tuple(GROUP)
    assert panda.kinds == ("revolute",) * 7
    # the URDF's limits, radians
    assert panda.lower[3] == pytest.approx(-3.1416) and panda.upper[5] == pytest.approx(3.8223)
    links = [b.link for b in panda.bodies]
    assert links == [f"panda_link{i}" for i in range(8)] + [
        "panda_hand", "panda_leftfinger", "panda_rightfinger",
    ]  # fmt: skip
    assert [b.joint for b in panda.bodies] == [0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7]
    # the SRDF disables 28 of the 49 pairs Pinocchio would check
    assert len(panda.self_pairs) == 21 and (panda.self_pairs[:, 0] < panda.self_pairs[:, 1]).all()
    hand = links.index("panda_hand")
    assert not ((panda.self_pairs == [links.index("panda_link7"), hand]).all(axis=1)).any()
    assert panda.within_limits(np.zeros(7))
    assert not panda.within_limits([0.0, 0.0, 0.0, 0.1, 0.0, 0.0, 0.0])  # joint 4 <= 0.0873
    assert not panda.within_limits([math.nan] * 7) and not panda.within_limits(np.zeros(6))


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(u=st.lists(st.floats(0.0, 1.0), min_size=7, max_size=7))
def test_joint_frames_agree_with_pinocchio(panda, u):
    """The numpy chain (joint placements and axes) against pinocchio.forwardKinematics,
    every joint frame to 1e-12, anywhere in the limits."""
    state = panda.lower + np.asarray(u) * (panda.upper - panda.lower)
    data = panda.model.createData()
    pin.forwardKinematics(panda.model, data, panda.configuration(state))
    frames = joint_frames(panda, state)
    for i in range(panda.model.njoints):
        assert np.abs(frames[i] - data.oMi[i].homogeneous).max() < 1e-12


def test_every_mesh_vertex_lies_in_its_links_bodies(panda):
    """At random configurations, every vertex of every link's collision mesh, placed by
    Pinocchio's geometry placements, lies inside the union of that link's bodies placed by
    body_frames: the chain and the covers together are sound."""
    rng = np.random.default_rng(7)
    data, gdata = panda.model.createData(), panda.geometry.createData()
    vertices = {}
    for g, obj in enumerate(panda.geometry.geometryObjects):
        mesh = trimesh.load(obj.meshPath, force="mesh", process=False)
        vertices[g] = np.asarray(mesh.vertices) * np.asarray(obj.meshScale)
    for _ in range(5):
        state = rng.uniform(panda.lower, panda.upper)
        pin.forwardKinematics(panda.model, data, panda.configuration(state))
        pin.updateGeometryPlacements(panda.model, data, panda.geometry, gdata)
        frames = body_frames(panda, state)
        for g, V in vertices.items():
            oMg = gdata.oMg[g].homogeneous
            world = V @ oMg[:3, :3].T + oMg[:3, 3]
            worst = np.full(len(world), np.inf)
            for body, frame in zip(panda.bodies, frames, strict=True):
                if body.geometry != g:
                    continue
                local = (world - frame[:3, 3]) @ frame[:3, :3]
                worst = np.minimum(worst, ((local / body.semi_axes) ** 2).sum(axis=1))
            assert worst.max() <= 1.0 + 1e-9, (panda.geometry.geometryObjects[g].name, worst.max())


def test_a_group_in_another_order_is_the_state_order(tmp_path, monkeypatch):
    monkeypatch.setenv("KCPLAN_CACHE_DIR", str(tmp_path))
    lines = []
    arm = load_arm(
        PANDA / "panda.urdf", ["panda_joint2", "panda_joint1"], bodies_per_link=1,
        progress=lines.append,
    )  # fmt: skip
    # one line per link; the 1-body covers come checked from the bundle (kcplan/cover/bundled)
    assert len(lines) == 11 and lines[0].startswith("panda_link0_0: 1 body, bundled in ")
    assert any("link6" in line and "convex hull" in line for line in lines)
    assert arm.joints == ("panda_joint2", "panda_joint1") and arm.dof == 2
    assert arm.lower.tolist() == pytest.approx([-1.8326, -2.9671])
    frames = joint_frames(arm, [0.3, -0.2])
    data = arm.model.createData()
    pin.forwardKinematics(arm.model, data, arm.configuration([0.3, -0.2]))
    assert np.allclose(frames[1], data.oMi[1].homogeneous, atol=1e-12)
    # joint 1 (state index 1) turns about the base's z axis by -0.2
    assert math.atan2(frames[1][1, 0], frames[1][0, 0]) == pytest.approx(-0.2)


@pytest.mark.parametrize(
    "joints, kwargs, message",
    [
        ([], {}, r"joints: expected at least one joint of the URDF, got none"),
        (["panda_joint1", "nope"], {}, r"joints: 'nope' is not a joint of the URDF"),
        (["panda_joint1", "panda_joint1"], {}, r"joints: 'panda_joint1' is named twice"),
        (
            GROUP,
            {"fixed": {"panda_joint1": 0.1}},
            r"fixed: 'panda_joint1' is in the planning group",
        ),
        (GROUP[:6], {"fixed": {"nope": 0.1}}, r"fixed: 'nope' is not a joint of the URDF"),
        (
            GROUP[:6],
            {"fixed": {"panda_joint7": math.inf}},
            r"fixed.panda_joint7: expected a finite",
        ),
        (
            GROUP[:6],  # joint 7 turns within [-2.9671, 2.9671]
            {"fixed": {"panda_joint7": 3.5}},
            r"fixed.panda_joint7: expected a value within the joint's limits "
            r"\[-2.9671, 2.9671\], got 3.5$",
        ),
        (GROUP, {"srdf": "missing.srdf"}, r"missing.srdf: srdf: expected an SRDF file, found none"),
    ],
)
def test_bad_groups_are_refused_with_one_line(joints, kwargs, message):
    with pytest.raises(ArmError, match=message) as err:
        load_arm(PANDA / "panda.urdf", joints, bodies_per_link=1, **kwargs)
    assert "\n" not in str(err.value)


def test_unreadable_robots_are_refused_with_one_line(tmp_path):
    with pytest.raises(ArmError, match=r"urdf: expected a URDF file, found none"):
        load_arm(tmp_path / "none.urdf", GROUP)
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'/><joint")
    with pytest.raises(ArmError, match=r"bad.urdf: urdf: expected a readable URDF"):
        load_arm(bad, GROUP)
    bare = tmp_path / "bare.urdf"
    bare.write_text(
        "<robot name='x'><link name='a'/><link name='b'/>"
        "<joint name='j' type='revolute'><parent link='a'/><child link='b'/>"
        "<axis xyz='0 0 1'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint>"
        "</robot>"
    )
    with pytest.raises(ArmError, match=r"bare.urdf: collision: expected links with collision"):
        load_arm(bare, ["j"])


def test_primitives_are_covered_by_their_enclosing_ellipsoids(tmp_path):
    """A box, a cylinder and a sphere link: every extreme point (corners, rim points, the
    sphere's poles) is inside its one body, and the box's corners and the cylinder's rim
    lie on it (the bounds of the module docstring are tight)."""
    urdf = tmp_path / "prims.urdf"
    links = {
        "box": "<box size='0.2 0.4 0.6'/>",
        "can": "<cylinder radius='0.1' length='0.5'/>",
        "ball": "<sphere radius='0.15'/>",
    }
    parts = ["<robot name='p'><link name='base'/>"]
    for k, (name, shape) in enumerate(links.items()):
        parts.append(
            f"<link name='{name}'><collision><origin xyz='0 0 {0.1 * k}'/><geometry>{shape}"
            "</geometry></collision></link>"
            f"<joint name='j_{name}' type='revolute'><parent link='base'/><child link='{name}'/>"
            "<axis xyz='0 1 0'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint>"
        )
    urdf.write_text("".join(parts) + "</robot>")
    arm = load_arm(urdf, [f"j_{n}" for n in links], representation="ellipsoids")
    assert sorted(b.link for b in arm.bodies) == sorted(links)  # Pinocchio's order
    box, can, ball = (next(b for b in arm.bodies if b.link == name) for name in links)
    assert box.semi_axes == pytest.approx(math.sqrt(3) * np.array([0.1, 0.2, 0.3]))
    assert can.semi_axes == pytest.approx([math.sqrt(1.5) * 0.1] * 2 + [math.sqrt(3) * 0.25])
    assert ball.semi_axes == pytest.approx([0.15] * 3)
    corners = np.array([[x, y, z] for x in (-0.1, 0.1) for y in (-0.2, 0.2) for z in (-0.3, 0.3)])
    angles = np.linspace(0, 2 * math.pi, 16)
    rim = np.array(
        [[0.1 * math.cos(a), 0.1 * math.sin(a), z] for a in angles for z in (-0.25, 0.25)]
    )
    for body, points in ((box, corners), (can, rim)):
        assert ((points / body.semi_axes) ** 2).sum(axis=1) == pytest.approx(1.0)
    assert box.placement[:3, 3] == pytest.approx([0.0, 0.0, 0.0])
    assert ball.placement[:3, 3] == pytest.approx([0.0, 0.0, 0.2])
    # as hulls (the default): the box exactly, the cylinder in a prism, the ball as is
    hulls = load_arm(urdf, [f"j_{n}" for n in links])
    box, can, ball = (next(b for b in hulls.bodies if b.link == name) for name in links)
    assert sorted(map(tuple, box.hull.vertices.round(12))) == sorted(map(tuple, corners))
    assert len(can.hull.vertices) == 64 and ball.hull is None
    assert ball.semi_axes == pytest.approx([0.15] * 3)
    assert can.placement[:3, 3] == pytest.approx([0.0, 0.0, 0.1])


def _surface_points(arm, frames, count=24, seed=0):
    """Points on every body's surface at the given body frames, shape (bodies, count, 3)."""
    u = np.random.default_rng(seed).normal(size=(count, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    local = u[None] * np.stack([b.semi_axes for b in arm.bodies])[:, None]
    return np.einsum("kij,knj->kni", frames[:, :3, :3], local) + frames[:, None, :3, 3]


def _check_speeds(arm, q1, q2, steps=65):
    """Every sampled surface point moves at most speed * s from q(0), and every distance
    between points of a self pair changes by at most pair speed * s."""
    s = np.linspace(0.0, 1.0, steps)
    paths = np.stack([_surface_points(arm, body_frames(arm, q1 + t * (q2 - q1))) for t in s])
    moved = np.linalg.norm(paths - paths[0], axis=-1).max(axis=-1)  # (steps, bodies)
    bound = speeds(arm, q1, q2)
    assert (moved <= s[:, None] * bound[None] + 1e-12).all()
    pairs = arm.self_pairs
    if len(pairs):
        first, second = pairs[:, 0], pairs[:, 1]
        gaps = np.linalg.norm(paths[:, first, :, None] - paths[:, second, None, :], axis=-1)
        change = np.abs(gaps - gaps[0]).max(axis=(-1, -2))  # (steps, pairs)
        assert (change <= s[:, None] * pair_speeds(arm, q1, q2, pairs)[None] + 1e-12).all()
    return moved[-1], bound


def test_the_chain_bounds_every_points_motion_along_random_edges(panda):
    """The speed bounds of kcplan.arm.bounds against the motion of surface points sampled
    at 65 points of random edges (long and short): sound, and a joint moves only the
    bodies it carries."""
    rng = np.random.default_rng(3)
    for scale in (1.0, 0.1, 0.01):
        for _ in range(4):
            q1 = rng.uniform(panda.lower, panda.upper)
            q2 = np.clip(q1 + scale * rng.uniform(-6, 6, 7), panda.lower, panda.upper)
            moved, bound = _check_speeds(panda, q1, q2)
            assert bound[0] == 0.0 and moved[0] == pytest.approx(0.0, abs=1e-12)  # link0
    q1 = 0.5 * (panda.lower + panda.upper)
    q2 = q1.copy()
    q2[6] += 0.5  # joint 7 carries link7, the hand and the fingers only
    moving = speeds(panda, q1, q2) > 0
    assert [b.link for b, m in zip(panda.bodies, moving, strict=True) if m] == [
        "panda_link7", "panda_hand", "panda_leftfinger", "panda_rightfinger",
    ]  # fmt: skip
    assert carries(panda)[:, 0].tolist() == [False] + [True] * 10


def test_the_chain_bounds_a_prismatic_joint(tmp_path):
    """A slide along x carrying a revolute elbow with a box link: sound on random edges,
    and the slide alone moves every point exactly as far as it slides."""
    urdf = tmp_path / "slide.urdf"
    urdf.write_text(
        "<robot name='s'><link name='base'/><link name='carriage'><collision><geometry>"
        "<box size='0.2 0.2 0.2'/></geometry></collision></link><link name='arm'><collision>"
        "<origin xyz='0.5 0 0'/><geometry><box size='1 0.1 0.1'/></geometry></collision></link>"
        "<joint name='slide' type='prismatic'><parent link='base'/><child link='carriage'/>"
        "<origin xyz='0 0 0.3'/><axis xyz='1 0 0'/>"
        "<limit lower='-0.5' upper='2' effort='1' velocity='1'/></joint>"
        "<joint name='elbow' type='revolute'><parent link='carriage'/><child link='arm'/>"
        "<origin xyz='0 0.2 0'/><axis xyz='0 0 1'/>"
        "<limit lower='-2' upper='2' effort='1' velocity='1'/></joint></robot>"
    )
    srdf = tmp_path / "slide.srdf"  # disables nothing: the joined links' pair is checked
    srdf.write_text("<robot name='s'></robot>")
    arm = load_arm(urdf, ["slide", "elbow"], srdf=srdf)
    assert arm.kinds == ("prismatic", "revolute") and len(arm.self_pairs) == 1
    assert len(load_arm(urdf, ["slide", "elbow"]).self_pairs) == 0  # no SRDF: joined, allowed
    rng = np.random.default_rng(5)
    for _ in range(10):
        _check_speeds(arm, rng.uniform(arm.lower, arm.upper), rng.uniform(arm.lower, arm.upper))
    moved, bound = _check_speeds(arm, np.array([0.0, 0.3]), np.array([1.5, 0.3]))
    assert moved == pytest.approx([1.5, 1.5]) and bound == pytest.approx([1.5, 1.5])


MBM = ROOT.parent / "shared" / "data" / "external" / "mbm" / "panda" / "problems.tar.bz2"


def test_an_archive_read_for_some_problems_reads_just_those_as_read_one_by_one():
    from kcplan.arm.mbm import load_mbm_archive, read_mbm_archive

    problems = load_mbm_archive(MBM, [("box", 2), ("cage", 100), ("cage", 101), ("shelf", 1)])
    assert sorted(problems) == [("box", 2), ("cage", 100)]  # what the archive lacks is skipped
    for (problem_class, index), problem in problems.items():
        alone = read_mbm_archive(MBM, problem_class, index)
        assert problem.joints == alone.joints and problem.allowed == alone.allowed
        assert np.array_equal(problem.goal, alone.goal)
        assert [ob.center.tolist() for ob in problem.obstacles] == [
            ob.center.tolist() for ob in alone.obstacles
        ]


def test_an_mbm_problem_is_read_with_its_obstacles_goal_and_allowed_pairs():
    from kcplan.arm.mbm import read_mbm_archive

    problem = read_mbm_archive(MBM, "box", 1)
    assert problem.joints == tuple(GROUP)
    assert problem.start == pytest.approx([0, -0.785, 0, -2.356, 0, 1.571, 0.785])
    assert problem.goal[:2] == pytest.approx([0.4534448383669427, 1.7628])
    assert problem.start_state["panda_finger_joint1"] == pytest.approx(0.065)
    kinds = [ob.kind for ob in problem.obstacles]
    assert kinds[0] == "cylinder" and kinds.count("box") == len(kinds) - 1
    can = problem.obstacles[0]  # dimensions [height 0.14, radius 0.03]
    assert can.extents == pytest.approx([0.03, 0.03, 0.07])
    assert can.center == pytest.approx(
        [0.5408380884576693, 0.3580155146897772, -0.3762264457751537]
    )
    assert frozenset(("panda_hand", "panda_leftfinger")) in problem.allowed
    assert frozenset(("panda_link0", "panda_hand")) not in problem.allowed


UR5 = MBM.parents[1] / "ur5"
UR5_GROUP = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
             "wrist_2_joint", "wrist_3_joint"]  # fmt: skip


@pytest.mark.parametrize(
    "urdf, group, per_link, bodies, pairs",
    [
        (PANDA / "panda.urdf", GROUP, None, 287, 13184),
        (UR5 / "ur5.urdf", UR5_GROUP, None, 226, 14544),
        (PANDA / "panda.urdf", GROUP, 4, 44, 336),
        (PANDA / "panda.urdf", GROUP, 2, 22, 84),  # the arm tests' covers (conftest)
        (PANDA / "panda.urdf", GROUP, 1, 11, 21),
    ],
    ids=["panda", "ur5", "panda-4", "panda-2", "panda-1"],
)
def test_the_default_covers_come_checked_from_the_bundle(
    urdf, group, per_link, bodies, pairs, tmp_path, monkeypatch
):
    """Every machine plans MBM's robots with the same default ellipsoid cover
    (kcplan/cover/bundled), and the Panda at 4, 2 and 1 bodies a link, and none is fitted: the
    benchmarks' body and pair counts, nothing written to the cache."""
    monkeypatch.setenv("KCPLAN_CACHE_DIR", str(tmp_path))
    lines: list[str] = []
    srdf = urdf.with_suffix(".srdf")
    arm = load_arm(urdf, group, srdf=srdf, bodies_per_link=per_link, progress=lines.append,
                   representation="ellipsoids")  # fmt: skip
    assert (len(arm.bodies), len(arm.self_pairs)) == (bodies, pairs)
    assert lines and all(" bundled" in line and "fitted" not in line for line in lines)
    assert not list(tmp_path.iterdir())


def test_the_scenes_allowed_pairs_are_not_checked(panda):
    """The MBM scene allows link5 and the hand to touch: the world checks the SRDF's pairs
    less those; a wrist bent so that their covers overlap is then valid."""
    from kcplan.arm import ArmWorld

    bent = np.array([0.0, -0.3, 0.0, -1.6, 0.0, 2.2, 0.785])
    link5_hand = frozenset(("panda_link5", "panda_hand"))
    link5_link7 = frozenset(("panda_link5", "panda_link7"))
    strict = ArmWorld(panda)
    assert strict.in_collision(bent)
    relaxed = ArmWorld(panda, allowed={link5_hand, link5_link7})
    assert len(relaxed.self_pairs) == len(strict.self_pairs) - 2
    assert not relaxed.in_collision(bent)


def test_bad_mbm_files_are_refused_with_one_line(tmp_path):
    from kcplan.arm.mbm import MbmError, read_mbm_archive, read_mbm_problem

    scene, request = tmp_path / "scene.yaml", tmp_path / "request.yaml"
    cone = "primitives: [{type: cone, dimensions: [1, 2]}]"
    scene.write_text(f"world: {{collision_objects: [{{id: a, {cone}, "
                     "primitive_poses: [{position: [0, 0, 0]}]}]}")  # fmt: skip
    goal = "goal_constraints: [{joint_constraints: [{joint_name: a, position: 1}]}]"
    request.write_text(f"start_state: {{joint_state: {{name: [a], position: [0]}}}}\n{goal}")
    with pytest.raises(MbmError, match=r"scene.yaml: world.collision_objects\[0\].primitives: "
                       r"expected a box, cylinder or sphere"):  # fmt: skip
        read_mbm_problem(scene, request)
    request.write_text("start_state: {joint_state: {name: [a], position: [0]}}")
    with pytest.raises(MbmError, match=r"request.yaml: goal_constraints\[0\].joint_constraints"):
        read_mbm_problem(scene, request)
    request.write_text(": : :")
    with pytest.raises(MbmError, match=r"request.yaml: expected YAML"):
        read_mbm_problem(scene, request)
    with pytest.raises(MbmError, match=r"problem: expected one of table_pick"):
        read_mbm_archive(MBM, "shelf", 1)
    with pytest.raises(MbmError, match=r"expected one box scene 101, found 0"):
        read_mbm_archive(MBM, "box", 101)


def _bracket_arm(tmp_path) -> Path:
    """A one-joint URDF whose link is the L bracket mesh (60 mm, 20 triangles)."""
    import shutil

    shutil.copy(ROOT / "scenarios" / "3d" / "meshes" / "l_bracket.stl", tmp_path / "b.stl")
    urdf = tmp_path / "bracket.urdf"
    urdf.write_text(
        "<robot name='b'><link name='base'/><link name='arm'><collision><geometry>"
        "<mesh filename='b.stl'/></geometry></collision></link>"
        "<joint name='j' type='revolute'><parent link='base'/><child link='arm'/>"
        "<axis xyz='0 0 1'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint></robot>"
    )
    return urdf


def test_link_covers_are_cut_until_they_stick_out_at_most_max_offset(tmp_path, monkeypatch):
    """Issue 25 item 5: ``max_offset`` cuts a link's cover until the proved offset is
    within it (the progress line says how far, and that the most bodies were hit when
    they were); ``bodies_per_link`` alone keeps the fixed count; neither is the
    default offset; a bad value is one line naming the field."""
    from kcplan.arm.model import DEFAULT_MAX_OFFSET, mesh_cover
    from kcplan.scenarios import load_scenario
    from kcplan.world import ScenarioError

    monkeypatch.setenv("KCPLAN_CACHE_DIR", str(tmp_path / "cache"))
    urdf = _bracket_arm(tmp_path)
    lines: list[str] = []
    arm = load_arm(urdf, ["j"], max_offset=0.006, progress=lines.append)
    cover, _ = mesh_cover(tmp_path / "b.stl", None, max_offset=0.006)
    assert cover.offset <= 0.006 and len(arm.bodies) == len(cover.bodies) > 1
    assert "sticking out by at most" in lines[0] and "stopped at" not in lines[0]
    assert len(arm.self_pairs) == 0
    capped: list[str] = []
    assert (
        len(
            load_arm(
                urdf, ["j"], bodies_per_link=2, max_offset=0.006, progress=capped.append
            ).bodies
        )
        == 2
    )
    assert "stopped at 2 bodies, the most asked for" in capped[0]
    assert len(load_arm(urdf, ["j"], bodies_per_link=2).bodies) == 2
    default = load_arm(urdf, ["j"], representation="ellipsoids")
    same = load_arm(urdf, ["j"], max_offset=DEFAULT_MAX_OFFSET)
    assert [b.semi_axes.tolist() for b in default.bodies] == [
        b.semi_axes.tolist() for b in same.bodies
    ]
    for bad in (-1.0, 0.0, math.nan):
        with pytest.raises(ArmError, match=r"bracket\.urdf: max_offset: expected a positive"):
            load_arm(urdf, ["j"], max_offset=bad)
    scenario = tmp_path / "s.yaml"
    robot = f"{{urdf: {urdf}, joints: [j], max_offset: -1}}"
    scenario.write_text(
        f"name: s\nrobot: {robot}\nstart: {{joints: [0]}}\ngoal: {{joints: [0.5]}}\n"
    )
    with pytest.raises(ScenarioError, match=r"robot\.max_offset: expected a positive number"):
        load_scenario(scenario)


def _reach_arms():
    from kcplan.scenarios import load_scenario

    yield "panda", load_scenario(ROOT / "scenarios/arm/box_1.yaml").arm
    yield "ur5", load_arm(UR5 / "ur5.urdf", UR5_GROUP)
    yield "panda-ellipsoids", load_arm(PANDA / "panda.urdf", GROUP, bodies_per_link=2)
    if _examples_installed():  # a base that drives (prismatic), two arms on one torso
        for name in ("example_pr2_doorway", "example_baxter"):
            yield name, load_scenario(ROOT / f"scenarios/arm/{name}.yaml").arm


def test_the_reach_ball_holds_every_body_at_every_state():
    """RESULTS 36.2 and 36.5: a cloud keeps only the points within this ball, so every
    point of every body must lie in it, at random states and at the joint box's corners
    (where the chain stretches)."""
    from kcplan.arm.bounds import reach_ball

    rng = np.random.default_rng(0)
    for name, arm in _reach_arms():
        centre, radius = reach_ball(arm)
        states = rng.uniform(arm.lower, arm.upper, size=(150, arm.dof))
        corners = np.where(rng.random((50, arm.dof)) < 0.5, arm.lower, arm.upper)
        farthest = 0.0
        for q in np.vstack([states, corners]):
            for body, frame in zip(arm.bodies, body_frames(arm, q), strict=True):
                if body.hull is not None:
                    points = body.hull.vertices @ frame[:3, :3].T + frame[:3, 3]
                    far = np.linalg.norm(points - centre, axis=1).max()
                else:
                    far = np.linalg.norm(frame[:3, 3] - centre) + body.semi_axes.max()
                farthest = max(farthest, far)
        assert farthest <= radius, (name, farthest, radius)
        assert farthest > 0.5 * radius, (name, farthest, radius)  # a bound worth having
