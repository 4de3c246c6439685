"""The KC certificate of arms (kcplan.certification.arm_certifier, ArmCertifier's kc_inflation):
bodies stay inside their grown guards within the reach it gives, checked on sampled
surface points placed by the forward kinematics; the grown guards' queries and the
decisions are the same in both twins (tests/test_arm_kernel.py checks accepted edges on
the links' meshes with and without them)."""

import numpy as np
import pytest

from kcplan.arm.bounds import (
    lever_growth,
    levers,
    point_accelerations,
    point_speeds,
    turn_speeds,
    twists,
)
from kcplan.arm.kinematics import body_frames
from kcplan.certification.arm_certifier import ArmEdgeCertifier, _kc_reaches
from kcplan.certification.kernel import KernelArmCertifier

EPS = 0.2


@pytest.fixture(scope="module")
def free(panda, world):
    states = np.random.default_rng(17).uniform(panda.lower, panda.upper, size=(200, panda.dof))
    return [q for q in states if not world.in_collision(q)]


def _reaches(panda, qm, step, first_order=True):
    """Each body's KC reach at q(m) for the signed joint step (grown guards taken as
    clear: containment does not depend on the scene)."""
    dq = np.abs(step)
    a = np.array([b.semi_axes for b in panda.bodies])
    frames = body_frames(panda, qm)
    _, u = twists(panda, qm, step)
    return _kc_reaches(
        EPS, np.ones(len(a), dtype=bool), a, np.array([f[:3, :3] for f in frames]),
        u if first_order else None, turn_speeds(panda, dq), point_speeds(panda) @ dq,
        levers(panda, qm) @ dq, lever_growth(panda, dq).sum(axis=1),
        point_accelerations(panda, dq),
    )  # fmt: skip


