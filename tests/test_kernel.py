"""The compiled kernel (kcplan._kernel) against its Python twin, and against bad input.

* Agreement: :class:`KernelCertifier` (C++, on coal) and :class:`EdgeCertifier` (Python,
  on python-fcl) decide the same random edges, in the same order on the same world, the
  same way; every edge either of them accepts is free under gap-free verification
  (:func:`kcplan.planning.verify.verify_path`, python-fcl clearances only).
* A pose that is not finite is never free, also through OMPL states; nor is a pose
  whose numbers overflow (the fault table), nor one far outside the bounds.
* Wrong input raises ValueError saying what was expected; fuzzed input never aborts the
  process, and an edge the kernel accepts in a small random world verifies free.
* The guard cache stays within its bound.
"""

import functools
import math
import zlib
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from ompl import base as ob

from kcplan import _kernel
from kcplan._kernel import EdgeCertifier as CompiledCertifier
from kcplan._kernel import Robot as KernelRobot
from kcplan._kernel import World as KernelWorld
from kcplan.certification.certifier import (
    CERTIFICATE_SETS,
    COUNTER_NAMES,
    LEARN_EVERY,
    LEARN_ODDS,
    LEARN_WARMUP,
    PROBE_EVERY,
    PROBE_WARMUP,
    EdgeCertifier,
    probe_points,
)
from kcplan.certification.domain import PoseDomain
from kcplan.certification.kernel import KernelCertifier
from kcplan.certification.ladder import GuardLadder
from kcplan.geometry.pose import Edge, quaternion_multiply, wrap_angle
from kcplan.maps.superquadric import bounding_polytopes
from kcplan.planning.states import set_state, state_space
from kcplan.planning.validator import KCMotionValidator
from kcplan.planning.verify import verify_path
from kcplan.scenarios import load_scenario, parse_scenario
from kcplan.world import CollisionWorld, Scenario
from kcplan.world.clutter import random_obstacles, random_pose
from kcplan.world.collision import CLEARANCE_RTOL

ROOT = Path(__file__).resolve().parent.parent
NAN, INF = math.nan, math.inf
SETS = {**CERTIFICATE_SETS, "rotation": ("rotation",)}
"""The ablation sets and the rotation-aware ball alone."""
MIN_EDGES = 20_000
"""Edges per certificate set, over all worlds."""
MIN_AGREEMENT = 0.995


# ------------------------------------------------------------------ worlds and edges


def _scenario_dict(name, n, bounds, robot, obstacles) -> dict:
    low, high = bounds
    return {
        "name": name,
        "dimension": n,
        "bounds": {"low": low, "high": high},
        "robot": robot,
        "start": {"position": low},
        "goal": {"position": high},
        "obstacles": obstacles,
    }


def _thin_walls() -> Scenario:
    """Twelve walls 0.05 thick at odd angles, a thin L polygon and a needle ellipse, for
    a robot 2 x 0.8: where a sampling validator steps over obstacles."""
    rng = np.random.default_rng(11)
    walls = []
    for i in range(4):
        for j in range(3):
            centre = [12.0 + 15 * i + rng.uniform(-2, 2), 10.0 + 15 * j + rng.uniform(-2, 2)]
            size = [0.05, float(rng.uniform(8, 16))]
            yaw = 0.13 + 0.71 * (3 * i + j)
            walls.append({"box": {"center": centre, "size": size, "yaw": yaw}})
    thin_l = [[30, 20], [36, 20], [36, 20.05], [30.05, 20.05], [30.05, 27], [30, 27]]
    walls.append({"polygon": {"vertices": thin_l}})
    walls.append({"ellipse": {"center": [50, 40], "semi_axes": [6, 0.03], "yaw": 0.9}})
    data = _scenario_dict("thin_walls", 2, ([0, 0], [70, 50]), {"semi_axes": [1.0, 0.4]}, walls)
    return parse_scenario(data, check=False)


THREE_BODIES = {
    "bodies": [
        {"semi_axes": [2.0, 1.2, 1.0]},
        {
            "semi_axes": [1.5, 0.5, 0.5],
            "position": [2.5, 1.0, 0.0],
            "quaternion": [0.0, 0.0, 0.3826834, 0.9238795],
        },
        {"semi_axes": [1.0, 1.0, 0.4], "position": [-2.0, 0.0, 1.0]},
    ]
}
"""A robot of three ellipsoids, the first at the origin (a core)."""


def _bodies_3d() -> Scenario:
    """Three ellipsoids (the first at the origin: a core) among random clutter with thin
    rotated walls, rotated ellipsoids, balls and boxes."""
    robot = THREE_BODIES
    obstacles = random_obstacles(np.random.default_rng(12), 3, 16, 20.0)
    data = _scenario_dict("bodies_3d", 3, ([-25] * 3, [25] * 3), robot, obstacles)
    return parse_scenario(data, check=False)


WORLDS = {
    # name: (scenario, edges); single-body worlds first (polytope runs on them only)
    "random_clutter": ("2d/random_clutter", 4000),
    "thin_walls": (_thin_walls, 5000),
    "slanted_gap": ("2d/slanted_gap", 3000),
    "box_field": ("3d/box_field", 3000),
    "window_wall": ("3d/window_wall", 3000),
    "open_space": ("3d/open_space", 2500),  # a mesh and a rotated box
    "l_robot_door": ("2d/l_robot_door", 3000),  # two ellipses
    "bodies_3d": (_bodies_3d, 3000),  # three ellipsoids
}


@functools.cache
def _scenario(name: str) -> Scenario:
    source = WORLDS[name][0]
    if callable(source):
        return source()
    return load_scenario(ROOT / "scenarios" / f"{source}.yaml")


def _turn(rng: np.random.Generator, pose: np.ndarray, n: int) -> np.ndarray:
    """An orientation near or far from ``pose``'s (sometimes the same)."""
    u = rng.random()
    if n == 2:
        if u < 0.2:
            return pose[2:].copy()
        spread = rng.choice([0.05, 0.5, 3.0])
        return wrap_angle(pose[2:] + rng.normal(0.0, spread))
    if u < 0.2:
        return pose[3:].copy()
    if u < 0.5:
        return random_pose(rng, 3, 0, 1)[3:]
    axis = rng.normal(size=3)
    half = 0.5 * rng.choice([0.05, 0.5, 2.0]) * rng.normal()
    delta = (*(math.sin(half) * axis / np.linalg.norm(axis)), math.cos(half))
    return np.array(quaternion_multiply(pose[3:], delta))


def _near_contact(world: CollisionWorld, p1: np.ndarray, p2: np.ndarray) -> np.ndarray:
    """The last free pose of the edge ``p1 -> p2`` before its first contact (to 1e-7 of
    the edge parameter, by bisection), or ``p2`` when no sample of the edge collides."""
    edge = Edge(p1, p2, world.dimension)
    free, hit = 0.0, None
    for s in np.linspace(0.0, 1.0, 17)[1:]:
        if world.in_collision(edge.pose(s)):
            hit = float(s)
            break
        free = float(s)
    if hit is None:
        return p2
    while hit - free > 1e-7:
        mid = 0.5 * (free + hit)
        if world.in_collision(edge.pose(mid)):
            hit = mid
        else:
            free = mid
    return edge.pose(free)


@functools.cache
def _edges(name: str) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
    """Random edges of world ``name`` (deterministic): starts that are free (19 in 20
    times; the rest unchecked), drawn next to an obstacle, uniformly or from earlier end
    states (as a planner extends its tree), ends at 0.05 to 3 robot reaches with
    orientation changes, one in 12 pulled back to just before contact, and some edges
    reversed (both ends then carry cached guards)."""
    scenario = _scenario(name)
    world = CollisionWorld(scenario)
    n, count = scenario.dimension, WORLDS[name][1]
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    low, high = scenario.bounds
    reach = scenario.robot.reach
    edges: list[tuple[np.ndarray, np.ndarray]] = []
    ends: list[np.ndarray] = []
    while len(edges) < count:
        u = rng.random()
        if edges and u < 0.1:
            p2, p1 = edges[int(rng.integers(len(edges)))]
            edges.append((p1, p2))
            continue
        if ends and u < 0.35:
            p1 = ends[int(rng.integers(len(ends)))]
        else:
            for _ in range(20 if rng.random() < 0.95 else 1):
                if rng.random() < 0.6:  # next to an obstacle
                    ob = scenario.obstacles[int(rng.integers(len(scenario.obstacles)))]
                    centre = ob.center + rng.normal(0.0, reach, n)
                else:
                    centre = rng.uniform(low, high)
                p1 = np.concatenate([centre, random_pose(rng, n, 0, 1)[n:]])
                if not world.in_collision(p1):
                    break
        p2 = np.empty_like(p1)
        p2[:n] = p1[:n] + rng.normal(0.0, reach * rng.choice([0.05, 0.3, 1.0, 3.0]), n)
        p2[n:] = _turn(rng, p1, n)
        if rng.random() < 0.08:
            p2 = _near_contact(world, p1, p2)
        edges.append((p1, p2))
        ends.append(p2)
    return tuple(edges)


