"""The compiled RRT-Connect of arms (kcplan/_kernel/arm_planner.hpp, kcplan.planning.native):
its paths re-checked on the links' own meshes without gaps, its stock twin's query counts,
its seeds, its time limit and its errors."""

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import arm_obstacles, panda_arm

from kcplan import _kernel
from kcplan.arm import ArmWorld
from kcplan.certification.arm_certifier import DEFAULT_KC_INFLATION
from kcplan.certification.kernel import KernelArmCertifier
from kcplan.planning.problem import plan

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
NATIVE = ("kc-rrtconnect-native", "kc-rrtconnect-lazy-native", "rrtconnect-32-native",
          "rrtconnect-native")  # fmt: skip
READY = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])


@pytest.fixture(scope="module")
def hulls():
    return panda_arm(bodies_per_link=None)


@pytest.fixture(scope="module")
def scene(hulls):
    return ArmWorld(hulls, arm_obstacles())


@pytest.mark.parametrize("name", NATIVE[:2])
@pytest.mark.parametrize("scenario", ["box_1", "bookshelf_small_2", "box_1_cloud"])
def test_native_kc_paths_are_free_on_the_meshes(name, scenario):
    """Every path of the certified native planners, shortcut, is free on the links' own
    meshes checked without gaps (kcplan.arm.verify, independent of the certifier), and
    against every point of a cloud."""
    result = plan(SCENARIOS / "arm" / f"{scenario}.yaml", name, seed=3, time_limit=20.0)
    assert result.solved
    check = result.verify()
    assert not check.collides, check.what
    assert check.min_clearance > 0.0
    c = result.counters
    assert c["native_tree_edges"] > 0 and c["native_attempts"] >= 1
    assert result.length <= result.raw_length + 1e-9  # the shortcuts never lengthen
    if name.startswith("kc-rrtconnect-lazy"):  # every edge of the path found was certified
        assert c["native_path_edges"] >= 1
    # every edge the loop asked reached the certifier, as a proof or (lazy) a screen
    asked = c["native_tree_edges"] + c["native_path_edges"] + c["native_shortcut_edges"]
    assert c["kc_edges"] + c["kc_screened_edges"] == asked


def test_the_same_seed_gives_the_same_path():
    box = SCENARIOS / "arm" / "box_1.yaml"
    paths = [plan(box, "kc-rrtconnect-lazy-native", seed=11).states for _ in range(2)]
    assert np.array_equal(paths[0], paths[1])
    other = plan(box, "kc-rrtconnect-lazy-native", seed=12).states
    assert not np.array_equal(paths[0], other) or len(other) == 2


def test_stock_twin_checks_one_state_per_step(scene):
    """DiscreteArmMotions: q2, then ceil(L / step) - 1 states inside a free edge of length
    L, in OMPL's order; a colliding end rejects after one state."""
    step = 1.0 / 32.0
    motions = _kernel.DiscreteArmMotions(scene.kernel, step)
    q1, q2 = READY.copy(), READY.copy()
    q2[0] += 0.5
    assert not scene.kernel.in_collision(q1.tolist()) and not scene.kernel.in_collision(q2.tolist())
    assert motions.check(q1.tolist(), q2.tolist())
    assert motions.states == math.ceil(0.5 / step)
    assert motions.edges == 1
    assert not motions.certified
    bad = _in_collision_state(scene)
    before = motions.states
    assert not motions.check(q1.tolist(), bad.tolist())
    assert motions.states == before + 1


def _in_collision_state(scene) -> np.ndarray:
    """A joint vector at which the arm touches the scene (the first of seeded samples)."""
    rng = np.random.default_rng(0)
    arm = scene.arm
    for _ in range(10000):
        q = rng.uniform(arm.lower, arm.upper)
        if scene.kernel.in_collision(q.tolist()):
            return q
    raise AssertionError("no colliding state found")


def test_the_time_limit_stops_the_search(scene, hulls):
    """A search that cannot end (its goal collides: no search) and one that is stopped by
    the clock both return unsolved, within their limit."""
    certifier = KernelArmCertifier(scene, kc_inflation=DEFAULT_KC_INFLATION).compiled
    planner = _kernel.ArmRRTConnect(scene.kernel.chain, _kernel.CertifiedArmMotions(certifier))
    bad = _in_collision_state(scene)
    result, path, raw = planner.solve(READY.tolist(), bad.tolist(), 0.5, 1.0, 0)
    assert not result.solved and path == [] and raw == []
    assert result.iterations == 0
    # a range so short that 5 ms cannot reach a far goal
    far = np.asarray(hulls.upper) - 0.05
    if scene.kernel.in_collision(far.tolist()):
        far = np.asarray(hulls.lower) + 0.05
    result, _, _ = planner.solve(READY.tolist(), far.tolist(), 1e-4, 0.005, 0)
    assert not result.solved
    assert result.iterations > 0
    assert result.solve_seconds < 0.005 + 0.05


def test_bad_input_is_one_clear_error(scene, hulls):
    certifier = KernelArmCertifier(scene).compiled
    certified = _kernel.CertifiedArmMotions(certifier)
    planner = _kernel.ArmRRTConnect(scene.kernel.chain, certified)
    outside = np.asarray(hulls.upper) + 0.1
    with pytest.raises(ValueError, match="^start: outside the joint limits$"):
        planner.solve(outside.tolist(), READY.tolist(), 0.5, 1.0)
    with pytest.raises(ValueError, match="^goal: outside the joint limits$"):
        planner.solve(READY.tolist(), outside.tolist(), 0.5, 1.0)
    with pytest.raises(ValueError, match="^range: expected a finite number > 0$"):
        planner.solve(READY.tolist(), READY.tolist(), 0.0, 1.0)
    with pytest.raises(ValueError, match="^state: expected 7 joint values, got 6$"):
        planner.solve(READY[:6].tolist(), READY.tolist(), 0.5, 1.0)
    screened = _kernel.ScreenedArmMotions(certifier, 0.1)
    with pytest.raises(ValueError, match="expected a certifying path validator"):
        _kernel.ArmRRTConnect(scene.kernel.chain, screened, screened)
    with pytest.raises(ValueError, match="^screen step: expected a finite number > 0$"):
        _kernel.ScreenedArmMotions(certifier, -1.0)
    with pytest.raises(ValueError, match="^joint step: expected a finite number > 0$"):
        _kernel.DiscreteArmMotions(scene.kernel, math.inf)