@pytest.mark.parametrize("first_order", [True, False])
def test_a_body_stays_inside_its_grown_guard_within_its_kc_reach(panda, free, first_order):
    """On either side of a guard at s = m, up to the KC reach, every sampled surface point
    of every body lies inside that body grown by 1 + eps at q(m) (the (KC) condition of
    kcplan.certification.arm_certifier), and some reaches beat the clearance a body would need
    for the ball to go as far."""
    u = np.random.default_rng(3).normal(size=(300, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    a = np.array([b.semi_axes for b in panda.bodies])
    worst, checked = -np.inf, 0
    for q1, q2 in zip(free[:15], free[1:16], strict=True):
        step, m = 0.5 * (q2 - q1), 0.4
        qm = q1 + m * step
        reach = _reaches(panda, qm, step, first_order)
        guard = body_frames(panda, qm)
        for k in range(len(a)):
            for fraction in (0.3, 0.7, 0.999):
                t = fraction * min(reach[k], 0.6)
                for s in (m - t, m + t):
                    frame = body_frames(panda, q1 + s * step)[k]
                    points = (u * a[k]) @ frame[:3, :3].T + frame[:3, 3]
                    local = (points - guard[k][:3, 3]) @ guard[k][:3, :3] / ((1 + EPS) * a[k])
                    worst = max(worst, np.linalg.norm(local, axis=1).max())
                    checked += 1
    assert checked > 1000
    assert worst <= 1.0 + 1e-9  # inside the grown guard


def test_the_kc_reach_needs_the_turn_term(panda, free):
    """Without its rotation term (a_max - a_min) w the reach would let a body leave its
    grown guard: the test above can fail."""
    u = np.random.default_rng(5).normal(size=(300, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    a = np.array([b.semi_axes for b in panda.bodies])
    worst = -np.inf
    for q1, q2 in zip(free[:15], free[1:16], strict=True):
        step, m = 0.5 * (q2 - q1), 0.4
        qm = q1 + m * step
        dq = np.abs(step)
        guard = body_frames(panda, qm)
        _, vel = twists(panda, qm, step)
        reach = _kc_reaches(
            EPS, np.ones(len(a), dtype=bool), a, np.array([f[:3, :3] for f in guard]), vel,
            np.zeros(len(a)), point_speeds(panda) @ dq, levers(panda, qm) @ dq,
            lever_growth(panda, dq).sum(axis=1), point_accelerations(panda, dq),
        )  # fmt: skip
        for k in range(len(a)):
            frame = body_frames(panda, q1 + (m + 0.999 * min(reach[k], 0.6)) * step)[k]
            points = (u * a[k]) @ frame[:3, :3].T + frame[:3, 3]
            local = (points - guard[k][:3, 3]) @ guard[k][:3, :3] / ((1 + EPS) * a[k])
            worst = max(worst, np.linalg.norm(local, axis=1).max())
    assert worst > 1.0


def test_the_kernel_computes_the_python_twists_and_turns(panda, world, free):
    chain = world.kernel.chain
    for q1, q2 in zip(free[:10], free[1:11], strict=True):
        step = q2 - q1
        np.testing.assert_allclose(chain.turn_speeds(np.abs(step).tolist()),
                                   turn_speeds(panda, step), rtol=1e-12)  # fmt: skip
        w, u = twists(panda, q1, step)
        expected = np.linalg.norm(u, axis=1) + np.linalg.norm(w, axis=1) * np.array(
            [b.semi_axes.max() for b in panda.bodies]
        )
        got = chain.first_order_speeds(q1.tolist(), step.tolist())
        np.testing.assert_allclose(got, expected, rtol=1e-9)


def test_grown_guards_are_the_same_in_both_twins(panda, world, free):
    """Body by body, the kernel's grown-guard verdicts are python-fcl's; at scale 1 a
    clear guard is a body with positive clearance, and a body grown far is not clear."""
    kernel = world.kernel
    same = total = 0
    for q in free[:40]:
        for scale in (1.0, 1.2, 2.0):
            got = np.array(kernel.grown_clear(q.tolist(), scale))
            expected = world.grown_clear(q, scale)
            same += (got == expected).sum()
            total += got.size
        scene, _ = world.safe_clearances(q)
        np.testing.assert_array_equal(world.grown_clear(q, 1.0), scene > 0)
    assert same >= total - 3  # coal and FCL may differ at a touching body
    assert not np.array(kernel.grown_clear(free[0].tolist(), 30.0)).all()
    for bad in (0.5, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="scale"):
            kernel.grown_clear(free[0].tolist(), bad)
        with pytest.raises(ValueError, match="scale"):
            world.grown_clear(free[0], bad)


def test_kernel_kc_decides_as_the_python_kc(world, free):
    """Both twins with the KC guards make the same decisions, the KC guards take some
    bodies farther than their balls, and the guards are never more than the ball's."""
    kernel = KernelArmCertifier(world, kc_inflation=EPS)
    python = ArmEdgeCertifier(world, kc_inflation=EPS)
    ball = KernelArmCertifier(world)
    rng = np.random.default_rng(9)
    near = []  # states within 2 cm of the scene: where a body, not a pair, may limit a guard
    for q in np.random.default_rng(17).uniform(world.arm.lower, world.arm.upper, (2000, 7)):
        if not world.kernel.in_collision(q.tolist()):
            if min(world.kernel.safe_clearances(q.tolist())[0]) < 0.02:
                near.append(q)
    same = edges = 0
    for q1, q2 in zip(near[:40], near[1:41], strict=False):
        q2 = q1 + rng.uniform(0.01, 0.05) * (q2 - q1)
        got = kernel.check(q1, q2)
        same += got == python.check(q1, q2)
        assert ball.check(q1, q2) == got  # a sound certificate more: the same free edges
        edges += 1
    assert same >= edges - 2
    k, p, b = kernel.counters, python.counters, ball.counters
    assert k["kc_reaches"] > 0 and k["grown_queries"] > 0
    assert k["guards"] <= b["guards"] and b["grown_queries"] == 0
    assert abs(k["guards"] - p["guards"]) <= max(3, 0.05 * p["guards"])
    assert kernel.certificates == python.certificates == ("ball", "kc", "region")


def test_bad_kc_inflations_are_refused(world):
    for bad in (-0.1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="kc_inflation"):
            KernelArmCertifier(world, kc_inflation=bad)
        with pytest.raises(ValueError, match="kc_inflation"):
            ArmEdgeCertifier(world, kc_inflation=bad)
