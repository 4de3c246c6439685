"""Certified joint-space edges of arms (kcplan.certification.arm_certifier) and planning with
them in OMPL, every accepted edge re-checked on the links' own meshes."""

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import arm_obstacles, panda_arm
from ompl import base as ob
from ompl import geometric as og

from kcplan.arm import ArmWorld
from kcplan.arm.verify import ArmMeshChecker, verify_arm_path
from kcplan.certification.arm_certifier import (
    ARM_COUNTER_NAMES,
    DEFAULT_KC_INFLATION,
    ArmEdgeCertifier,
)
from kcplan.certification.certifier import COUNTER_NAMES
from kcplan.planning.states import joint_reader, joint_space, joint_state, set_joint_state
from kcplan.planning.validator import KCMotionValidator

READY = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])


@pytest.fixture(scope="module")
def panda():
    return panda_arm(bodies_per_link=1)


@pytest.fixture(scope="module")
def scene(panda):
    return ArmWorld(panda, arm_obstacles()), arm_obstacles()


@pytest.mark.parametrize("dof", [1, 2, 7])
def test_joint_reader_reads_every_joint_as_a_tuple(dof):
    """What the validator hands the kernel for an OMPL state: a tuple of the joints, in
    order (one joint too: itemgetter of one index alone would return a bare float)."""
    values = np.linspace(-1.0, 1.0, dof) + 0.25
    space = joint_space(-2.0 * np.ones(dof), 2.0 * np.ones(dof))
    state = space.allocState()
    set_joint_state(state, values)
    read = joint_reader(dof)(state)
    assert isinstance(read, tuple) and read == tuple(values)
    np.testing.assert_array_equal(joint_state(state, dof), values)


def test_the_arm_counters_are_the_rigid_certifiers():
    assert set(ARM_COUNTER_NAMES) <= set(COUNTER_NAMES)


def test_accepted_arm_edges_are_free_on_the_meshes(panda, scene):
    """Random edges of every length between valid states: every accepted edge is free on
    the links' collision meshes (checked without gaps, independent of the covers), and
    a good share of the short free edges is accepted."""
    world, obstacles = scene
    certifier = ArmEdgeCertifier(world)
    rng = np.random.default_rng(11)
    accepted = short_accepted = short = 0
    for scale in (1.0, 0.3, 0.05):
        for _ in range(25):
            q1 = rng.uniform(panda.lower, panda.upper)
            if not certifier.state_valid(q1):
                continue
            q2 = np.clip(q1 + scale * rng.uniform(-3, 3, 7), panda.lower, panda.upper)
            if certifier.check(q1, q2):
                accepted += 1
                short_accepted += scale < 0.1
                check = verify_arm_path(panda, obstacles, [q1, q2])
                assert not check.collides, (q1.tolist(), q2.tolist(), check)
            short += scale < 0.1
    assert accepted > 10 and short_accepted >= 0.5 * short
    c = certifier.counters
    assert c["edges"] == c["rejected"] + accepted
    reasons = ("rejected_end_state", "rejected_probe", "rejected_guard", "not_proven")
    assert sum(c[k] for k in reasons) == c["rejected"]


def test_the_mesh_checker_misses_no_contact_that_dense_sampling_sees(panda, scene):
    """Each link and self pair keeps its own horizon (ArmMeshChecker): on random edges a
    contact found by 400 evenly spaced samples is found by the checker too, and where the
    checker reports one the meshes are within its tolerance there."""
    _, obstacles = scene
    checker = ArmMeshChecker(panda, obstacles)
    items = len(checker._links) + len(checker._pairs)
    rng = np.random.default_rng(5)
    found = 0
    for scale in (1.0, 0.3, 0.1):
        for _ in range(8):
            q1 = rng.uniform(panda.lower, panda.upper)
            q2 = np.clip(q1 + scale * rng.uniform(-3, 3, 7), panda.lower, panda.upper)
            check = checker.check([q1, q2])
            dense = False
            for s in np.linspace(0.0, 1.0, 400):
                checker._place(q1 + s * (q2 - q1))
                if min(checker._distance(i) for i in range(items)) <= checker.tolerance:
                    dense = True
                    break
            assert check.collides or not dense, (q1.tolist(), q2.tolist())
            if check.collides:
                found += 1
                checker._place(q1 + check.where[1] * (q2 - q1))
                assert min(checker._distance(i) for i in range(items)) <= checker.tolerance
            assert check.collides or check.queries >= items  # each item measured once
    assert found >= 5  # the scene is cluttered enough for the test to mean something


