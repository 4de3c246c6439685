"""Bad input and faults for arms (issue 25, item 9): Hypothesis fuzz of both arm
certifiers (the compiled :class:`kcplan.certification.kernel.KernelArmCertifier` and its Python
twin :class:`kcplan.certification.arm_certifier.ArmEdgeCertifier`) with joint values that are
not finite, outside the limits by tiny to huge amounts, or of the wrong length; every
fuzzed edge they accept between valid states re-checked on the links' own meshes
(:func:`kcplan.arm.verify.verify_arm_path`); and robots that cannot be built (no
collision geometry, a joint named twice, a fixed value that is not a finite number),
refused in one line by :func:`kcplan.arm.load_arm` and the arm scenario loader."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import PANDA
from conftest import PANDA_GROUP as GROUP
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from kcplan.arm import ArmError, load_arm
from kcplan.arm.scenario import parse_arm_scenario
from kcplan.arm.verify import verify_arm_path
from kcplan.certification.arm_certifier import ArmEdgeCertifier
from kcplan.certification.kernel import KernelArmCertifier
from kcplan.world.fields import ScenarioError

MARGINS = [1e-12, 1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e100, 1e308]
"""How far outside a joint limit a fuzzed value lies (tiny to huge)."""
FUZZ = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


BODIES_PER_LINK = 1  # conftest.panda


@pytest.fixture(scope="module")
def certifiers(world):
    """Both backends on one world, each with its guard cache kept across examples (the
    cache must not let a bad state through either)."""
    return {"kernel": KernelArmCertifier(world), "python": ArmEdgeCertifier(world)}


@pytest.fixture(scope="module")
def free(panda, world):
    """Valid states (for the cover) of the scene, uniform in the joint limits."""
    states = np.random.default_rng(11).uniform(panda.lower, panda.upper, size=(200, panda.dof))
    return [q for q in states if not world.in_collision(q)]


def _bad_value(data, low: float, high: float) -> float:
    """A joint value that is not finite, or outside ``[low, high]`` by a drawn margin."""
    kind = data.draw(st.sampled_from(["nan", "inf", "-inf", "above", "below", "float"]))
    if kind in ("nan", "inf", "-inf"):
        return float(kind)
    if kind == "float":  # any float outside the limits (or not finite)
        x = data.draw(st.floats(allow_nan=True, allow_infinity=True))
        return x if not low <= x <= high else high + 1.0
    margin = data.draw(st.sampled_from(MARGINS) | st.floats(1e-12, 1e308))
    x = high + margin if kind == "above" else low - margin
    if low <= x <= high:  # a margin lost to rounding (1e-12 on a limit of 2.9): one ulp out
        x = math.nextafter(high, math.inf) if kind == "above" else math.nextafter(low, -math.inf)
    return x


@FUZZ
@given(data=st.data())
def test_no_edge_to_or_from_a_bad_state_is_ever_certified(panda, world, certifiers, free, data):
    """Some joints of a valid state replaced by a value that is not finite or outside the
    limits (by 1e-12 to 1e308): not a valid state, no certified edge to it, from it or
    between two such states, no crash, and not one query asked of the world for it."""
    backend = data.draw(st.sampled_from(sorted(certifiers)))
    decide = certifiers[backend]
    q = free[data.draw(st.integers(0, len(free) - 1))]
    bad = q.copy()
    joints = data.draw(st.sets(st.integers(0, panda.dof - 1), min_size=1, max_size=panda.dof))
    for j in joints:
        bad[j] = _bad_value(data, float(panda.lower[j]), float(panda.upper[j]))
    assert not panda.within_limits(bad)
    event(f"{backend}: {len(joints)} bad joint(s)")
    before = world.counters
    assert decide.state_valid(bad) is False
    assert decide.check(q, bad) is False
    assert decide.check(bad, q) is False
    assert decide.check(bad, bad) is False
    assert world.counters == before  # refused before any collision or distance query
    # the good state is still decided as before (nothing cached for the bad one)
    assert decide.state_valid(q) is True


@FUZZ
@given(data=st.data())
def test_fuzzed_edges_between_valid_states_are_free_on_the_meshes(panda, world, certifiers,
                                                                  free, data):  # fmt: skip
    """Edges between states drawn anywhere in the limits (exactly on a limit too), of any
    length: whatever a backend certifies, the links' own meshes find free."""
    backend = data.draw(st.sampled_from(sorted(certifiers)))
    decide = certifiers[backend]
    q1 = free[data.draw(st.integers(0, len(free) - 1))]
    q2 = np.array([
        data.draw(st.sampled_from([lo, hi]) | st.floats(lo, hi))
        for lo, hi in zip(panda.lower.tolist(), panda.upper.tolist(), strict=True)
    ])  # fmt: skip
    t = data.draw(st.sampled_from([1e-9, 1e-3, 0.05, 0.3, 1.0]) | st.floats(0.0, 1.0))
    q2 = np.clip(q1 + t * (q2 - q1), panda.lower, panda.upper)
    if decide.check(q1, q2):
        event(f"{backend}: accepted")
        check = verify_arm_path(panda, world.obstacles, [q1, q2])
        assert not check.collides, (backend, q1.tolist(), q2.tolist(), check)
    else:
        event(f"{backend}: rejected")


