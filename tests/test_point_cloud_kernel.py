"""The kernel's point cloud (kcplan/_kernel/point_cloud.hpp): its k-d tree's bounds decide
which points coal measures, so its answers must be those of measuring every point.

Each case compares a world holding the cloud with brute force over every point: coal's
distance from the body to each point's ball (the same narrow phase, no tree), and, free of
coal, the distances from points sampled densely on the body's surface (never below the
body's distance) and the exact distance of a ball query."""

import coal
import numpy as np
import pytest
from conftest import sphere_points
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kcplan._kernel import COAL_CLEARANCE_RTOL, REACH_MARGIN, CloudOrder
from kcplan._kernel import Robot as KernelRobot
from kcplan._kernel import World as KernelWorld

SURFACE = 4000




UNIT = sphere_points(SURFACE)


def _world(points: np.ndarray, radius: float, axes, order=CloudOrder.morton,
           tolerance: float = 0.0) -> KernelWorld:  # fmt: skip
    """A world of one ellipsoid and the cloud, no allowance (rtol = atol = 0): the
    tolerance's floor is the padding."""
    world = KernelWorld(KernelRobot(3, list(map(float, axes)), [0, 0, 0, 0, 0, 0, 1]), 1.0, 0, 0)
    world.add_points(np.ascontiguousarray(points, dtype=float), radius, order)
    world.cloud_tolerance = tolerance
    world.finalize()
    return world


def _coal_distances(points, radius, axes, pose) -> np.ndarray:
    """coal's distance from the ellipsoid at `pose` to each point's ball (no tree)."""
    body = coal.Ellipsoid(*map(float, axes))
    R = Rotation.from_quat(pose[3:]).as_matrix()
    at = coal.Transform3s(R, np.asarray(pose[:3], dtype=float))
    ball = coal.Sphere(radius)
    out = np.empty(len(points))
    for i, p in enumerate(points):
        result = coal.DistanceResult()
        d = coal.distance(body, at, ball, coal.Transform3s(np.eye(3), p), coal.DistanceRequest(),
                          result)  # fmt: skip
        out[i] = max(d, 0.0)
    return out