def test_the_mesh_checker_measures_far_links_by_their_hulls_from_below(panda, scene, monkeypatch):
    """A link's convex hull holds its mesh: where the hull is far, its distance (less the
    margin) is a lower bound of the mesh's; near, the meshes themselves are measured."""
    import kcplan.arm.verify as verify

    _, obstacles = scene
    checker = ArmMeshChecker(panda, obstacles)
    items = range(len(checker._links) + len(checker._pairs))
    rng = np.random.default_rng(11)
    by_hull = 0
    for _ in range(12):
        checker._place(rng.uniform(panda.lower, panda.upper))
        fast = [checker._distance(i) for i in items]
        monkeypatch.setattr(verify, "HULL_NEAR", math.inf)
        exact = [checker._distance(i) for i in items]
        monkeypatch.undo()
        for d, e in zip(fast, exact, strict=True):
            assert d <= e + 1e-12
            if d <= verify.HULL_NEAR:
                assert d == e  # near: the meshes' own distance
            else:
                by_hull += d < e - 1e-9
    assert by_hull > 50  # the hulls do serve


def test_the_mesh_checker_reads_what_trimesh_cannot_as_pinocchio_read_it(panda, scene,
                                                                          monkeypatch):  # fmt: skip
    """A mesh format trimesh cannot read here (Collada without pycollada: Baxter's,
    TIAGo's) is measured on the triangles Pinocchio read (assimp), not refused with a
    traceback: for the Panda's STL files both loaders give the same distances (within
    10 µm: assimp keeps single precision, and FCL's GJK stops at its own tolerance)."""
    import trimesh

    import kcplan.arm.verify as verify

    _, obstacles = scene
    by_trimesh = ArmMeshChecker(panda, obstacles)
    verify._file_mesh.cache_clear()

    def cannot(*args, **kwargs):
        raise ImportError("missing `pip install pycollada`")

    monkeypatch.setattr(trimesh, "load", cannot)
    by_pinocchio = ArmMeshChecker(panda, obstacles)
    monkeypatch.undo()
    verify._file_mesh.cache_clear()
    assert all(h is not None for h in by_pinocchio._hulls[:8])  # the links' hulls too
    items = range(len(by_trimesh._links) + len(by_trimesh._pairs))
    rng = np.random.default_rng(3)
    for _ in range(6):
        q = rng.uniform(panda.lower, panda.upper)
        by_trimesh._place(q), by_pinocchio._place(q)
        for i in items:
            assert by_pinocchio._distance(i) == pytest.approx(by_trimesh._distance(i), abs=1e-5)


def test_an_edge_that_meets_the_scene_midway_is_rejected(panda, scene):
    """Both ends free (covers and meshes), the meshes in contact near s = 0.59."""
    world, obstacles = scene
    certifier = ArmEdgeCertifier(world)
    q1 = np.array([-1.04, 1.68, 0.97, -0.74, 1.68, 3.64, 0.98])
    q2 = np.array([-0.76, 1.3, 1.64, -0.31, 2.39, 3.82, 0.55])
    assert certifier.state_valid(q1) and certifier.state_valid(q2)
    for q in (q1, q2):
        assert not verify_arm_path(panda, obstacles, [q, q]).collides
    check = verify_arm_path(panda, obstacles, [q1, q2])
    assert check.collides and 0.4 < check.where[1] < 0.7
    assert not certifier.check(q1, q2) and not certifier.check(q2, q1)
    c = certifier.counters
    assert c["rejected_probe"] == 2 and c["guards"] == 0  # a probe hit it before any guard
    unprobed = ArmEdgeCertifier(world, probes=False)
    assert not unprobed.check(q1, q2) and not unprobed.check(q2, q1)
    c = unprobed.counters
    assert c["rejected_guard"] + c["not_proven"] == 2 and c["probes"] == 0 and c["guards"] > 2