@pytest.mark.parametrize("backend", ["kernel", "python"])
@pytest.mark.parametrize("length", [0, 1, 6, 8, 14])
def test_a_state_of_the_wrong_length_is_a_value_error(certifiers, free, backend, length):
    decide, q = certifiers[backend], free[0]
    wrong = np.zeros(length)
    for args in ((q, wrong), (wrong, q), (wrong, wrong)):
        with pytest.raises(ValueError, match=r"expected 7 joint values") as err:
            decide.check(*args)
        assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match=r"expected 7 joint values, got " + str(length)):
        decide.state_valid(wrong)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_world_queries_refuse_joint_values_that_are_not_finite(panda, world, free, bad):
    q = free[0].copy()
    q[3] = bad
    for query in (world.in_collision, world.clearances, world.safe_clearances):
        with pytest.raises(ValueError, match=r"finite joint values"):
            query(q)
    with pytest.raises(ValueError, match=r"finite joint values"):
        world.kernel.in_collision(q.tolist())
    with pytest.raises(ValueError, match=r"expected 7"):
        world.in_collision(q[:6])


# ---------------------------------------------------------------- robots that cannot be built

BARE = (  # a revolute joint between two links, neither with collision geometry
    "<robot name='x'><link name='a'/><link name='b'/>"
    "<joint name='j' type='revolute'><parent link='a'/><child link='b'/>"
    "<axis xyz='0 0 1'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint>"
    "</robot>"
)


def _scenario(tmp_path: Path, **robot) -> dict:
    """An arm scenario (plain data) of the bundled Panda, ``robot`` fields overriding."""
    return {
        "name": "fuzz",
        "robot": {
            "urdf": str(PANDA / "panda.urdf"),
            "joints": GROUP,
            "bodies_per_link": 1,
            **robot,
        },  # fmt: skip
        "start": {"joints": [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]},
        "goal": {"joints": [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]},
    }


def test_a_urdf_without_collision_geometry_is_one_line(tmp_path, monkeypatch):
    monkeypatch.setenv("KCPLAN_CACHE_DIR", str(tmp_path / "covers"))
    bare = tmp_path / "bare.urdf"
    bare.write_text(BARE)
    with pytest.raises(ArmError, match=r"bare.urdf: collision: expected links with") as err:
        load_arm(bare, ["j"])
    assert "\n" not in str(err.value)
    data = _scenario(tmp_path, urdf="bare.urdf", joints=["j"])
    data["start"] = data["goal"] = {"joints": [0.0]}
    with pytest.raises(ScenarioError, match=r"s.yaml: robot: .*bare.urdf: collision") as err:
        parse_arm_scenario(data, "s.yaml", tmp_path)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize(
    "robot, message",
    [
        ({"joints": [*GROUP, "panda_joint3"]}, r"'panda_joint3' is named twice"),
        ({"joints": ["panda_joint1", "panda_joint1"]}, r"'panda_joint1' is named twice"),
        ({"joints": GROUP[:6], "fixed": {"panda_joint7": math.nan}}, r"robot.fixed.panda_joint7"),
        ({"joints": GROUP[:6], "fixed": {"panda_joint7": math.inf}}, r"robot.fixed.panda_joint7"),
        ({"joints": GROUP[:6], "fixed": {"panda_joint7": -math.inf}}, r"robot.fixed.panda_joint7"),
        ({"joints": GROUP[:6], "fixed": {"panda_joint7": "far"}}, r"robot.fixed.panda_joint7"),
        ({"joints": GROUP[:6], "fixed": {"panda_joint7": None}}, r"robot.fixed.panda_joint7"),
        (
            {"joints": GROUP[:6], "fixed": {"panda_joint7": -3.0}},
            r"fixed.panda_joint7: expected a value within the joint's limits",
        ),
    ],
)
def test_bad_groups_and_fixed_values_in_a_scenario_are_one_line(tmp_path, monkeypatch, robot,
                                                                message):  # fmt: skip
    monkeypatch.setenv("KCPLAN_CACHE_DIR", str(tmp_path / "covers"))
    data = _scenario(tmp_path, **robot)
    dof = len(robot["joints"])
    for key in ("start", "goal"):
        data[key] = {"joints": data[key]["joints"][:dof] + [0.0] * (dof - 7)}
    with pytest.raises(ScenarioError, match=message) as err:
        parse_arm_scenario(data, "s.yaml", tmp_path)
    assert "\n" not in str(err.value) and str(err.value).startswith("s.yaml: ")


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, "far", None, [0.1]])
def test_load_arm_refuses_a_fixed_value_that_is_not_a_finite_number(tmp_path, monkeypatch,
                                                                    value):  # fmt: skip
    monkeypatch.setenv("KCPLAN_CACHE_DIR", str(tmp_path / "covers"))
    with pytest.raises(ArmError, match=r"fixed.panda_joint7: expected a finite value") as err:
        load_arm(PANDA / "panda.urdf", GROUP[:6], fixed={"panda_joint7": value},
                 bodies_per_link=1)  # fmt: skip
    assert "\n" not in str(err.value)