LOOSE_COUNTERS = (
    "rejected_guard",
    "rejected_probe",
    "probes",
    "probed_edges",
    "not_proven",
    "occupancy_queries",
    "occupancy_rejections",
    "rejected_occupancy",
    "certified_by_endpoints",
    "certified_one_guard",
    "guards",
    "endpoint_guards",
    "cached_guards",
    "bisection_nodes",
)
"""Counters of guard work and of near-contact states. Coal and FCL find slightly
different nearest points (so separating planes) and clearances, so a guard reaches a
little further in one of them; near contact a guard has a tiny clearance in one and none
in the other (``not_proven`` / ``rejected_guard``), and coal's collision test reports
contact up to about 1e-6 before its distance reaches 0, so the kernel learns more grid
cells from the near-contact states (``occupancy_queries``); the grid's learning
schedule follows the grid's rejections, so the twins learn a few other cells
(``occupancy_rejections``, ``rejected_occupancy``; the decisions stay the same). A
near-contact edge may be rejected by a probe in one and by a guard in the other, and the
probes' schedule follows the rejections (``rejected_probe``, ``probes``,
``probed_edges``)."""


def _counter_gap(python: dict, kernel: dict) -> dict:
    """Counters that differ between the two certifiers by more than 1 % (+ 3), or 10 %
    (+ 10) for :data:`LOOSE_COUNTERS`."""
    gaps = {}
    for k in COUNTER_NAMES:
        rel, extra = (0.1, 10) if k in LOOSE_COUNTERS else (0.01, 3)
        if abs(python[k] - kernel[k]) > rel * max(python[k], kernel[k]) + extra:
            gaps[k] = (python[k], kernel[k])
    return gaps


# ------------------------------------------------------------------ 1. agreement


@pytest.mark.parametrize("name", sorted(WORLDS))
def test_kernel_collision_verdicts_agree_with_python_fcl(name):
    """The kernel's collision query lets GJK stop once a pair is proven apart: it still
    finds every collision python-fcl finds, and calls every state free that python-fcl
    sees more than 1e-6 of the scene's size away from all obstacles (near contact coal
    reports contact up to about 1e-6 early, which only rejects)."""
    scenario = _scenario(name)
    world = CollisionWorld(scenario)
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    low, high = scenario.bounds
    n = scenario.dimension
    poses = rng.uniform(low, high, (1500, n))
    if n == 2:
        poses = np.column_stack([poses, rng.uniform(-np.pi, np.pi, len(poses))])
    else:
        q = rng.normal(size=(len(poses), 4))
        poses = np.column_stack([poses, q / np.linalg.norm(q, axis=1, keepdims=True)])
    near = 1e-6 * float(np.ptp(scenario.bounds, axis=0).max())
    hits = 0
    for pose in poses:
        compiled = world.kernel.in_collision(pose.tolist())
        if world.in_collision(pose):
            hits += 1
            assert compiled, pose
        elif world.clearance(pose) > near:
            assert not compiled, pose
    assert 0 < hits < len(poses)  # both kinds of state were drawn


def _superquadric_world() -> Scenario:
    """Three superquadric polytopes of about 1,000 vertices each (where GJK hill-climbs
    over vertex neighbours) around three ellipsoids, inside a mesh-free box field."""
    obstacles = []
    for i, (e, axes) in enumerate([(0.3, [6, 3, 2]), (0.6, [2, 5, 3]), (1.0, [4, 4, 1])]):
        outer = bounding_polytopes(axes, e, count=500).outer
        obstacles.append(
            {"convex": {"vertices": outer.tolist(), "position": [9.0 * (i - 1), 0, 0]}}
        )
    obstacles += random_obstacles(np.random.default_rng(13), 3, 6, 20.0)
    data = _scenario_dict("superquadrics", 3, ([-25] * 3, [25] * 3), THREE_BODIES, obstacles)
    return parse_scenario(data, check=False)


@pytest.mark.parametrize("name", ["slanted_gap", "l_robot_door", "open_space", "superquadrics"])
def test_warm_started_queries_answer_as_cold_ones(name):
    """Every narrow-phase query starts GJK where its pair's last one ended. Along random
    walks (the coherence of a planner's queries) and random jumps, the warm world's
    collision verdicts equal those of a world built afresh for every pose, its distances
    and region clearances agree to GJK's tolerance, and its region planes are the same
    pieces."""
    scenario = _superquadric_world() if name == "superquadrics" else _scenario(name)
    fcl_world = CollisionWorld(scenario)
    build = _kernel.build_kernel_world  # a new world: every pair starts cold
    args = (scenario, fcl_world.robot, fcl_world._half_height)
    warm = build(*args)
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    n = scenario.dimension
    horizon = float(fcl_world.robot.largest_semi_axis)
    low, high = scenario.bounds
    step_length = 0.03 * float(np.ptp(scenario.bounds, axis=0).max())
    hits = planes = 0
    for step in range(240):
        if step % 40 == 0:  # a jump: warm starts from far away
            pose = np.concatenate([rng.uniform(low, high), random_pose(rng, n, 0, 1)[n:]])
        else:
            pose = np.concatenate([pose[:n] + rng.normal(0.0, step_length, n), _turn(rng, pose, n)])
        p = pose.tolist()
        cold = build(*args)
        hit = warm.in_collision(p)
        assert hit == cold.in_collision(p), (step, p)
        hits += hit
        d_warm, d_cold = np.array(warm.body_distances(p)), np.array(build(*args).body_distances(p))
        np.testing.assert_allclose(d_warm, d_cold, rtol=1e-5, atol=1e-6, err_msg=str(p))
        free_warm, regions_warm = warm.free_regions(p, horizon)
        free_cold, regions_cold = build(*args).free_regions(p, horizon)
        assert free_warm == free_cold
        for (pw, hw), (pc, hc) in zip(regions_warm, regions_cold, strict=True):
            assert len(pw) == len(pc)
            assert hw == pytest.approx(hc, rel=1e-5, abs=1e-6)
            for a, b in zip(pw, pc, strict=True):
                assert a[4] == pytest.approx(b[4], rel=1e-5, abs=1e-6)  # clearance
                planes += 1
    assert 0 < hits < 240 and planes > 0  # both kinds of pose, and planes, were met


@pytest.mark.parametrize("e, axes", [(0.3, [6, 3, 2]), (1.0, [4, 4, 1])])
def test_region_planes_hold_the_full_scans_support(e, axes):
    """A region plane's offset is the exact support of its piece along the plane's normal
    (the plane holds the piece whatever the direction): for one superquadric polytope of
    about 1,000 vertices it is, at every pose, the maximum of ``n . x`` over all its
    vertices."""
    vertices = bounding_polytopes(axes, e, count=500).outer
    obstacles = [{"convex": {"vertices": vertices.tolist()}}]
    data = _scenario_dict("one piece", 3, ([-25] * 3, [25] * 3), THREE_BODIES, obstacles)
    scenario = parse_scenario(data, check=False)
    world = CollisionWorld(scenario).kernel
    rng = np.random.default_rng(len(vertices))
    planes = 0
    for _ in range(300):
        pose = np.concatenate([rng.uniform(-16, 16, 3), random_pose(rng, 3, 0, 1)[3:]])
        free, regions = world.free_regions(pose.tolist(), 30.0)
        for rows, _horizon in regions if free else ():
            for nx, ny, nz, offset, _clearance in rows:
                scan = vertices[:, 0] * nx + vertices[:, 1] * ny + vertices[:, 2] * nz
                assert offset == pytest.approx(scan.max(), rel=1e-14, abs=1e-13)
                planes += 1
    assert planes > 300


