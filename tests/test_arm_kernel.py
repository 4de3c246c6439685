"""The compiled twin of arms (kcplan/_kernel: Chain, ArmWorld, ArmCertifier) against its
Python reference (kcplan.arm.kinematics, kcplan.arm.bounds, kcplan.arm.world,
kcplan.certification.arm_certifier) and against Pinocchio, with every accepted edge re-checked
on the links' own meshes."""

import fcl
import numpy as np
import pinocchio as pin
import pytest
from conftest import AXES_A, AXES_B, FRAME_A, FRAME_B
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from kcplan.arm import ArmWorld
from kcplan.arm.bounds import (
    carries,
    first_order_speeds,
    lever_growth,
    levers,
    point_accelerations,
    point_speeds,
    relative_accelerations,
    relative_first_order,
    relative_speeds,
)
from kcplan.arm.kinematics import body_frames
from kcplan.arm.verify import verify_arm_path
from kcplan.certification.arm_certifier import ARM_COUNTER_NAMES, ArmEdgeCertifier
from kcplan.certification.kernel import KernelArmCertifier
from kcplan.world.obstacles import Obstacle

CYLINDER = Obstacle(  # as kcplan.arm.scenario reads one: extents (r, r, h / 2)
    "cylinder", 3, {}, np.array([0.45, 0.35, 0.4]),
    Rotation.from_quat([0.3, 0.0, 0.0, 0.954]).as_matrix(), np.array([0.05, 0.05, 0.15]),
)  # fmt: skip


EXTRA_OBSTACLES = (CYLINDER,)  # beside the arm tests' scene (conftest.world)


def test_kernel_frames_are_pinocchios(panda, world, states):
    chain = world.kernel.chain
    data = panda.model.createData()
    for q in states[:40]:
        pin.forwardKinematics(panda.model, data, panda.configuration(q))
        expected = np.array([data.oMi[i].homogeneous for i in range(panda.model.njoints)])
        frames = np.array(chain.joint_frames(q.tolist())).reshape(-1, 4, 4)
        np.testing.assert_allclose(frames, expected, rtol=0, atol=1e-12)
        bodies = np.array(chain.body_frames(q.tolist())).reshape(-1, 4, 4)
        np.testing.assert_allclose(bodies, body_frames(panda, q), rtol=0, atol=1e-12)


def test_kernel_speed_bounds_are_the_python_bounds(panda, world):
    chain = world.kernel.chain
    rho = np.array(chain.point_speeds).reshape(len(panda.bodies), panda.dof)
    np.testing.assert_allclose(rho, point_speeds(panda), rtol=1e-15, atol=0)
    fixed = np.array([b.joint == 0 for b in panda.bodies])  # link0's bodies never move
    assert fixed.any() and (rho[fixed, 0] == 0).all() and (rho[~fixed, 0] > 0).all()
    C = np.array(chain.carries).reshape(rho.shape)
    assert (C == carries(panda)).all()
    pairs = world.self_pairs
    got = np.array(chain.relative_speeds(pairs.tolist())).reshape(len(pairs), panda.dof)
    np.testing.assert_allclose(got, relative_speeds(rho, C, pairs), rtol=1e-15, atol=0)


def test_kernel_levers_are_the_python_levers(panda, world, states):
    chain = world.kernel.chain
    rho = point_speeds(panda)
    for q1, q2 in zip(states[:10], states[1:11], strict=True):
        got = np.array(chain.levers(q1.tolist())).reshape(rho.shape)
        np.testing.assert_allclose(got, levers(panda, q1), rtol=0, atol=1e-12)
        assert (got <= rho + 1e-12).all() and ((got > 0) == (rho > 0)).all()
        dq = np.abs(q2 - q1)
        growth = np.array(chain.lever_growth(dq.tolist())).reshape(rho.shape)
        np.testing.assert_allclose(growth, lever_growth(panda, dq), rtol=1e-14, atol=0)