@st.composite
def clouds(draw):
    f = st.floats
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    n = draw(st.integers(1, 400))
    kind = draw(st.sampled_from(("blob", "plane", "shell", "repeated")))
    if kind == "blob":
        points = rng.normal(scale=draw(f(0.05, 1.0)), size=(n, 3))
    elif kind == "repeated":  # many points in one Morton cell, and the same point again
        points = np.repeat(rng.normal(scale=0.3, size=(n // 20 + 1, 3)), 20, axis=0)[:n]
        points[: n // 2] += rng.normal(scale=1e-5, size=(n // 2, 3))
    elif kind == "plane":
        points = np.column_stack([rng.uniform(-1, 1, (n, 2)), np.full(n, draw(f(-0.6, 0.6)))])
    else:
        points = draw(f(0.3, 1.5)) * sphere_points(n)
    points = points + rng.uniform(-0.3, 0.3, 3)
    radius = draw(f(1e-4, 0.05))
    axes = [draw(f(0.02, 0.4)) for _ in range(3)]
    position = rng.uniform(-0.8, 0.8, 3)
    q = Rotation.random(random_state=rng.integers(2**31)).as_quat()
    return points, radius, axes, [*position, *q]


TOLERANCES = st.sampled_from([0.0, 0.25, 1.0])


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(clouds(), st.sampled_from([CloudOrder.morton, CloudOrder.median]), TOLERANCES)
def test_the_tree_finds_what_measuring_every_point_finds(case, order, tolerance):
    points, radius, axes, pose = case
    world = _world(points, radius, axes, order, tolerance)
    brute = _coal_distances(points, radius, axes, pose)
    (d,) = world.body_distances(pose)
    # coal's GJK stops a little above the distance (within the kernel's allowance, and
    # within its tolerance, 1e-6, of another GJK run); a ball's bound is the distance.
    # With a tolerance t (floor 0 here) the search may stop early: d (1 + t) still
    # reaches the distance, and d stays below it
    assert brute.min() * (1.0 - COAL_CLEARANCE_RTOL) - 1e-9 <= d * (1.0 + tolerance)
    assert d <= brute.min() * (1 + 1e-6) + 2e-6
    # the verdict: contact exactly where some ball is within GJK's tolerance of the body
    assert world.in_collision(pose) == bool(brute.min() < 1e-6)
    # the tree bounded most points without measuring them
    counters = world.cloud_counters
    assert counters["exact"] <= counters["points"] <= 2 * len(points) + 16


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(clouds())
def test_distances_never_exceed_the_bodys_surface_samples(case):
    """Free of coal: every sampled point of the ellipsoid's surface is at least as far
    from each ball as the body is, so the smallest of those distances bounds the body's
    from above; the kernel's answer, less its allowance, must not exceed it."""
    points, radius, axes, pose = case
    world = _world(points, radius, axes)
    R = Rotation.from_quat(pose[3:]).as_matrix()
    surface = pose[:3] + (UNIT * axes) @ R.T
    gaps = np.linalg.norm(surface[:, None, :] - points[None, :, :], axis=2).min() - radius
    (d,) = world.body_distances(pose)
    # as coal measures it: within the kernel's allowance above the distance
    assert d * (1.0 - COAL_CLEARANCE_RTOL) <= max(gaps, 0.0) + 1e-9


@settings(max_examples=100, deadline=None)
@given(clouds(), st.floats(0.01, 0.5))
def test_a_ball_is_measured_exactly(case, ball):
    """A ball's bound along the centres' line is its distance: no GJK at all."""
    points, radius, _, pose = case
    world = _world(points, radius, [ball] * 3)
    centre = np.asarray(pose[:3])
    exact = max(np.linalg.norm(points - centre, axis=1).min() - radius - ball, 0.0)
    (d,) = world.body_distances(pose)
    assert d == pytest.approx(exact, abs=1e-9)
    assert world.ball_collides(centre.tolist(), ball) == bool(exact < 1e-6)
    # at a tolerance: exactly as short as the search may stop, never more
    world.cloud_tolerance = 0.5
    (loose,) = world.body_distances(pose)
    assert exact / 1.5 - 1e-9 <= loose <= exact + 1e-9


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(clouds(), st.floats(0.0, 0.3), st.floats(0.1, 2.0))
def test_a_tolerance_keeps_the_padded_verdict_exact(case, padding, tolerance):
    """The tolerance's floor is the threshold of the verdict (the padding): a state is in
    collision exactly when some ball is within the padding, as with the exact search, and
    a clearance past it is short by at most the factor 1 + tolerance."""
    points, radius, axes, pose = case
    world = _world(points, radius, axes, tolerance=tolerance)
    world.padding = padding
    brute = _coal_distances(points, radius, axes, pose).min()
    if abs(brute - padding) < 1e-5:  # GJK's own tolerance decides it
        return
    assert world.in_collision(pose) == bool(brute < padding)
    (clearance,) = world.safe_body_clearances(pose)
    beyond = max(brute - padding, 0.0)
    # coal's GJK (brute) may stop up to about 1e-6 of the distance above it
    assert (beyond - 1e-5 * brute) / (1.0 + tolerance) - 2e-6 <= clearance
    assert clearance <= beyond + 1e-6 * brute + 2e-6


def test_bad_clouds_are_refused_with_a_message():
    robot = KernelRobot(3, [0.1, 0.1, 0.1], [0, 0, 0, 0, 0, 0, 1])
    world = KernelWorld(robot, 1.0, 0, 0)
    with pytest.raises(ValueError, match="at least one point"):
        world.add_points(np.zeros((0, 3)), 0.01)
    with pytest.raises(ValueError, match="finite coordinates"):
        world.add_points(np.array([[0.0, np.nan, 0.0]]), 0.01)
    with pytest.raises(ValueError, match="radius"):
        world.add_points(np.zeros((2, 3)), 0.0)
    with pytest.raises(TypeError):  # not n x 3
        world.add_points(np.zeros((2, 2)), 0.01)
    planar = KernelWorld(KernelRobot(2, [0.1, 0.1], [0, 0, 0]), 1.0, 0, 0)
    with pytest.raises(ValueError, match="3D"):
        planar.add_points(np.zeros((2, 3)), 0.01)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(clouds(), st.floats(0.05, 1.0), st.floats(0.0, 0.3))
def test_a_clouds_region_plane_holds_every_ball_near_the_body(case, horizon, padding):
    """The plane of a cloud (free_regions): every ball (grown by the padding) within the
    horizon of the body lies in {n . x <= offset} (the certificates use the plane only
    where the body lies beyond it), and the plane's clearance is no more than the body's
    distance to the balls less the padding."""
    points, radius, axes, pose = case
    world = _world(points, radius, axes)
    world.padding = padding
    free, regions = world.free_regions(pose, horizon)
    brute = _coal_distances(points, radius, axes, pose)
    if not free:  # a contact, within the padding
        assert brute.min() * (1.0 - COAL_CLEARANCE_RTOL) <= padding + 1e-9
        return
    ((planes, region_horizon),) = regions
    reach = horizon + max(axes)  # a ball nearer than the horizon has its centre in here
    near = np.abs(points - pose[:3]).max(axis=1) <= reach + radius
    for nx, ny, nz, offset, clearance in planes:
        assert clearance <= max(brute.min() * (1 + 1e-6) + 2e-6 - padding, 0.0)  # GJK's
        if not np.isfinite(offset):
            continue
        n = np.array([nx, ny, nz])
        assert abs(np.linalg.norm(n) - 1.0) < 1e-9
        assert (points[near] @ n + radius + padding <= offset + 1e-9).all()
    if not planes:  # nothing within the horizon: the horizon is certain
        gjk = brute.min() * (1 + 1e-6) + 2e-6
        assert region_horizon <= max(gjk - padding, 0.0) or brute.min() >= horizon


@pytest.fixture(scope="module")
def panda():
    """The bundled Panda, each link its own convex hull."""
    from kcplan.scenarios import load_scenario

    root = __import__("pathlib").Path(__file__).resolve().parents[1]
    return load_scenario(root / "scenarios/arm/box_1.yaml").arm


def _hull_distances(vertices, triangles, points) -> np.ndarray:
    """Exact distances from points (m, 3) to a closed convex polytope (0 inside), free of
    coal and FCL: the nearest point of each triangle (trimesh), and the facet planes
    for inside."""
    import trimesh

    corners = vertices[triangles]  # (t, 3, 3)
    m, t = len(points), len(triangles)
    nearest = trimesh.triangles.closest_point(
        np.repeat(corners, m, axis=0), np.tile(points, (t, 1))
    ).reshape(t, m, 3)
    outside = np.linalg.norm(nearest - points[None], axis=2).min(axis=0)
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    centre = vertices.mean(axis=0)
    flip = np.einsum("ij,ij->i", normals, corners[:, 0] - centre) < 0
    normals[flip] *= -1
    inside = (np.einsum("ij,mj->mi", normals, points) <=
              np.einsum("ij,ij->i", normals, corners[:, 0])[None] + 1e-12).all(axis=1)  # fmt: skip
    return np.where(inside, 0.0, outside)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**32 - 1), st.floats(1e-3, 0.02))
def test_a_link_hulls_clearance_to_a_cloud_is_every_points(panda, seed, radius):
    """Each link hull's clearance to a cloud (the kernel's tree, its 26 planes, GJK's
    planes) against the exact distance from the hull to every point, less the radius."""
    from kcplan.arm.kinematics import body_frames
    from kcplan.arm.world import ArmWorld
    from kcplan.world.obstacles import Obstacle

    arm = panda
    rng = np.random.default_rng(seed)
    q = rng.uniform(arm.lower, arm.upper)
    frames = body_frames(arm, q)
    # points around the links: near each link's centre, some within centimetres
    centres = frames[:, :3, 3]
    points = centres[rng.integers(len(centres), size=150)] + rng.normal(scale=0.08, size=(150, 3))
    cloud = Obstacle(kind="pointcloud", index=0, spec={}, center=np.zeros(3), rotation=np.eye(3),
                     extents=np.full(3, radius), vertices=np.ascontiguousarray(points))  # fmt: skip
    kernel = ArmWorld(arm, [cloud], prove_pairs=False).kernel
    tolerance = kernel.scene.cloud_tolerance  # as planners use it
    loose, _ = kernel.safe_clearances(q.tolist())
    kernel.scene.cloud_tolerance = 0.0
    scene, _ = kernel.safe_clearances(q.tolist())
    # the cheaper bounds change the work, not the exact answers
    kernel.scene.set_cloud_bounds(dop=False, gjk_planes=False, centre_line=False)
    bare, _ = kernel.safe_clearances(q.tolist())
    np.testing.assert_allclose(bare, scene, rtol=1e-5, atol=2e-6)
    # the tolerance's answers: below the exact ones, by at most its factor (the floor,
    # the allowance's raw threshold, is below 1e-6 m)
    assert tolerance > 0
    assert (np.asarray(loose) <= np.asarray(scene) + 1e-12).all()
    assert (np.asarray(loose) * (1 + tolerance) >= np.asarray(scene) * (1 - 1e-5) - 2e-6).all()
    # the kernel's cloud keeps the points within the arm's reach (REACH_MARGIN beyond)
    centre, reach = ArmWorld(arm, (), prove_pairs=False).reach
    points = points[np.linalg.norm(points - centre, axis=1) <= reach + radius + REACH_MARGIN]
    assert kernel.scene.cloud_points == len(points)
    for k, (body, frame) in enumerate(zip(arm.bodies, frames, strict=True)):
        local = (points - frame[:3, 3]) @ frame[:3, :3]  # the points in the link's frame
        exact = max(_hull_distances(body.hull.vertices, body.hull.triangles, local).min()
                    - radius, 0.0)  # fmt: skip
        # certain (no more than the distance), and within coal's allowance of it
        assert scene[k] <= exact + 1e-9, (k, scene[k], exact)
        assert scene[k] >= exact * (1 - 2 * COAL_CLEARANCE_RTOL) - 1e-4, (k, scene[k], exact)


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**32 - 1))
def test_a_cloud_keeps_the_points_within_the_arms_reach_and_its_verdicts(panda, seed):
    """Points whose balls lie beyond the arm's reach ball are dropped (RESULTS 36.2): the
    reach ball holds every hull vertex at random states, and every state's verdict is
    that of the whole cloud."""
    from kcplan.arm.kinematics import body_frames
    from kcplan.arm.world import ArmWorld
    from kcplan.world.obstacles import Obstacle

    arm, rng, radius = panda, np.random.default_rng(seed), 0.01
    centre, reach = ArmWorld(arm, (), prove_pairs=False).reach
    states = rng.uniform(arm.lower, arm.upper, size=(40, arm.dof))
    for q in states:
        for body, frame in zip(arm.bodies, body_frames(arm, q), strict=True):
            world = body.hull.vertices @ frame[:3, :3].T + frame[:3, 3]
            assert np.linalg.norm(world - centre, axis=1).max() <= reach
    # a shell of points about the reach's edge, and some at the links
    directions = rng.normal(size=(600, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    points = centre + directions * rng.uniform(0.2, 1.5 * reach, size=(600, 1))
    cloud = Obstacle(kind="pointcloud", index=0, spec={}, center=np.zeros(3), rotation=np.eye(3),
                     extents=np.full(3, radius), vertices=np.ascontiguousarray(points))  # fmt: skip
    kernel = ArmWorld(arm, [cloud], prove_pairs=False).kernel
    within = np.linalg.norm(points - centre, axis=1) <= reach + radius + REACH_MARGIN
    assert kernel.scene.cloud_points == within.sum() < len(points)
    whole = ArmWorld(arm, [cloud], prove_pairs=False)
    whole.__dict__["reach"] = (centre, np.inf)  # the ablation: every point kept
    every = whole.kernel
    assert every.scene.cloud_points == len(points)
    for q in states:
        assert kernel.in_collision(q.tolist()) == every.in_collision(q.tolist())


def test_a_reach_is_set_before_the_obstacles_and_a_cloud_beyond_it_is_no_obstacle():
    world = KernelWorld(KernelRobot(3, [0.1, 0.1, 0.1], [0, 0, 0, 0, 0, 0, 1]), 1.0, 0, 0)
    world.set_reach([0.0, 0.0, 0.0], 1.0)
    world.add_points(np.array([[3.0, 0.0, 0.0], [0.0, 4.0, 0.0]]), 0.01)
    assert world.n_objects == 0 and world.cloud_points == 0
    world.add_points(np.array([[0.5, 0.0, 0.0], [0.0, 4.0, 0.0]]), 0.01)
    assert world.n_objects == 1 and world.cloud_points == 1
    with pytest.raises(ValueError, match="expected finite coordinates"):
        world.add_points(np.array([[3.0, 0.0, 0.0], [np.nan, 0.0, 0.0]]), 0.01)
    with pytest.raises(ValueError, match="reach: expected before the first obstacle"):
        world.set_reach([0.0, 0.0, 0.0], 2.0)
    with pytest.raises(ValueError, match="reach: expected a finite centre and a radius > 0"):
        KernelWorld(KernelRobot(3, [0.1] * 3, [0, 0, 0, 0, 0, 0, 1]), 1.0, 0, 0).set_reach(
            [0.0, 0.0, 0.0], -1.0)