def _arena_world(directory: Path) -> Scenario:
    """Three ellipsoids inside a convex arena mesh (an icosphere stretched to 40 x 24 x 16
    semi-axes, 1,280 triangles, as HRM's inscribed arenas), with a box, a ball and a
    wall inside: where the kernel reads distances off the mesh's planes."""
    arena = trimesh.creation.icosphere(subdivisions=3)
    arena.apply_scale([40.0, 24.0, 16.0])
    arena.export(directory / "arena.stl")
    obstacles = [
        {"mesh": {"file": "arena.stl"}},
        {"box": {"center": [10, 0, 0], "size": [4, 6, 3], "quaternion": _unit([0.2, 0.1, 0.3, 1])}},
        {"sphere": {"center": [-12, 5, -2], "radius": 3}},
        {"box": {"center": [-2, -8, 0], "size": [0.1, 8, 10]}},
    ]
    data = _scenario_dict("arena", 3, ([-36, -20, -13], [36, 20, 13]), THREE_BODIES, obstacles)
    return parse_scenario(data, directory=directory, check=False)


def test_distances_read_off_a_convex_arena_agree_with_python_fcl(tmp_path):
    """Inside a convex mesh the kernel proves bodies clear, and measures them, on the
    triangles' planes instead of coal's BVH: its verdicts are python-fcl's (away from
    contact), its distances python-fcl's to FCL's error, and never above them by more
    than that error (a clearance must not be overestimated)."""
    scenario = _arena_world(tmp_path)
    world = CollisionWorld(scenario)
    rng = np.random.default_rng(5)
    low, high = scenario.bounds
    near = 1e-6 * float(np.ptp(scenario.bounds, axis=0).max())
    hits = close_calls = 0
    for _ in range(1500):
        pose = np.concatenate([rng.uniform(low, high), random_pose(rng, 3, 0, 1)[3:]])
        fcl_free = not world.in_collision(pose)
        compiled = world.kernel.in_collision(pose.tolist())
        fcl_d = world.body_clearances(pose)
        if not fcl_free:
            hits += 1
            assert compiled, pose
            continue
        if fcl_d.min() > near:
            assert not compiled, pose
        kernel_d = np.array(world.kernel.body_distances(pose.tolist()))
        allowance = 2 * CLEARANCE_RTOL * fcl_d + 1e-6
        np.testing.assert_array_less(kernel_d, fcl_d + allowance, err_msg=str(pose))
        np.testing.assert_array_less(fcl_d, kernel_d + allowance, err_msg=str(pose))
        close_calls += int(np.any(kernel_d < 6.0))
    assert 0 < hits < 1500 and close_calls > 100


@pytest.mark.parametrize("share", [0.25, pytest.param(1.0, marks=pytest.mark.study)])
@pytest.mark.parametrize(
    "name",  # the ablations' agreement a study (.ci/run runs it), kcplan's sets in the suite
    [
        pytest.param(k, marks=pytest.mark.study) if k in ("ca", "kc-paper") else k
        for k in sorted(SETS)
    ],  # fmt: skip
)
def test_kernel_and_python_certifiers_agree_edge_by_edge(name, share):
    """Both certifiers on one CollisionWorld, the same edges in the same order: at least
    99.5 % identical decisions per certificate set, every edge either accepts is free
    (gap-free on python-fcl), and their counters tell the same story. The suite takes the
    first quarter of each world's edges; the study (``-m study``) all of them."""
    kinds = SETS[name]
    total = agreed = 0
    accepted = {"python": 0, "kernel": 0}
    report, bad, gaps = [], [], {}
    for world_name in WORLDS:
        scenario = _scenario(world_name)
        if "polytope" in kinds and not scenario.robot.is_single:
            continue  # the paper's bound is for one body at the origin: refused (tested below)
        world = CollisionWorld(scenario)
        ladder = GuardLadder(scenario.robot.semi_axes) if "polytope" in kinds else None
        python = EdgeCertifier(world, certificates=kinds, ladder=ladder)
        kernel = KernelCertifier(world, certificates=kinds, ladder=ladder)
        edges = _edges(world_name)
        edges = edges[: math.ceil(share * len(edges))]
        py = np.array([python.check(p1, p2) for p1, p2 in edges])
        kc = np.array([kernel.check(p1, p2) for p1, p2 in edges])
        differ = np.flatnonzero(py != kc)
        total += len(edges)
        agreed += len(edges) - len(differ)
        accepted["python"] += int(py.sum())
        accepted["kernel"] += int(kc.sum())
        report.append(
            f"{world_name}: {len(edges)} edges, agree {1 - len(differ) / len(edges):.4%}, "
            f"accepted python {py.sum()} kernel {kc.sum()}"
        )
        for i in differ[:5]:
            p1, p2 = edges[i]
            check = verify_path(world, [p1, p2])
            report.append(
                f"  differ at edge {i}: python {py[i]}, kernel {kc[i]}, verify collides "
                f"{check.collides} (min clearance {check.min_clearance:.3g}), "
                f"{p1.tolist()} -> {p2.tolist()}"
            )
        for i in np.flatnonzero(py | kc):
            p1, p2 = edges[i]
            if verify_path(world, [p1, p2]).collides:
                bad.append((world_name, int(i), bool(py[i]), bool(kc[i])))
        # the same run, counted: every edge once, every rejection with one reason
        cp, ck = python.counters, kernel.counters
        for c, decided in ((cp, py), (ck, kc)):
            assert c["edges"] == len(edges)
            assert c["rejected"] == int((~decided).sum())
            reasons = [k for k in COUNTER_NAMES if k.startswith("rejected_") or k == "not_proven"]
            assert sum(c[k] for k in reasons) == c["rejected"]
        gap = _counter_gap(cp, ck)
        if gap:
            gaps[world_name] = gap
        assert kernel.covered.keys() == python.covered.keys()
        for k, covered in python.covered.items():
            assert kernel.covered[k] == pytest.approx(covered, rel=0.02, abs=1.0)
    summary = "\n".join(
        [f"{name} {kinds}: {total} edges, agree {agreed / total:.4%}, accepted {accepted}"]
        + report
        + [f"counters apart: {gaps}"]
    )
    print(summary)
    assert total >= share * MIN_EDGES, summary
    assert agreed >= MIN_AGREEMENT * total, summary
    assert not bad, f"accepted edges that collide (world, edge, python, kernel): {bad}"
    assert not gaps, summary
    # the edges are not trivial: both accept and reject plenty
    assert 0.2 * total < accepted["kernel"] < 0.9 * total, summary


# ------------------------------------------------------------------ 2. non-finite poses


def _fields(n: int) -> list[str]:
    return ["x", "y", "yaw"] if n == 2 else ["x", "y", "z", "qx", "qy", "qz", "qw"]


def _set_field(state, n: int, field: str, value: float) -> None:
    """``state.setX(value)`` ... ``state.setYaw(value)``, or ``state.rotation().x = value``
    ... for ``qx`` ... ``qw``."""
    if field.startswith("q"):
        setattr(state.rotation(), field[1], value)
    else:
        getattr(state, "set" + field.capitalize())(value)


@pytest.mark.parametrize("backend", ["kernel", "python"])
@pytest.mark.parametrize("path", ["2d/random_clutter", "3d/box_field", "2d/l_robot_door"])
def test_a_pose_that_is_not_finite_is_never_free_through_ompl(path, backend):
    """Real OMPL states with a NaN or an infinity in any field (or a zero quaternion):
    checkMotion rejects the edge both ways, the state is invalid, through the validator
    and through SpaceInformation, and the validator carries on (no stored error)."""
    scenario = load_scenario(ROOT / "scenarios" / f"{path}.yaml")
    n = scenario.dimension
    world = CollisionWorld(scenario)
    si = ob.SpaceInformation(state_space(*scenario.bounds))
    mv = KCMotionValidator(si, world.robot, world, backend=backend)
    try:
        si.setMotionValidator(mv)
        si.setStateValidityChecker(mv.state_valid)
        si.setup()
        start, near = si.allocState(), si.allocState()
        set_state(start, scenario.start, n)
        step = scenario.start.copy()
        step[0] += 0.5
        set_state(near, step, n)
        assert mv.state_valid(start) and mv.checkMotion(start, near)
        rejected = 0
        for field in _fields(n):
            for value in (NAN, INF, -INF):
                bad = si.allocState()
                set_state(bad, scenario.start, n)
                _set_field(bad, n, field, value)
                assert mv.checkMotion(start, bad) is False, (field, value)
                assert mv.checkMotion(bad, start) is False, (field, value)
                assert si.checkMotion(start, bad) is False, (field, value)
                assert mv.state_valid(bad) is False and si.isValid(bad) is False
                rejected += 3
        if n == 3:
            zero = si.allocState()
            set_state(zero, scenario.start, n)
            for field in ("qx", "qy", "qz", "qw"):
                _set_field(zero, n, field, 0.0)
            assert mv.checkMotion(start, zero) is False and mv.state_valid(zero) is False
            rejected += 1
        assert mv.error is None
        assert mv.checkMotion(start, near) and mv.checkMotion(near, start)
        assert mv.counters["rejected_end_state"] == rejected
        assert mv.counters["rejected"] == rejected
    finally:
        mv.close()