def test_states_outside_the_limits_are_never_free(panda, scene):
    world, _ = scene
    certifier = ArmEdgeCertifier(world)
    before = dict(world.counters)
    for bad in ([math.nan] * 7, [0.0, 0.0, 0.0, 0.5, 0.0, 1.0, 0.0], [1e308] * 7):
        assert not certifier.state_valid(bad)
        assert not certifier.check(READY, bad)
    assert world.counters == before  # no query was spent on them
    assert certifier.counters["rejected_end_state"] == 3
    with pytest.raises(ValueError, match="7 joint values"):
        certifier.check(READY, READY[:6])


def test_rrtconnect_plans_a_certified_arm_path(panda, scene):
    """OMPL's RRT-Connect on the group's joint box with KCMotionValidator(si, arm, world):
    the path is free on the meshes, without gaps."""
    world, obstacles = scene
    si = ob.SpaceInformation(joint_space(panda.lower, panda.upper))
    mv = KCMotionValidator(si, panda, world)
    si.setMotionValidator(mv)
    si.setStateValidityChecker(mv.state_valid)
    si.setup()
    start, goal = si.allocState(), si.allocState()
    target = np.array([1.64, -0.18, -2.46, -0.78, 1.21, 1.28, 1.13])
    set_joint_state(start, READY)
    set_joint_state(goal, target)
    assert mv.state_valid(start) and mv.state_valid(goal)
    pdef = ob.ProblemDefinition(si)
    pdef.setStartAndGoalStates(start, goal)
    planner = og.RRTConnect(si)
    planner.setProblemDefinition(pdef)
    planner.setup()
    assert planner.solve(20.0)
    mv.raise_error()
    path = pdef.getSolutionPath()
    states = [np.array([s[j] for j in range(panda.dof)]) for s in path.getStates()]
    assert np.allclose(states[0], READY) and np.allclose(states[-1], target)
    check = verify_arm_path(panda, obstacles, states)
    assert not check.collides and check.queries > len(states)
    assert mv.counters["edges"] > 0 and mv.counters["rejected"] < mv.counters["edges"]


def test_the_validator_chooses_the_arm_certificates(panda, scene):
    """An arm's validator certifies with the clearance ball, the KC guards and the
    free-region planes by default (kc-*), with the ball alone for certificates=("ball",)
    (ca-*), the ball and either of the others when asked; anything else, or an inflation
    that is not a positive number, is one clear ValueError."""
    world, _ = scene
    si = ob.SpaceInformation(joint_space(panda.lower, panda.upper))
    default = KCMotionValidator(si, panda, world)
    assert default.certifier.certificates == ("ball", "kc", "region")
    assert default.certifier.compiled.kc_inflation == DEFAULT_KC_INFLATION
    assert default.certifier.compiled.planes
    ball = KCMotionValidator(si, panda, world, certificates=("ball",))
    assert ball.certifier.certificates == ("ball",) and ball.certifier.compiled.kc_inflation == 0
    assert not ball.certifier.compiled.planes
    planes = KCMotionValidator(si, panda, world, certificates=("ball", "region"))
    assert planes.certifier.certificates == ("ball", "region")
    without = KCMotionValidator(si, panda, world, certificates=("ball", "kc"))
    assert without.certifier.certificates == ("ball", "kc") and not without.certifier.planes
    python = KCMotionValidator(
        si, panda, world, backend="python", inflations=[0.3], certificates=("ball", "kc", "region")
    )
    assert python.certifier.kc_inflation == 0.3 and python.certifier.planes
    for bad in (("region",), ("ball", "polytope"), ("ball", "kc", "kc"), ()):
        expected = r"certificates: arms have \('ball', 'kc', 'region'\): 'ball', then"
        with pytest.raises(ValueError, match=expected):
            KCMotionValidator(si, panda, world, certificates=bad)
    for bad in ([0.0], [-1.0], [float("nan")]):
        with pytest.raises(ValueError, match="inflations: expected a KC inflation > 0"):
            KCMotionValidator(si, panda, world, inflations=bad)


