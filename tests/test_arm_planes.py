"""The free-region planes of arms (the plane certificate of kcplan.certification.arm_certifier).

The bound the certificate rests on is checked against the links' hulls moved by
Pinocchio's kinematics (no certificate code involved); a hand sliding over a round
table is certified with a few guards where the clearance ball needs many, decided alike
by the kernel and its Python twin, and re-checked on the links' own meshes; and a table
raised into the hand's way rejects the same edge."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kcplan.arm import ArmWorld
from kcplan.arm.bounds import point_accelerations, twists
from kcplan.arm.kinematics import body_frames
from kcplan.arm.verify import verify_arm_path
from kcplan.certification.arm_certifier import ArmEdgeCertifier
from kcplan.certification.kernel import KernelArmCertifier
from kcplan.world.obstacles import Obstacle

BODIES_PER_LINK = None  # the links' own hulls (kcplan's default representation)
READY = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
"""A Panda state whose fingers are lowest, at z = 0.478 m, about x = 0.3 m."""
TABLE_TOP = 0.478 - 0.004  # 4 mm under the fingers


def round_table(top: float):
    """A cylinder of radius 0.15 m standing under the Panda's fingers at READY."""
    half = 0.05  # as kcplan.arm.scenario reads a cylinder: extents (r, r, h / 2)
    centre, extents = np.array([0.3, 0.0, top - half]), np.array([0.15, 0.15, half])
    return [Obstacle("cylinder", 3, {}, centre, np.eye(3), extents)]


def yaw_edge(swing: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
    """READY turned about the base joint from -swing to +swing radians."""
    q1, q2 = READY.copy(), READY.copy()
    q1[0], q2[0] = -swing, swing
    return q1, q2


@settings(max_examples=40, deadline=None)
@given(
    st.integers(0, 299),
    st.integers(0, 299),
    st.floats(0.0, 1.0),
    st.floats(1e-3, 0.5),
    st.integers(0, 2**32 - 1),
)
def test_no_point_crosses_a_slab_faster_than_its_bound(panda, states, i, j, m, t, seed):
    """Within t of a guard at q(m) no vertex of a link's hull moves along a unit n farther
    than S t + M t^2 / 2, on either side, S = max |n . u + x . (n x w)| over the hull's
    vertices x about its centre (at most |n . u| + |n x w| a_max): the support function
    of the hull, moved by Pinocchio's kinematics, against the bound of the twist (w, u)
    and the largest acceleration M there."""
    q1, q2 = states[i], states[j]
    step = q2 - q1
    qm = q1 + m * step
    w, u = twists(panda, qm, step)
    M = point_accelerations(panda, np.abs(step))
    n = np.random.default_rng(seed).normal(size=(len(panda.bodies), 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    at_m = body_frames(panda, qm)
    for s in (m - t, m + t):
        frames = body_frames(panda, q1 + s * step)
        for k, body in enumerate(panda.bodies):
            a_max = float(np.max(body.semi_axes))
            z = np.cross(n[k], w[k])
            spread = (body.hull.vertices @ at_m[k][:3, :3].T) @ z
            across = max(n[k] @ u[k] + spread.max(), -(n[k] @ u[k]) - spread.min())
            assert across <= abs(n[k] @ u[k]) + np.linalg.norm(z) * a_max + 1e-12
            before = (body.hull.vertices @ at_m[k][:3, :3].T + at_m[k][:3, 3]) @ n[k]
            after = (body.hull.vertices @ frames[k][:3, :3].T + frames[k][:3, 3]) @ n[k]
            assert after.max() - before.max() <= across * t + M[k] * t * t / 2 + 1e-12


def test_a_hand_sliding_over_a_table_needs_few_guards(panda):
    """The fingers 4 mm over a round table, the base turned by 0.5 rad: the planes
    certify the edge with at most a third of the ball's guards; the Python twin decides
    alike; the links' own meshes are free all along it (checked without gaps)."""
    world = ArmWorld(panda, round_table(TABLE_TOP))
    q1, q2 = yaw_edge()
    assert not world.in_collision(q1) and not world.in_collision(q2)
    planes, ball = KernelArmCertifier(world), KernelArmCertifier(world, planes=False)
    assert planes.check(q1, q2) and ball.check(q1, q2)
    assert planes.counters["plane_reaches"] > 0 and ball.counters["plane_queries"] == 0
    assert 3 * planes.counters["guards"] <= ball.counters["guards"]
    twin = ArmEdgeCertifier(world, planes=True)
    assert twin.check(q1, q2)
    assert abs(twin.counters["guards"] - planes.counters["guards"]) <= 1
    check = verify_arm_path(panda, world.obstacles, [q1, q2])
    assert not check.collides and check.queries > 2


@pytest.mark.parametrize("raise_by", [0.006, 0.02])
def test_a_table_in_the_hands_way_rejects_the_edge(panda, raise_by):
    """A wider turn with the table raised into the fingers' way (they cut 2 mm or 16 mm
    into it midway; at the ends they are off the table): neither backend accepts it, and
    the meshes confirm the collision."""
    world = ArmWorld(panda, round_table(TABLE_TOP + raise_by))
    q1, q2 = yaw_edge(0.8)
    assert not world.in_collision(q1) and not world.in_collision(q2)
    assert world.in_collision(READY)  # the middle of the edge
    assert verify_arm_path(panda, world.obstacles, [q1, q2]).collides
    for kind in (KernelArmCertifier, ArmEdgeCertifier):
        certifier = kind(world, planes=True)
        assert certifier.planes
        assert not certifier.check(q1, q2)
        assert certifier.counters["rejected"] == 1


def test_planes_decide_random_edges_as_the_twin_and_soundly(panda, world, states):
    """Random edges in the arm tests' scene with the planes on: the kernel and its Python
    twin decide alike (coal's and FCL's directions differ a little), the planes take some
    bodies farther than their balls, and every accepted edge is free on the meshes."""
    free = [q for q in states if not world.in_collision(q)]
    kernel, twin = KernelArmCertifier(world, planes=True), ArmEdgeCertifier(world, planes=True)
    rng = np.random.default_rng(3)
    same = accepted = 0
    for _ in range(40):
        q1, q2 = free[rng.integers(len(free))], free[rng.integers(len(free))]
        q2 = q1 + rng.uniform(0.05, 0.5) * (q2 - q1)
        ok = kernel.check(q1, q2)
        same += ok == twin.check(q1, q2)
        if ok:
            accepted += 1
            assert not verify_arm_path(panda, world.obstacles, [q1, q2]).collides, (q1, q2)
    assert same >= 38 and accepted >= 10
    assert kernel.counters["plane_reaches"] > 0