@pytest.mark.parametrize("path", ["2d/random_clutter", "3d/box_field", "2d/l_robot_door"])
def test_kernel_rejects_poses_that_are_not_finite_and_world_queries_refuse_them(path):
    scenario = load_scenario(ROOT / "scenarios" / f"{path}.yaml")
    world = CollisionWorld(scenario)
    certifier = KernelCertifier(world)
    python = EdgeCertifier(world)
    good = scenario.start
    near = good.copy()
    near[0] += 0.5
    assert certifier.check(good, near) and python.check(good, near)
    kernel_world = world.kernel
    for i in range(len(good)):
        for value in (NAN, INF, -INF):
            bad = good.copy()
            bad[i] = value
            for c in (certifier, python):
                assert c.check(good, bad) is False and c.check(bad, good) is False
                assert c.check(bad, bad) is False and c.state_valid(bad) is False
            with pytest.raises(ValueError, match="finite"):
                kernel_world.in_collision(bad.tolist())
            with pytest.raises(ValueError, match="finite"):
                kernel_world.safe_body_clearances(bad.tolist())
            with pytest.raises(ValueError, match="finite"):
                kernel_world.free_regions(bad.tolist(), 1.0)
            with pytest.raises(ValueError, match="finite"):
                certifier.measure(bad)
    if scenario.dimension == 3:
        zero = np.concatenate([good[:3], np.zeros(4)])
        assert not certifier.check(good, zero) and not certifier.state_valid(zero)
        with pytest.raises(ValueError, match="finite"):
            kernel_world.in_collision(zero.tolist())
        args = [*good.tolist(), *good[:3].tolist(), 0.0, 0.0, NAN, 1.0]
        assert certifier.check_se3(*args, 0.01) is False
        assert certifier.state_valid_se3(*args[7:]) is False
    else:
        assert certifier.check_se2(*good.tolist(), good[0], NAN, good[2]) is False
        assert certifier.state_valid_se2(INF, good[1], good[2]) is False
    expected = 3 * 3 * len(good)  # three edges per bad value and position
    assert python.counters["rejected"] == python.counters["rejected_end_state"] == expected
    extra = 2 if scenario.dimension == 3 else 1
    assert certifier.counters["rejected"] == certifier.counters["rejected_end_state"]
    assert certifier.counters["rejected"] == expected + extra
    assert certifier.check(good, near)  # nothing sticks


MAGNITUDES = (1e10, 1e100, 1e154, 1e200, 1e308, -1e308)
"""Finite numbers whose squares, products or sums overflow (issue 26, item 1)."""


def _closed_room(n: int) -> Scenario:
    """A robot inside a closed room [0, 24]^n: every edge that leaves it crosses a wall."""
    walls = []
    for axis in range(n):
        for side in (-0.5, 24.5):
            centre, size = [12.0] * n, [26.0] * n
            centre[axis], size[axis] = side, 1.0
            walls.append({"box": {"center": centre, "size": size}})
    robot = {"semi_axes": [1.0, 0.5] if n == 2 else [1.0, 0.5, 0.4]}
    data = _scenario_dict("room", n, ([0.0] * n, [24.0] * n), robot, walls)
    return parse_scenario(data, check=False)


@pytest.mark.parametrize("backend", ["kernel", "python"])
@pytest.mark.parametrize("n", [2, 3])
def test_no_magnitude_of_any_coordinate_certifies_an_edge_through_a_wall(n, backend):
    """The fault table: from the middle of a closed room, an edge to a pose with one field
    at each of MAGNITUDES, in a fresh validator each time, through OMPL states. A
    translation that leaves the room crosses a wall, so it must be rejected (both ways,
    and the state is invalid); a rotation field may be decided either way (the robot
    turns in place, 11 from every wall with a reach of 1), but never raises or stores an
    error."""
    scenario = _closed_room(n)
    fields = _fields(n)
    decided = {}
    for value in MAGNITUDES:
        for field in fields:
            world = CollisionWorld(scenario)
            si = ob.SpaceInformation(state_space(*scenario.bounds))
            mv = KCMotionValidator(si, world.robot, world, backend=backend)
            try:
                start, bad = si.allocState(), si.allocState()
                middle = np.array([12.0] * n + ([0.3] if n == 2 else [0.0, 0.0, 0.0, 1.0]))
                set_state(start, middle, n)
                set_state(bad, middle, n)
                _set_field(bad, n, field, value)
                forward, backward = mv.checkMotion(start, bad), mv.checkMotion(bad, start)
                valid = mv.state_valid(bad)
                assert mv.error is None, (field, value, mv.error)
                if field in ("x", "y", "z"):
                    assert (forward, backward, valid) == (False, False, False), (field, value)
                decided[field, value] = forward
            finally:
                mv.close()
    assert len(decided) == len(fields) * len(MAGNITUDES)


@pytest.mark.parametrize("n", [2, 3])
def test_the_pose_domain_twins_admit_the_same_poses(n):
    """kcplan/_kernel/domain.hpp and kcplan/certification/domain.py: the same box (bounds padded
    by their diagonal and the robot's reach), yaw range and quaternion norms, on poses
    just inside and just outside each limit, through the certifiers' state checks."""
    scenario = _closed_room(n)
    world = CollisionWorld(scenario)
    kernel, python = KernelCertifier(world), EdgeCertifier(world)
    pad = math.hypot(*([24.0] * n)) + world.robot.reach
    assert python.domain.high[0] == pytest.approx(24.0 + pad)
    middle = [12.0] * n + ([0.3] if n == 2 else [0.0, 0.0, 0.0, 1.0])
    cases = []
    for k in range(n):
        for edge, inside in ((-pad, True), (-pad - 1e-6, False), (24 + pad, True),
                             (24 + pad + 1e-6, False)):  # fmt: skip
            p = list(middle)
            p[k] = edge
            cases.append((p, inside))
    if n == 2:
        cases += [(middle[:2] + [2 * math.pi], True), (middle[:2] + [6.3], False)]
    else:
        for scale, inside in ((1e-99, True), (1e-101, False), (1e99, True), (1e101, False)):
            cases.append((middle[:3] + [0.0, 0.0, 0.0, scale], inside))
    for pose, inside in cases:
        assert python.domain.admits(pose) is inside, pose
        if not inside:  # outside: never free, and no query is spent on it
            before = world.kernel.counters["collision_queries"]
            assert kernel.state_valid(pose) is False and python.state_valid(pose) is False
            assert world.kernel.counters["collision_queries"] == before
    with pytest.raises(ValueError, match="bounds"):
        PoseDomain(n, [0.0] * n, [1e100] * n)
    with pytest.raises(ValueError, match="bounds"):
        PoseDomain(n, [1.0] * n, [0.0] * n)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_fuzzed_edges_with_huge_numbers_are_never_certified_outside_the_domain(data):
    """Edges from inside the closed room to poses with any fields drawn from every float
    magnitude: both backends decide them alike, never raise, and accept only edges whose
    end stays inside the room's walls, verified free without gaps by python-fcl."""
    n = data.draw(st.sampled_from([2, 3]))
    scenario = _closed_room(n)
    world = CollisionWorld(scenario)
    kernel, python = KernelCertifier(world), EdgeCertifier(world)
    huge = st.floats(allow_nan=False, allow_infinity=False) | st.sampled_from(MAGNITUDES)
    middle = [12.0] * n + ([0.3] if n == 2 else [0.0, 0.0, 0.0, 1.0])
    for _ in range(5):
        p2 = list(middle)
        for k in data.draw(st.sets(st.integers(0, len(middle) - 1), min_size=1)):
            p2[k] = data.draw(huge)
        decisions = kernel.check(middle, p2), python.check(middle, p2)
        if not python.domain.admits(p2):
            assert decisions == (False, False), p2
        if any(decisions):
            assert all(0.0 < x < 24.0 for x in p2[:n]), p2
            assert not verify_path(world, [middle, p2]).collides, p2