def test_a_validator_refuses_the_options_of_the_other_kind_of_robot(panda, scene):
    """The certifier is chosen once (kcplan.certification.certifiers.certifier_for), and each
    kind of robot has its own options: an arm's validator refuses a rigid robot's option
    (it used to ignore learn_schedule, horizon, sweep_test and refuse fallback), a rigid
    robot's refuses an arm's, and a typo is named, all as one ValueError."""
    from kcplan.certification.certifiers import ARM_OPTIONS, RIGID_OPTIONS
    from kcplan.certification.kernel import KernelArmCertifier, KernelCertifier
    from kcplan.planning.states import state_space
    from kcplan.scenarios import load_scenario
    from kcplan.world.collision import CollisionWorld

    world, _ = scene
    si = ob.SpaceInformation(joint_space(panda.lower, panda.upper))
    assert isinstance(KCMotionValidator(si, panda, world).certifier, KernelArmCertifier)
    for name in sorted(set(RIGID_OPTIONS) - set(ARM_OPTIONS)):
        with pytest.raises(ValueError, match=rf"^{name}: an option of rigid robots only; the "
                           r"options of arms are certificates, inflations, max_guards"):
            KCMotionValidator(si, panda, world, **{name: None})
    scenario = load_scenario(Path(__file__).parents[1] / "scenarios/2d/narrow_corridor.yaml")
    rigid = CollisionWorld(scenario)
    si2 = ob.SpaceInformation(state_space(*scenario.bounds))
    assert isinstance(KCMotionValidator(si2, rigid.robot, rigid).certifier, KernelCertifier)
    for name in sorted(set(ARM_OPTIONS) - set(RIGID_OPTIONS)):
        with pytest.raises(ValueError, match=rf"^{name}: an option of arms only; "):
            KCMotionValidator(si2, rigid.robot, rigid, **{name: True})
    with pytest.raises(ValueError, match=r"^horizn: not an option; the options of rigid robots"):
        KCMotionValidator(si2, rigid.robot, rigid, horizn=1.0)
    with pytest.raises(ValueError, match=r"^backend: expected 'kernel' or 'python', got 'gpu'"):
        KCMotionValidator(si2, rigid.robot, rigid, backend="gpu")


BOX_1 = Path(__file__).resolve().parents[1] / "scenarios" / "arm" / "box_1.yaml"


def _lazy_setup(scenario, seed: int):
    """box_1 set up as plan() sets up kc-rrtconnect-lazy (a fresh OMPL setup)."""
    from kcplan.planning.problem import PLANNERS, seed_ompl
    from kcplan.planning.setups import setup_for

    seed_ompl(seed)
    setup = setup_for(scenario, PLANNERS["kc-rrtconnect-lazy"])
    setup.si.setStateValidityChecker(setup.state_valid)
    start, goal = setup.si.allocState(), setup.si.allocState()
    setup.write(start, scenario.start)
    setup.write(goal, scenario.goal)
    setup.ss.setStartAndGoalStates(start, goal)
    planner = og.RRTConnect(setup.si)
    setup.ss.setPlanner(planner)
    setup.ss.setup()
    planner.setRange(setup.kc_range * setup.space.getMaximumExtent())
    return setup


def _assert_certified_and_free(scenario, states) -> None:
    """Every edge of the path certified by a fresh certifier, and free on the meshes
    without gaps (kcplan.arm.verify, independent of the certificates)."""
    from kcplan.certification.certifiers import certifier_for

    world = ArmWorld(scenario.arm, scenario.obstacles, allowed=scenario.allowed)
    fresh = certifier_for(scenario.arm, world)
    assert all(fresh.check(a, b) for a, b in zip(states, states[1:], strict=False))
    check = verify_arm_path(scenario.arm, scenario.obstacles, states, allowed=scenario.allowed)
    assert not check.collides and check.queries > len(states)


def test_the_lazy_planner_certifies_every_edge_of_the_path_it_returns():
    """kc-rrtconnect-lazy screens its trees' edges and certifies the path only: fewer
    edges certified than screened, and the path it returns is certified edge by edge
    and free on the meshes."""
    from kcplan.planning.problem import plan
    from kcplan.scenarios import load_scenario

    scenario = load_scenario(BOX_1)
    result = plan(scenario, "kc-rrtconnect-lazy", seed=2, time_limit=20.0, simplify=False)
    assert result.solved
    c = result.counters
    edges = len(result.states) - 1
    assert c["kc_lazy_attempts"] == c["kc_lazy_rejected_paths"] + 1
    assert c["kc_screened_edges"] > edges  # every tree edge, not only the path's
    if not c["kc_lazy_repaired_edges"]:  # a repair's sub-plans certify as they grow
        assert c["kc_edges"] <= c["kc_lazy_attempts"] * edges  # the paths' edges only
    _assert_certified_and_free(scenario, [np.array(q) for q in result.states])