def test_the_local_bound_holds_along_random_edges(panda, states):
    """Every covering ellipsoid's points move at most A t + Q t^2 / 2 within t of a
    guard at s = m (kcplan.arm.bounds): checked on the ellipsoids' sampled surface points,
    placed by the forward kinematics at s = m +- t, and the bound is below the global one
    (v t) for short t."""
    u = np.random.default_rng(2).normal(size=(200, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    rho = point_speeds(panda)
    tighter = 0
    for q1, q2 in zip(states[20:40], states[21:41], strict=True):
        dq, m = np.abs(q2 - q1), 0.4
        qm = q1 + m * (q2 - q1)
        A = levers(panda, qm) @ dq
        Q = lever_growth(panda, dq).sum(axis=1)
        at_m = body_frames(panda, qm)
        for t in (0.02, 0.1, 0.3, 0.6):
            frames = body_frames(panda, q1 + (m + t) * (q2 - q1))
            for k, body in enumerate(panda.bodies):
                local = u * body.semi_axes
                moved = (local @ frames[k][:3, :3].T + frames[k][:3, 3]) - (
                    local @ at_m[k][:3, :3].T + at_m[k][:3, 3]
                )
                assert np.linalg.norm(moved, axis=1).max() <= A[k] * t + Q[k] * t * t / 2 + 1e-12
            tighter += (A * 0.02 + Q * 0.0002 < rho @ dq * 0.02).sum()
    assert tighter > 0.5 * 20 * len(panda.bodies)


def test_first_order_bounds_hold_and_are_the_kernels(panda, world, states):
    """Within t of a guard no sampled surface point moves farther than A1 t + M t^2 / 2
    (the body's twist there and its largest acceleration, kcplan.arm.bounds), on either
    side; the kernel computes the same A1 and M; and A1 is well below the levers' A."""
    u = np.random.default_rng(4).normal(size=(200, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    chain, ratios, worst = world.kernel.chain, [], 0.0
    for q1, q2 in zip(states[40:60], states[41:61], strict=True):
        step, m = q2 - q1, 0.4
        qm = q1 + m * step
        A1, M = first_order_speeds(panda, qm, step), point_accelerations(panda, np.abs(step))
        got = chain.first_order_speeds(qm.tolist(), step.tolist())
        np.testing.assert_allclose(got, A1, rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(chain.point_accelerations(np.abs(step).tolist()), M, rtol=1e-9)
        at_m = body_frames(panda, qm)
        for t in (0.003, 0.05, 0.2, 0.4):
            for s in (m - t, m + t):
                frames = body_frames(panda, q1 + s * step)
                for k, body in enumerate(panda.bodies):
                    local = u * body.semi_axes
                    moved = (local @ frames[k][:3, :3].T + frames[k][:3, 3]) - (
                        local @ at_m[k][:3, :3].T + at_m[k][:3, 3]
                    )
                    bound = A1[k] * t + M[k] * t * t / 2
                    worst = max(worst, np.linalg.norm(moved, axis=1).max() - bound)
        moving = A1 > 0
        ratios.extend(A1[moving] / (levers(panda, qm) @ np.abs(step))[moving])
    assert worst <= 1e-12
    assert np.median(ratios) < 0.8  # the twist's joint terms partly cancel


def test_relative_first_order_bounds_the_pairs_and_is_the_kernels(panda, world, states):
    """Within t of a guard, the distance between any sampled surface point of one body of a
    self pair and any of the other changes by at most A1 t + M t^2 / 2 (the pair's
    relative first order, kcplan.arm.bounds), on either side, where the bodies' own
    (world-frame) first order would not do; the kernel computes the same A1 and M."""
    u = np.random.default_rng(6).normal(size=(60, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    pairs = world.self_pairs
    worst, tighter = -np.inf, 0
    for q1, q2 in zip(states[60:72], states[61:73], strict=True):
        step, m = q2 - q1, 0.4
        qm = q1 + m * step
        A1 = relative_first_order(panda, qm, step, pairs)
        M = relative_accelerations(panda, np.abs(step), pairs)
        np.testing.assert_allclose(world.kernel.pair_first_order(qm.tolist(), step.tolist()),
                                   np.stack([A1, M], axis=1), rtol=1e-9, atol=1e-15)  # fmt: skip
        own = first_order_speeds(panda, qm, step)
        tighter += (A1 < own[pairs[:, 0]] + own[pairs[:, 1]] - 1e-9).sum()
        placed = [(u * b.semi_axes) @ f[:3, :3].T + f[:3, 3]
                  for b, f in zip(panda.bodies, body_frames(panda, qm), strict=True)]  # fmt: skip
        for t in (0.01, 0.1, 0.4):
            for s in (m - t, m + t):
                moved = [(u * b.semi_axes) @ f[:3, :3].T + f[:3, 3]
                         for b, f in zip(panda.bodies, body_frames(panda, q1 + s * step),
                                         strict=True)]  # fmt: skip
                for row, (k, j) in enumerate(pairs):
                    before = np.linalg.norm(placed[k][:, None] - placed[j][None], axis=2)
                    after = np.linalg.norm(moved[k][:, None] - moved[j][None], axis=2)
                    change = np.abs(after - before).max()
                    worst = max(worst, change - (A1[row] * t + M[row] * t * t / 2))
    assert worst <= 1e-12
    assert tighter > 0.5 * 12 * len(pairs)  # the joints both carry drop out


def test_kernel_and_python_agree_on_every_state(world, states):
    kernel = world.kernel
    got = [kernel.in_collision(q.tolist()) for q in states]
    expected = [world.in_collision(q) for q in states]
    assert got == expected
    assert 30 < sum(got) < 270  # both kinds were tried


def test_both_clearances_are_lower_bounds_of_the_sampled_distance(panda, world, states):
    """Each self pair's clearance, kernel (coal) and Python (supports along FCL's
    direction), is at most the smallest distance between sampled surface points (an
    upper bound of the distance), and the two differ little."""
    kernel = world.kernel
    u = np.random.default_rng(3).normal(size=(4000, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    for q in states[:6]:
        if world.in_collision(q):
            continue
        k_scene, k_pairs = kernel.safe_clearances(q.tolist())
        p_scene, p_pairs = world.safe_clearances(q)
        frames = body_frames(panda, q)
        for m, (i, j) in enumerate(world.self_pairs):
            a = frames[i][:3, 3] + (u * panda.bodies[i].semi_axes) @ frames[i][:3, :3].T
            b = frames[j][:3, 3] + (u * panda.bodies[j].semi_axes) @ frames[j][:3, :3].T
            sampled = cKDTree(b[::8]).query(a)[0].min()  # the nearest of the pairs
            assert k_pairs[m] <= sampled and p_pairs[m] <= sampled
        np.testing.assert_allclose(k_pairs, p_pairs, atol=0.02)
        np.testing.assert_allclose(k_scene, p_scene, atol=0.02)


def test_fcl_overestimates_thin_ellipsoids_and_the_arm_world_does_not():
    """The case that made the Python world take only FCL's direction: FCL's distance
    exceeds the sampled distance (an upper bound of the true one) by 7 %, and
    :func:`kcplan.world.support.separation` along FCL's direction stays below it."""
    from kcplan.world.support import EllipsoidSupport, separation

    Fa, Fb = np.array(FRAME_A), np.array(FRAME_B)
    Ra, Rb = Fa[:, :3], Fb[:, :3]
    a, b = np.array(AXES_A), np.array(AXES_B)
    o1 = fcl.CollisionObject(fcl.Ellipsoid(*a), fcl.Transform(Ra, Fa[:, 3]))
    o2 = fcl.CollisionObject(fcl.Ellipsoid(*b), fcl.Transform(Rb, Fb[:, 3]))
    result = fcl.DistanceResult()
    d = fcl.distance(o1, o2, fcl.DistanceRequest(enable_nearest_points=True), result)
    u = np.random.default_rng(0).normal(size=(20000, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    pa, pb = Fa[:, 3] + (u * a) @ Ra.T, Fb[:, 3] + (u[::5] * b) @ Rb.T
    sampled = min(np.sqrt(((pa[i : i + 2000, None] - pb[None]) ** 2).sum(-1)).min()
                  for i in range(0, len(pa), 2000))  # fmt: skip
    assert d > 1.05 * sampled  # FCL: 0.1256 m; the distance is at most 0.1168 m
    n = result.nearest_points[1] - result.nearest_points[0]
    n /= np.linalg.norm(n)
    gap = separation(EllipsoidSupport(Fa[:, 3], Ra, a), EllipsoidSupport(Fb[:, 3], Rb, b), n)
    assert 0.9 * sampled < gap <= sampled


def test_kernel_certifier_decides_as_the_python_certifier(panda, world, states):
    free = [q for q in states if not world.in_collision(q)][:40]
    kernel, python = KernelArmCertifier(world), ArmEdgeCertifier(world)
    same = 0
    for q1, q2 in zip(free, free[1:], strict=False):
        q2 = q1 + 0.25 * (q2 - q1)
        same += kernel.check(q1, q2) == python.check(q1, q2)
    assert same >= len(free) - 2
    k, p = kernel.counters, python.counters
    assert k["edges"] == p["edges"] == len(free) - 1
    for name in ARM_COUNTER_NAMES:  # coal's and FCL's distances differ a little
        assert abs(k[name] - p[name]) <= max(3, 0.05 * p[name]), name
    assert k["certified_by_endpoints"] + k["certified_one_guard"] < k["edges"] - k["rejected"]


@pytest.mark.parametrize("kc_inflation", [0.0, 0.5])  # the balls; and the KC guards too
def test_every_edge_the_kernel_accepts_is_free_on_the_meshes(panda, world, states, kc_inflation):
    free = [q for q in states if not world.in_collision(q)]
    kernel = KernelArmCertifier(world, kc_inflation=kc_inflation)
    rng = np.random.default_rng(5)
    accepted = 0
    for _ in range(60):
        q1, q2 = free[rng.integers(len(free))], free[rng.integers(len(free))]
        q2 = q1 + rng.uniform(0.05, 0.6) * (q2 - q1)
        if kernel.check(q1, q2):
            accepted += 1
            check = verify_arm_path(panda, world.obstacles, [q1, q2])
            assert not check.collides, (q1, q2, check)
    assert accepted >= 15
    assert (kernel.counters["grown_queries"] > 0) == (kc_inflation > 0)


def test_the_kernel_never_certifies_a_bad_state(panda, world, states):
    kernel = KernelArmCertifier(world)
    q = next(q for q in states if not world.in_collision(q))
    assert kernel.state_valid(q)
    before = world.counters["collision_queries"]
    for bad in (np.nan, np.inf, -np.inf, 1e308, panda.upper[0] + 1e-9):
        r = q.copy()
        r[0] = bad
        assert not kernel.state_valid(r)
        assert not kernel.check(q, r)
        assert not kernel.check(r, q)
    assert world.counters["collision_queries"] == before  # rejected with no query
    with pytest.raises(ValueError, match="expected 7 joint values, got 6"):
        kernel.check(q, q[:6])
    with pytest.raises(ValueError, match="finite joint values"):
        world.kernel.in_collision([np.nan] * panda.dof)


def test_part_balls_decide_every_edge_as_every_pair_does(panda, world, states):
    """Deciding far groups of self pairs by the links' balls (the default) changes no
    radius: the same decisions and the same guards as looking at every pair, with groups
    actually skipped. (On the covers of FIT_VERSION 3 this found a probe that collided
    for one certifier and not the other: coal's warm-started yes/no query had taken a
    separating plane 9e-7 off the origin for a contact of two ellipsoids 5.8 mm apart;
    kcplan/_kernel/coal_requests.hpp, confirmed_contact.)"""
    free = [q for q in states if not world.in_collision(q)][:60]
    grouped, every = KernelArmCertifier(world), KernelArmCertifier(world, part_balls=False)
    rng = np.random.default_rng(11)
    for q1, q2 in zip(free, free[1:], strict=False):
        for t in (0.05, 0.3, 1.0):
            end = q1 + t * (q2 - q1)
            assert grouped.check(q1, end) == every.check(q1, end)
        other = free[rng.integers(len(free))]
        assert grouped.check(other, q1) == every.check(other, q1)
    g, e = grouped.counters, every.counters
    for name in ARM_COUNTER_NAMES:
        assert g[name] == e[name], name
    assert g["skipped_groups"] > 0 and e["skipped_groups"] == 0
    assert g["rejected"] > 0 and g["certified_by_endpoints"] + g["certified_one_guard"] > 0


def test_the_guard_cache_saves_guards_and_changes_no_decision(panda, world, states):
    """kc-rrtconnect-nocache's certifier (``guard_cache=False``: one guard and one state
    check remembered) decides every edge of a star of edges, asked twice, as the default
    one, which measures fewer guards: the edges that share a state share its guard. (The
    Python twin gets the same one-entry cache.)"""
    from kcplan.certification.certifiers import certifier_for

    twin = certifier_for(panda, world, "python", guard_cache=False)
    assert twin.cache.max_entries == 1
    assert certifier_for(panda, world, "python").cache.max_entries > 100_000
    free = [q for q in states if not world.in_collision(q)][:25]
    cached = certifier_for(panda, world, "kernel")
    once = certifier_for(panda, world, "kernel", guard_cache=False)
    hub = free[0]
    for _ in range(2):
        for q in free[1:]:
            for end in (hub + 0.3 * (q - hub), q):
                assert cached.check(hub, end) == once.check(hub, end)
    c, o = cached.counters, once.counters
    assert c["rejected"] == o["rejected"] > 0 and c["edges"] - c["rejected"] > 0
    assert c["guards"] < o["guards"] and c["endpoint_guards"] < o["endpoint_guards"]
    assert c["cached_guards"] > o["cached_guards"]


def test_a_self_colliding_end_is_not_remembered_as_valid(panda):
    """Pairs are measured lazily, but an end guard at a self-colliding state still
    rejects its edge and leaves the state invalid in the cache."""
    alone = ArmWorld(panda, ())  # no obstacles: a collision is a self-collision
    states = np.random.default_rng(3).uniform(panda.lower, panda.upper, size=(400, panda.dof))
    touching = [q for q in states if alone.in_collision(q)]
    free = [q for q in states if not alone.in_collision(q)]
    assert touching and free
    certifier = KernelArmCertifier(alone, probes=False)  # straight to the end guards
    for q in touching[:10]:
        assert not certifier.check(q, free[0])  # q1 is assumed valid: the guard finds it
        assert not certifier.state_valid(q)
    assert certifier.counters["rejected_guard"] == min(10, len(touching))


def test_queries_between_edges_answer_as_a_fresh_world(panda, world, states):
    """The kernel puts a body into the scene only when a query first needs it there, and
    an edge's guards move bodies to other states: interleaved with edges, each state's
    collision query and clearances are those of a world that never moved."""
    from kcplan.arm.world import build_kernel_arm

    kernel, fresh = KernelArmCertifier(world), build_kernel_arm(world)
    free = [q for q in states if not world.in_collision(q)][:30]
    tried = 0
    for i, (q1, q2) in enumerate(zip(free, free[1:], strict=False)):
        kernel.check(q1, q1 + 0.5 * (q2 - q1))  # guards and probes at other states
        q = states[(7 * i) % len(states)]
        assert world.kernel.in_collision(q.tolist()) == fresh.in_collision(q.tolist())
        if i % 5 == 0:
            got = world.kernel.safe_clearances(q.tolist())  # GJK's warm starts differ a hair
            for a, b in zip(got, fresh.safe_clearances(q.tolist()), strict=True):
                np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-6)
        tried += 1
    assert tried == len(free) - 1 and kernel.counters["guards"] > 20


def test_the_twins_screen_every_edge_alike_and_screening_proves_nothing(panda, world, states):
    """``screen`` (the lazy planner's test of a tree edge) decides as its Python twin,
    probe by probe; it accepts an edge the certificate rejects once its probes are too
    sparse to meet the contact, which ``check`` never does."""
    free = [q for q in states if not world.in_collision(q)][:40]
    kernel, python = KernelArmCertifier(world), ArmEdgeCertifier(world)
    decisions = []
    for q1, q2 in zip(free, free[1:], strict=False):
        for step in (0.05, 0.2, 1.0):
            a, b = kernel.screen(q1, q2, step), python.screen(q1, q2, step)
            assert a == b, (q1, q2, step)
            decisions.append(a)
    assert any(decisions) and not all(decisions)
    k, p = kernel.counters, python.counters
    assert k["screened_edges"] == p["screened_edges"] == 3 * (len(free) - 1)
    assert k["probes"] == p["probes"] > 0 and k["guards"] == p["guards"] == 0
    obstacles = world.obstacles
    sparse = [
        (q1, q2)
        for q1, q2 in zip(free, free[1:], strict=False)
        if kernel.screen(q1, q2, 100.0) and verify_arm_path(panda, obstacles, [q1, q2]).collides
    ]
    assert sparse, "expected an edge that touches between its ends"
    for q1, q2 in sparse:
        assert not kernel.check(q1, q2) and not python.check(q1, q2)
    with pytest.raises(ValueError, match="step"):
        kernel.screen(free[0], free[1], 0.0)
    with pytest.raises(ValueError, match="step"):
        python.screen(free[0], free[1], -1.0)


def test_a_check_without_probes_decides_every_edge_as_with_them(panda, world, states):
    """``check(..., probe=False)`` (a lazy planner's certification of a screened path
    edge) asks no probe, and its guards alone reach the same decision on every edge as a
    check with probes: probes only reject early. The twins agree call by call."""
    free = [q for q in states if not world.in_collision(q)][:18]
    edges = list(zip(free, free[1:], strict=False))
    probed = [KernelArmCertifier(world).check(a, b) for a, b in edges]
    kernel, python = KernelArmCertifier(world), ArmEdgeCertifier(world)
    bare = []
    for a, b in edges:
        k, p = kernel.check(a, b, probe=False), python.check(a, b, probe=False)
        assert k == p, (a, b)
        bare.append(k)
    assert bare == probed and any(bare) and not all(bare)
    for c in (kernel.counters, python.counters):
        assert c["probes"] == 0 and c["rejected_probe"] == 0 and c["guards"] > 0
    obstacles = world.obstacles
    for (a, b), ok in zip(edges, bare, strict=True):
        if ok:  # independent of the certificate
            assert not verify_arm_path(panda, obstacles, [a, b]).collides