def _turn_past_a_pin(backend: str, probes: int):
    """A 4 x 0.6 ellipse at (5, 5) turning from yaw -pi/4 to pi/4 past a pin at (6.9, 5):
    both ends are free and the core (radius 0.3) does not move, but at yaw 0 the tip
    (7, 5) is inside the pin."""
    data = _scenario_dict(
        "pin", 2, ([0.0, 0.0], [10.0, 10.0]), {"semi_axes": [2.0, 0.3]},
        [{"circle": {"center": [6.9, 5.0], "radius": 0.15}}],
    )  # fmt: skip
    world = CollisionWorld(parse_scenario(data, check=False))
    cls = KernelCertifier if backend == "kernel" else EdgeCertifier
    return world, cls(world, probes=probes)


@pytest.mark.parametrize("backend", ["kernel", "python"])
def test_a_colliding_probe_rejects_before_any_guard(backend):
    """Step 3's probes: the edge's middle collides, so the first probe (s = 1/2) rejects
    it with one collision query and no guard; without probes the same edge costs guards
    before it is rejected, and both decisions agree with the gap-free check."""
    p1, p2 = [5.0, 5.0, -math.pi / 4], [5.0, 5.0, math.pi / 4]
    world, certifier = _turn_past_a_pin(backend, probes=3)
    assert verify_path(world, [p1, p2]).collides
    assert certifier.state_valid(p1) and certifier.state_valid(p2)
    before = world.counters["collision_queries"]
    assert not certifier.check(p1, p2)
    c = certifier.counters
    assert (c["rejected_probe"], c["probes"], c["guards"]) == (1, 1, 0)
    assert world.counters["collision_queries"] == before + 2  # the core sweep, one probe
    world, certifier = _turn_past_a_pin(backend, probes=0)
    assert not certifier.check(p1, p2)
    c = certifier.counters
    assert c["rejected_probe"] == c["probes"] == 0 and c["guards"] >= 2
    assert c["rejected_guard"] + c["not_proven"] == 1
    with pytest.raises(ValueError, match="probes"):
        _turn_past_a_pin(backend, probes=-1)


def test_probes_stop_where_they_do_not_reject():
    """The schedule (PROBE_WARMUP, PROBE_ODDS, PROBE_EVERY): where no probe rejects, the
    first PROBE_WARMUP edges that reach the probes are probed, then every PROBE_EVERY-th;
    both twins keep the same schedule."""
    counters = []
    for backend in ("kernel", "python"):
        world, certifier = _turn_past_a_pin(backend, probes=3)
        rng = np.random.default_rng(4)
        for _ in range(1500):
            p1 = [*rng.uniform(2.5, 3.5, 2), rng.uniform(-3, 3)]  # far from the pin
            p2 = [*rng.uniform(2.5, 3.5, 2), rng.uniform(-3, 3)]
            certifier.check(p1, p2)
        counters.append(certifier.counters)
    kernel, python = counters
    for c in counters:
        assert c["rejected_probe"] == 0 and c["probes"] == 3 * c["probed_edges"]
        # no edge is decided before the probes (no cached guard, nothing rejected)
        assert c["cached_guards"] == 0 and c["rejected"] == 0
        assert c["probed_edges"] == PROBE_WARMUP + (c["edges"] - PROBE_WARMUP) // PROBE_EVERY
    assert kernel == python


def test_grid_cells_are_learned_while_they_pay():
    """The occupancy grid's schedule (LEARN_WARMUP, LEARN_ODDS, LEARN_EVERY): where the
    colliding states hardly ever fall into a tested cell again, the grid tests the cell
    of the first LEARN_WARMUP colliding states and then of every LEARN_EVERY-th; where
    they come back to the same cells, the cell of every one. Both twins keep the same
    schedule; ``learn_schedule=False`` tests every cell."""
    data = _scenario_dict(
        "floor", 2, ([0.0, 0.0], [400.0, 200.0]), {"semi_axes": [2.0, 1.0]},
        [{"box": {"center": [200.0, 50.0], "size": [400.0, 100.0]}}],
    )  # fmt: skip
    world = CollisionWorld(parse_scenario(data, check=False))
    rng = np.random.default_rng(6)
    spread = [[*rng.uniform([5, 5], [395, 95]), 0.0] for _ in range(2000)]  # all collide
    counters = {}
    for backend, cls in (("kernel", KernelCertifier), ("python", EdgeCertifier)):
        for schedule in (True, False):
            certifier = cls(world, learn_schedule=schedule)
            assert not any(certifier.state_valid(p) for p in spread)
            counters[backend, schedule] = certifier.counters
    assert counters["kernel", True] == counters["python", True]
    assert counters["kernel", False] == counters["python", False]
    paid, every = counters["kernel", True], counters["kernel", False]
    assert every["occupancy_rejections"] * LEARN_ODDS < every["occupancy_queries"]
    assert every["occupancy_queries"] > 1900  # a cell tested for nearly every state
    assert LEARN_WARMUP + 1700 // LEARN_EVERY < paid["occupancy_queries"]
    assert paid["occupancy_queries"] <= LEARN_WARMUP + 1750 // LEARN_EVERY
    # states that come back to a few cells: the grid pays, every cell is tested
    back = [[*rng.uniform([5, 5], [25, 25]), 0.0] for _ in range(2000)]
    certifier = KernelCertifier(world)
    assert not any(certifier.state_valid(p) for p in back)
    c = certifier.counters
    assert c["occupancy_rejections"] * LEARN_ODDS >= c["occupancy_queries"] > 100


def test_probe_points_halve_the_largest_stretch_left():
    assert probe_points(7) == [0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875]
    for count in range(1, 64):
        points = sorted([0.0, *probe_points(count), 1.0])
        gaps = np.diff(points)
        assert len(set(points)) == count + 2 and gaps.max() <= 2 * gaps.min() + 1e-15


# ------------------------------------------------------------------ 3. errors


def _world_2d(obstacles=()) -> KernelWorld:
    world = KernelWorld(KernelRobot(2, [1.0, 0.5], [0.0, 0.0, 0.0]), 1.0, 2e-3, 1e-6)
    for centre, radius in obstacles:
        world.add_sphere(centre, radius)
    return world


def test_wrong_pose_lengths_are_refused_with_the_expected_count():
    s2 = load_scenario(ROOT / "scenarios" / "2d" / "open_field.yaml")
    s3 = load_scenario(ROOT / "scenarios" / "3d" / "open_space.yaml")
    for scenario, size in ((s2, 3), (s3, 7)):
        world = CollisionWorld(scenario)
        certifier = KernelCertifier(world)
        good = scenario.start.tolist()
        for wrong in ([], [1.0], good[:-1], [*good, 0.0], [0.0] * 10):
            message = f"expected {size} numbers in {scenario.dimension}D, got {len(wrong)}"
            with pytest.raises(ValueError, match=message):
                world.kernel.in_collision(wrong)
            with pytest.raises(ValueError, match=message):
                world.kernel.body_distances(wrong)
            with pytest.raises(ValueError, match=message):
                certifier.check(good, wrong)
            with pytest.raises(ValueError, match=message):
                certifier.check(wrong, good)
            with pytest.raises(ValueError, match=message):
                certifier.state_valid(wrong)
        other = "se3" if size == 3 else "se2"
        with pytest.raises(ValueError, match=f"this world is {scenario.dimension}D"):
            getattr(world.kernel, f"in_collision_{other}")(*([0.0] * (10 - size)))
        with pytest.raises(ValueError, match=f"this world is {scenario.dimension}D"):
            getattr(certifier, f"state_valid_{other}")(*([0.0] * (10 - size)))
        with pytest.raises(ValueError, match="horizon: expected a number >= 0"):
            world.kernel.free_regions(good, -1.0)
        assert certifier.counters["edges"] == 0  # a refused call decides nothing