def test_an_arm_plans_with_the_lazy_planner_unless_told_otherwise():
    """plan() and ``kcplan plan`` without a planner: the lazy kc planner of the compiled
    loop for an arm (it measures best there, RESULTS 26.2), the eager one for a rigid
    robot."""
    from kcplan.cli import main
    from kcplan.planning.names import DEFAULT_ARM_PLANNER, DEFAULT_PLANNER, default_planner
    from kcplan.planning.problem import plan
    from kcplan.scenarios import load_scenario

    assert (DEFAULT_ARM_PLANNER, DEFAULT_PLANNER) == ("kc-rrtconnect-lazy-native", "kc-rrtconnect")
    assert default_planner(True) == DEFAULT_ARM_PLANNER
    assert default_planner(False) == DEFAULT_PLANNER
    scenario = load_scenario(BOX_1)
    result = plan(scenario, seed=2, time_limit=20.0, simplify=False)
    assert result.solved and result.planner == DEFAULT_ARM_PLANNER
    assert result.counters["native_attempts"] >= 1 and result.counters["native_path_edges"] >= 1
    _assert_certified_and_free(scenario, [np.array(q) for q in result.states])
    rigid = plan(BOX_1.parents[1] / "2d" / "narrow_corridor.yaml", seed=2, simplify=False)
    assert rigid.planner == DEFAULT_PLANNER and "native_attempts" not in rigid.counters
    assert main(["plan", str(BOX_1), "--seed", "2", "--no-simplify"]) == 0


def test_a_path_the_certificate_rejects_starts_the_planner_again_with_denser_probes():
    """With probes too sparse to see anything (one per 100 rad: the trees check their
    states only) the planner's first path often crosses the box; with repairs off the
    certificate rejects it, the planner starts again with probes twice as dense each time,
    and the path it finally returns is certified and free. (OMPL is seeded once per
    process, so the runs are repeated until one meets a rejection: about one in two
    does.)"""
    from kcplan.planning.lazy import solve_lazily
    from kcplan.scenarios import load_scenario

    scenario = load_scenario(BOX_1)
    setup = _lazy_setup(scenario, seed=4)
    for _ in range(30):
        outcome = solve_lazily(
            setup.ss, setup.validator, setup.read, 30.0, screen_step=100.0, repair=False
        )
        assert outcome.solved and outcome.attempts == outcome.rejected_paths + 1
        assert outcome.repaired_edges == 0
        if outcome.rejected_paths:
            break
        setup.ss.clear()
    assert outcome.rejected_paths >= 1
    assert outcome.screen_step == 100.0 / 2**outcome.rejected_paths
    assert setup.validator.screen_step is None  # it certifies again
    states = [setup.read(s) for s in setup.ss.getSolutionPath().getStates()]
    _assert_certified_and_free(scenario, states)
    with pytest.raises(ValueError, match="screen_step"):
        solve_lazily(setup.ss, setup.validator, setup.read, 1.0, screen_step=0.0)


def test_a_rejected_edge_is_replaced_by_a_certified_sub_plan():
    """The same sparse probes with repairs on: an edge the certificate rejects is replaced
    by a sub-plan between its ends whose edges are certified, and the first attempt's path
    is returned, certified edge by edge (by a fresh certifier) and free on the meshes."""
    from kcplan.planning.lazy import solve_lazily
    from kcplan.scenarios import load_scenario

    scenario = load_scenario(BOX_1)
    setup = _lazy_setup(scenario, seed=4)
    for _ in range(30):
        before = setup.validator.counters["edges"]
        outcome = solve_lazily(setup.ss, setup.validator, setup.read, 30.0, screen_step=100.0)
        assert outcome.solved and outcome.attempts == outcome.rejected_paths + 1
        if outcome.repaired_edges and not outcome.rejected_paths:
            break
        setup.ss.clear()
    assert outcome.attempts == 1 and outcome.repaired_edges >= 1
    assert outcome.screen_step == 100.0  # not started again
    states = [setup.read(s) for s in setup.ss.getSolutionPath().getStates()]
    # the path's edges were certified, and so was every edge the sub-plans' trees grew
    assert setup.validator.counters["edges"] - before >= len(states) - 1
    _assert_certified_and_free(scenario, states)