@pytest.mark.parametrize(
    "dimension, semi_axes, poses, message",
    [
        (2, [0.0, 1.0], [0, 0, 0], "positive finite"),
        (2, [1.0, -1.0], [0, 0, 0], "positive finite"),
        (2, [NAN, 1.0], [0, 0, 0], "positive finite"),
        (2, [INF, 1.0], [0, 0, 0], "positive finite"),
        (3, [1.0, 1.0, 0.0], [0, 0, 0, 0, 0, 0, 1], "positive finite"),
        (3, [1.0, 1.0, -1e-300], [0, 0, 0, 0, 0, 0, 1], "positive finite"),
        (2, [1.0, 1.0, 1.0], [0, 0, 0], "expected 2 semi-axes and 3 pose numbers per body"),
        (2, [1.0, 1.0], [0, 0], "expected 2 semi-axes and 3 pose numbers per body"),
        (2, [], [], "expected 2 semi-axes"),
        (3, [1.0, 1.0, 1.0], [0, 0, 0], "expected 3 semi-axes and 7 pose numbers per body"),
        (2, [1.0, 1.0], [NAN, 0, 0], "body poses must be finite"),
        (3, [1.0, 1.0, 1.0], [0, 0, 0, 0, 0, 0, 0], "body poses must be finite"),
        (4, [1.0] * 4, [0.0] * 9, "dimension: expected 2 or 3, got 4"),
        (2, [1.0, 1.0] * 33, [0.0] * 99, "at most 32 bodies, got 33"),
    ],
)
def test_degenerate_robots_are_refused(dimension, semi_axes, poses, message):
    with pytest.raises(ValueError, match=message):
        KernelRobot(dimension, semi_axes, poses)


def test_degenerate_obstacles_and_world_options_are_refused():
    robot = KernelRobot(2, [1.0, 0.5], [0.0, 0.0, 0.0])
    for half_height, rtol, atol in ((0.0, 0.0, 0.0), (1.0, 1.0, 0.0), (1.0, 0.0, -1.0),
                                    (NAN, 0.0, 0.0), (1.0, 0.0, INF)):  # fmt: skip
        with pytest.raises(ValueError, match="expected half_height > 0"):
            KernelWorld(robot, half_height, rtol, atol)
    world = _world_2d()
    I3 = [1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0]
    cube = [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]
    faces = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]
    cases = [
        (world.add_prism, ([0.0, 0.0, 1.0, 0.0],), "at least 3 points"),
        (world.add_prism, ([0.0, 0.0, 1.0, 0.0, 1.0],), "at least 3 points"),
        (world.add_prism, ([0.0, 0.0, 1.0, 0.0, NAN, 1.0],), "prism: expected finite"),
        (world.add_convex, (cube, [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 4]), "index out of range"),
        (world.add_convex, (cube, [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, -1]), "index out of range"),
        (world.add_convex, (cube, faces[:9]), "at least 4 vertices and 4 triangles"),
        (world.add_convex, (cube[:-1], faces), "expected m x 3 vertices"),
        (world.add_mesh, (cube, [0, 1, 7]), "mesh: triangle index out of range"),
        (world.add_mesh, (cube, []), "mesh: expected m x 3 vertices and t x 3 triangles"),
        (world.add_sphere, ([0.0, 0.0, 0.0], 0.0), "positive finite radius"),
        (world.add_sphere, ([0.0, 0.0, 0.0], -1.0), "positive finite radius"),
        (world.add_sphere, ([0.0, 0.0, 0.0], INF), "positive finite radius"),
        (world.add_sphere, ([NAN, 0.0, 0.0], 1.0), "sphere: expected finite"),
        (world.add_box, ([0.0, 0.0, 0.0], I3, [1.0, 0.0, 1.0]), "positive finite half sides"),
        (world.add_box, ([0.0, 0.0, 0.0], [NAN] * 9, [1.0] * 3), "box: expected finite"),
        (world.add_ellipsoid, ([0.0] * 3, I3, [1.0, -1.0, 1.0]), "positive finite semi-axes"),
    ]
    for method, args, message in cases:
        with pytest.raises(ValueError, match=message):
            method(*args)
    assert world.n_objects == 0  # nothing half-added
    with pytest.raises(ValueError, match="radius: expected a positive number"):
        world.ball_collides([0.0, 0.0, 0.0], 0.0)
    with pytest.raises(ValueError, match="radius: expected a positive number"):
        world.sweep_core_collides([0.0] * 3, [1.0, 0.0, 0.0], -1.0)
    with pytest.raises(ValueError, match="sweep: expected finite"):
        world.sweep_core_collides([0.0] * 3, [INF, 0.0, 0.0], 1.0)


def _compiled(world, certificates=("region",), max_guards=64, cache=100, ladder=([], [], 1.0)):
    return CompiledCertifier(
        world, list(certificates), False, max_guards, -1.0, True, True, 3,
        [-10.0] * 3, [10.0] * 3, cache, *ladder,
    )  # fmt: skip


def test_unknown_or_unfit_certificates_are_refused():
    scenario = load_scenario(ROOT / "scenarios" / "2d" / "l_robot_door.yaml")
    world = CollisionWorld(scenario)
    for certificates in (("nope",), ("ball", "Region"), ()):
        for make in (KernelCertifier, EdgeCertifier):
            with pytest.raises(ValueError, match="certificates: expected names from"):
                make(world, certificates=certificates)
    for make in (KernelCertifier, EdgeCertifier):
        with pytest.raises(ValueError, match="'polytope' .* needs one body"):
            make(world, certificates=("polytope",))
        with pytest.raises(ValueError, match="fallback: expected 'bisection' or 'discrete'"):
            make(world, fallback="sampling")
    kernel_world = _world_2d([([3.0, 0.0, 0.0], 1.0)])
    with pytest.raises(ValueError, match="expected names from .* got 'nope'"):
        _compiled(kernel_world, ("ball", "nope"))
    with pytest.raises(ValueError, match="certificates: expected names"):
        _compiled(kernel_world, ())
    with pytest.raises(ValueError, match="'polytope' needs a ladder"):
        _compiled(kernel_world, ("polytope",))
    with pytest.raises(ValueError, match="ladder: expected one row block per level"):
        _compiled(kernel_world, ("polytope",), ladder=([0.1, 0.2], [[1.0, 0.0, 0.0]], 1.0))
    with pytest.raises(ValueError, match="ladder: levels must increase"):
        _compiled(kernel_world, ("polytope",), ladder=([0.2, 0.1], [[1.0, 0, 0]] * 2, 1.0))
    with pytest.raises(ValueError, match="max_guards: expected a number >= 0"):
        _compiled(kernel_world, max_guards=-1)
    with pytest.raises(ValueError, match="max_entries: expected at least 1"):
        _compiled(kernel_world, cache=0)
    with pytest.raises(TypeError):
        _compiled(kernel_world, cache=-1)
    discrete = CompiledCertifier(
        kernel_world, ["ball"], True, 64, -1.0, False, False, 0, [-10.0] * 3, [10.0] * 3, 100,
        [], [], 1.0,
    )  # fmt: skip
    with pytest.raises(ValueError, match="resolution: expected a positive number"):
        discrete.check([0.0, 0.0, 0.0], [6.0, 0.0, 0.0], 0.0)


# ------------------------------------------------------------------ 4. fuzz

OK_ERRORS = (ValueError, TypeError)

wild = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 1.0, -1.0, 0.5, 1e300, -1e300, 1e-300, NAN, INF, -INF]),
    st.floats(-20.0, 20.0),
)
wild_list = st.lists(wild, max_size=10)
indices = st.lists(st.one_of(st.integers(-2, 12), st.just(2**40)), max_size=15)


def _call(f, *args):
    """``f(*args)``, or None when it raised one of the errors a bad argument may raise."""
    try:
        return f(*args)
    except OK_ERRORS:
        return None


def _finite(values) -> bool:
    return all(math.isfinite(v) for v in values)


def _kernel_robot(data) -> KernelRobot:
    """A fuzzed robot when the draw makes one, else a valid one of 1 to 3 bodies."""
    robot = _call(KernelRobot, data.draw(st.sampled_from([2, 3, 1, 4, 0])), data.draw(wild_list),
                  data.draw(wild_list))  # fmt: skip
    if robot is not None:
        return robot
    n = data.draw(st.sampled_from([2, 3]))
    bodies = data.draw(st.integers(1, 3))
    axes = data.draw(st.lists(st.floats(0.05, 5.0), min_size=n * bodies, max_size=n * bodies))
    size = 3 if n == 2 else 7
    poses = data.draw(st.lists(st.floats(-3, 3), min_size=size * bodies, max_size=size * bodies))
    if n == 3:
        for k in range(bodies):
            poses[size * k + 6] += 4.0  # a quaternion that can be normalised
    return KernelRobot(n, axes, poses)


def _check_pose_query(world: KernelWorld, bodies: int, pose: list, kind: str, horizon: float):
    size = 3 if world.dimension == 2 else 7
    finite = len(pose) == size and _finite(pose)
    if kind == "collision":
        result = _call(world.in_collision, pose)
        assert result is None or isinstance(result, bool)
    elif kind == "distances":
        result = _call(world.body_distances, pose)
        if result is not None:  # never NaN, never negative
            assert len(result) == bodies
            assert all(d >= 0.0 for d in result), result
    else:
        result = _call(world.free_regions, pose, horizon)
        if result is not None:
            free, regions = result
            assert isinstance(free, bool) and len(regions) == bodies
    if not finite and len(pose) == size:
        assert result is None  # a pose that is not finite is refused, never answered


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_fuzzed_kernel_world_calls_return_or_raise_value_errors(data):
    """Random robots, obstacles (degenerate and huge included) and queries, in any order:
    every call returns or raises ValueError/TypeError; the process never aborts."""
    robot = _kernel_robot(data)
    world = _call(KernelWorld, robot, data.draw(wild), data.draw(wild), data.draw(wild))
    if world is None:
        world = KernelWorld(robot, 1.0, 2e-3, 1e-6)
    vec3 = st.lists(wild, min_size=3, max_size=3) | st.lists(wild, max_size=4)
    ops = st.sampled_from(
        ["prism", "box", "convex", "sphere", "ellipsoid", "mesh", "finalize", "collision",
         "distances", "regions", "ball", "sweep", "se2", "se3", "reset"]
    )  # fmt: skip
    for op in data.draw(st.lists(ops, max_size=12)):
        if op == "prism":
            _call(world.add_prism, data.draw(wild_list))
        elif op in ("box", "ellipsoid"):
            rotation = data.draw(st.lists(wild, min_size=9, max_size=9) | st.just(
                [1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0]))  # fmt: skip
            method = world.add_box if op == "box" else world.add_ellipsoid
            _call(method, data.draw(vec3), rotation, data.draw(vec3))
        elif op in ("convex", "mesh"):
            method = world.add_convex if op == "convex" else world.add_mesh
            _call(method, data.draw(st.lists(wild, max_size=18)), data.draw(indices))
        elif op == "sphere":
            _call(world.add_sphere, data.draw(vec3), data.draw(wild))
        elif op == "finalize":
            world.finalize()
        elif op in ("collision", "distances", "regions"):
            size = 3 if world.dimension == 2 else 7
            pose = data.draw(st.lists(wild, min_size=size, max_size=size) | wild_list)
            _check_pose_query(world, len(robot), pose, op, data.draw(wild))
        elif op == "ball":
            result = _call(world.ball_collides, data.draw(vec3), data.draw(wild))
            assert result is None or isinstance(result, bool)
        elif op == "sweep":
            result = _call(world.sweep_core_collides, data.draw(vec3), data.draw(vec3),
                           data.draw(wild))  # fmt: skip
            assert result is None or isinstance(result, bool)
        elif op == "se2":
            _call(world.in_collision_se2, *data.draw(st.lists(wild, min_size=3, max_size=3)))
        elif op == "se3":
            _call(world.in_collision_se3, *data.draw(st.lists(wild, min_size=7, max_size=7)))
        else:
            world.reset_counters()
            assert world.counters["collision_queries"] == 0
    assert world.n_objects >= 0 and len(world.body_query_counts) == len(robot)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_fuzzed_kernel_certifier_calls_never_accept_what_is_not_finite(data):
    """A certifier with fuzzed options (garbage ladders too) on a small world, fuzzed
    edges and states: every call returns a bool or raises ValueError/TypeError, and an
    edge or state with a number that is not finite is never accepted."""
    robot = _kernel_robot(data)
    n = robot.dimension
    world = KernelWorld(robot, 2.0, 2e-3, 1e-6)
    for _ in range(data.draw(st.integers(0, 3))):
        centre = data.draw(st.lists(st.floats(-6, 6), min_size=3, max_size=3))
        _call(world.add_sphere, centre, data.draw(st.floats(0.01, 3.0)))
    if data.draw(st.booleans()):
        _call(world.add_prism, data.draw(st.lists(st.floats(-6, 6), min_size=6, max_size=10)))
    valid = st.lists(st.sampled_from(["ball", "rotation", "region", "polytope"]), min_size=1,
                     max_size=3)  # fmt: skip
    names = st.one_of(valid, valid, valid, st.sampled_from([[], ["ball", "nope"]]))
    width = 3 if n == 2 else 6
    row = st.lists(wild, min_size=width, max_size=width)
    good_ladder = st.just(([0.05, 0.2], [[1.0] * width, [0.5] * width], 1.0))
    ladder = data.draw(
        st.one_of(
            good_ladder,
            good_ladder,
            st.tuples(st.lists(wild, max_size=3), st.lists(row.map(list), max_size=3), wild),
        )
    )
    certifier = _call(
        CompiledCertifier, world, data.draw(names),
        data.draw(st.booleans()), data.draw(st.integers(0, 80) | st.just(-1)), data.draw(wild),
        data.draw(st.booleans()), data.draw(st.booleans()), data.draw(st.lists(wild, min_size=3,
        max_size=3)), data.draw(st.lists(wild, min_size=3, max_size=3)),
        data.draw(st.integers(1, 200) | st.sampled_from([0, -1])), *ladder,
    )  # fmt: skip
    event(f"fuzzed options {'refused' if certifier is None else 'taken'}")
    if certifier is None:
        certifier = _compiled(world, ("ball", "region"))
    size = 3 if n == 2 else 7
    pose = st.lists(wild, min_size=size, max_size=size) | st.lists(st.floats(-8, 8),
        min_size=size, max_size=size) | wild_list  # fmt: skip
    for _ in range(data.draw(st.integers(1, 8))):
        p1, p2 = data.draw(pose), data.draw(pose)
        finite = len(p1) == len(p2) == size and _finite(p1 + p2)
        result = _call(certifier.check, p1, p2, data.draw(wild))
        assert result is None or isinstance(result, bool)
        if len(p1) == len(p2) == size and not finite:
            assert result is False
        valid = _call(certifier.state_valid, p1)
        assert valid is None or isinstance(valid, bool)
        if len(p1) == size and not _finite(p1):
            assert valid is False
        fast = getattr(certifier, f"check_se{n}")
        if len(p1) == len(p2) == size:
            result = _call(fast, *p1, *p2, 0.01)
            assert result is None or (isinstance(result, bool) and (finite or not result))
        measured = _call(certifier.measure, p1)
        if measured is not None:
            clearance, bodies = measured
            assert len(bodies) == len(robot) and not math.isnan(clearance)
    counters = certifier.counters
    assert counters["edges"] >= counters["rejected"] >= 0


def _unit(q: list) -> list:
    norm = math.sqrt(sum(v * v for v in q))
    return [v / norm for v in q]


def _obstacle(draw, n: int) -> dict:
    centre = draw(st.lists(st.floats(-8, 8), min_size=n, max_size=n))
    kind = draw(st.sampled_from(["box", "ball", "ellipse", "wall", "polygon"]))
    turn = (
        {"yaw": draw(st.floats(-4, 4))}
        if n == 2
        else {"quaternion": _unit(draw(st.lists(st.floats(-1, 1), min_size=3, max_size=3)) + [1.0])}
    )
    if kind == "box":
        return {"box": {"center": centre, "size": draw(
            st.lists(st.floats(0.05, 6), min_size=n, max_size=n))} | turn}  # fmt: skip
    if kind == "wall":
        size = [draw(st.floats(0.01, 0.1))] + [draw(st.floats(3, 12))] * (n - 1)
        return {"box": {"center": centre, "size": size} | turn}
    if kind == "ball":
        return {
            ("circle" if n == 2 else "sphere"): {
                "center": centre,
                "radius": draw(st.floats(0.05, 4)),
            }
        }
    if kind == "ellipse" or n == 3:
        axes = draw(st.lists(st.floats(0.02, 4), min_size=n, max_size=n))
        return {("ellipse" if n == 2 else "ellipsoid"): {"center": centre, "semi_axes": axes}
                | turn}  # fmt: skip
    k = draw(st.integers(3, 7))  # a convex polygon: a perturbed regular one
    radius = draw(st.floats(0.2, 5))
    angles = np.sort(np.array(draw(st.lists(st.floats(0, 1), min_size=k, max_size=k))))
    angles = 2 * np.pi * (np.arange(k) + 0.8 * angles) / k
    points = np.column_stack([np.cos(angles), np.sin(angles)]) * radius + centre
    return {"polygon": {"vertices": points.tolist()}}


@st.composite
def small_worlds(draw) -> Scenario:
    n = draw(st.sampled_from([2, 3]))
    axes = sorted(draw(st.lists(st.floats(0.1, 3), min_size=n, max_size=n)), reverse=True)
    if draw(st.booleans()):
        robot = {"semi_axes": axes}
    else:  # two bodies; the second off the origin
        offset = draw(st.lists(st.floats(-3, 3), min_size=n, max_size=n))
        robot = {"bodies": [{"semi_axes": axes}, {"semi_axes": axes[::-1], "position": offset}]}
    obstacles = [_obstacle(draw, n) for _ in range(draw(st.integers(0, 5)))]
    data = _scenario_dict("fuzz", n, ([-10.0] * n, [10.0] * n), robot, obstacles)
    return parse_scenario(data, check=False)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scenario=small_worlds(), data=st.data())
def test_fuzzed_edges_the_kernel_accepts_are_free(scenario, data):
    """Small random worlds (thin walls, needles, polygons, one or two bodies, or nothing at
    all), random finite edges and options: every edge the kernel accepts verifies free
    without gaps on python-fcl."""
    world = CollisionWorld(scenario)
    n = scenario.dimension
    kinds = data.draw(st.sampled_from([v for k, v in SETS.items() if k != "kc-paper"]))
    certifier = KernelCertifier(
        world,
        certificates=kinds,
        max_guards=data.draw(st.integers(0, 64)),
        sweep_test=data.draw(st.booleans()),
        occupancy=data.draw(st.booleans()),
        horizon=data.draw(st.none() | st.floats(0.0, 10.0)),
        cache_entries=data.draw(st.integers(1, 50)),
    )
    position = st.lists(st.floats(-12, 12), min_size=n, max_size=n)
    turn = (
        st.lists(st.floats(-10, 10), min_size=1, max_size=1)
        if n == 2
        else st.lists(st.floats(-2, 2), min_size=4, max_size=4).map(
            lambda q: q if sum(v * v for v in q) > 1e-6 else [*q[:3], 1.0]
        )
    )
    poses = []
    accepted = 0
    for _ in range(data.draw(st.integers(1, 12))):
        p1 = data.draw(position) + data.draw(turn)
        if poses and data.draw(st.booleans()):
            p1 = poses[data.draw(st.integers(0, len(poses) - 1))]  # a cached state
        if data.draw(st.booleans()):
            p2 = data.draw(position) + data.draw(turn)
        else:  # near p1
            step = data.draw(st.lists(st.floats(-1, 1), min_size=len(p1), max_size=len(p1)))
            p2 = [a + b for a, b in zip(p1, step, strict=True)]
            if n == 3 and sum(v * v for v in p2[3:]) < 1e-6:
                p2[6] += 1.0
        poses += [p1, p2]
        if certifier.check(p1, p2):
            accepted += 1
            check = verify_path(world, [p1, p2])
            assert not check.collides, (p1, p2, check)
    event(f"accepted edges: {min(accepted, 3)}{'+' if accepted >= 3 else ''}")
    assert certifier.counters["edges"] >= accepted


# ------------------------------------------------------------------ 5. the cache bound


def test_guard_cache_stays_within_its_bound_and_decides_as_an_unbounded_one():
    scenario = load_scenario(ROOT / "scenarios" / "2d" / "random_clutter.yaml")
    world = CollisionWorld(scenario)
    small = KernelCertifier(world, cache_entries=100)
    large = KernelCertifier(world)
    sizes, decisions = [], []
    edges = _edges("random_clutter")[:3000]
    for i, (p1, p2) in enumerate(edges):
        decisions.append((small.check(p1, p2), large.check(p1, p2)))
        small.state_valid(p1 + [0.01, 0.0, 0.0])
        sizes.append(small.cache_size)
        assert small._kernel.validity_cache_size <= 100, i
    assert max(sizes) <= 100
    assert min(sizes[1000:]) >= 50  # the cache keeps the newest three quarters
    assert large.cache_size > 1000
    same = sum(a == b for a, b in decisions)
    assert same >= 0.995 * len(decisions)
    assert small.counters["guards"] > large.counters["guards"]  # it had to measure again
    with pytest.raises(ValueError, match="max_entries: expected at least 1"):
        KernelCertifier(world, cache_entries=0)


def test_kernel_robot_twin_matches_the_python_robot():
    for path in ("2d/l_robot_door", "3d/box_field", "2d/thin_wall"):
        robot = load_scenario(ROOT / "scenarios" / f"{path}.yaml").robot
        twin = _kernel.kernel_robot(robot)
        assert len(twin) == len(robot) and twin.is_single == robot.is_single
        assert twin.core_radius == pytest.approx(robot.core_radius)
        assert twin.reach == pytest.approx(robot.reach)


@pytest.mark.parametrize("world_name", ["thin_walls", "box_field"])
def test_the_twins_screen_every_edge_alike_and_screening_proves_nothing(world_name):
    """``screen`` (the lazy planner's test of a tree edge) decides as its Python twin on
    the same world (occupancy grid, core sweep, probes) but where coal and FCL see a
    contact differently (then the edge collides); it accepts edges that touch an
    obstacle between its probes, which ``check`` rejects and the gap-free verifier
    finds colliding."""
    scenario = _scenario(world_name)
    world = CollisionWorld(scenario)
    python, kernel = EdgeCertifier(world), KernelCertifier(world)
    thinnest = scenario.robot.smallest_semi_axis
    edges = _edges(world_name)[:300]
    decisions = {}
    for step in (0.5 * thinnest, 1e9):
        py = np.array([python.screen(p1, p2, step) for p1, p2 in edges])
        kc = np.array([kernel.screen(p1, p2, step) for p1, p2 in edges])
        differ = np.flatnonzero(py != kc)
        assert len(differ) <= 0.01 * len(edges)
        assert all(verify_path(world, list(edges[i])).collides for i in differ)
        decisions[step] = kc
    assert python.counters["screened_edges"] == kernel.counters["screened_edges"] == 600
    assert kernel.counters["probes"] > 0 and kernel.counters["guards"] == 0
    assert abs(python.counters["probes"] - kernel.counters["probes"]) <= 0.01 * 600 * 64
    fine, sparse = decisions[0.5 * thinnest], decisions[1e9]
    missed = [e for e, f, s in zip(edges, fine, sparse, strict=True) if s and not f]
    assert fine.sum() < sparse.sum() and missed
    assert any(verify_path(world, [p1, p2]).collides for p1, p2 in missed[:20])
    assert not any(kernel.check(p1, p2) for p1, p2 in missed[:20])
    with pytest.raises(ValueError, match="step"):
        kernel.screen(*edges[0], 0.0)
    with pytest.raises(ValueError, match="step"):
        python.screen(*edges[0], -1.0)


def test_a_rigid_check_without_probes_asks_none_and_stays_sound():
    """``check(..., probe=False)`` (a lazy planner's certification of a screened path
    edge) asks no probe in either twin, the twins decide alike (but where coal and FCL
    see a contact differently: then the edge collides), and every edge it accepts is free
    without gaps (verify_path, independent of the certificate)."""
    world = CollisionWorld(_scenario("box_field"))
    python, kernel = EdgeCertifier(world), KernelCertifier(world)
    edges = _edges("box_field")[:200]
    py = np.array([python.check(p1, p2, probe=False) for p1, p2 in edges])
    kc = np.array([kernel.check(p1, p2, probe=False) for p1, p2 in edges])
    differ = np.flatnonzero(py != kc)
    assert len(differ) <= 0.01 * len(edges)
    assert all(verify_path(world, list(edges[i])).collides for i in differ)
    assert kc.any() and not kc.all()
    for c in (python.counters, kernel.counters):
        assert c["probes"] == 0 and c["rejected_probe"] == 0 and c["guards"] > 0
    accepted = [list(e) for e, ok in zip(edges, kc, strict=True) if ok]
    assert not any(verify_path(world, e).collides for e in accepted)
