"""The FCL collision world against independent computations.

2D: an exact planar oracle in numpy (the robot ellipse is mapped to the unit disk; a
polygon collides iff the mapped polygon region comes within distance 1 of the origin;
clearances by dense boundary sampling refined with a scalar minimiser).
3D: closed forms (sphere-sphere, ellipsoid-half-space).
"""

import math
from pathlib import Path

import fcl
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize_scalar
from scipy.spatial import ConvexHull

from kcplan.geometry.pose import pose_frame
from kcplan.scenarios import parse_scenario
from kcplan.world import CollisionWorld


def world_2d(obstacles, a=(5.0, 3.5), bounds=((-100, -100), (100, 100))):
    data = {
        "name": "t",
        "dimension": 2,
        "bounds": {"low": list(bounds[0]), "high": list(bounds[1])},
        "robot": {"semi_axes": list(a)},
        "start": {"position": [0, 0]},
        "goal": {"position": [1, 0]},
        "obstacles": obstacles,
    }
    return CollisionWorld(parse_scenario(data, check=False))


def world_3d(obstacles, a=(4.0, 2.5, 2.0)):
    data = {
        "name": "t",
        "dimension": 3,
        "bounds": {"low": [-100] * 3, "high": [100] * 3},
        "robot": {"semi_axes": list(a)},
        "start": {"position": [0, 0, 0]},
        "goal": {"position": [1, 0, 0]},
        "obstacles": obstacles,
    }
    return CollisionWorld(parse_scenario(data, check=False))


# ---------------------------------------------------------------- planar oracle


def point_segment_distance(P, A, B):
    """Distances from points P (k, 2) to every segment A[j]B[j]: shape (k, m)."""
    d = B - A
    t = np.clip(((P[:, None, :] - A) * d).sum(-1) / (d * d).sum(-1), 0.0, 1.0)
    return np.linalg.norm(P[:, None, :] - (A + t[..., None] * d), axis=-1)


def inside_polygon(P, V):
    """Even-odd rule for points P (k, 2) and a simple polygon V (m, 2)."""
    x, y = P[:, :1], P[:, 1:]
    A, B = V, np.roll(V, -1, axis=0)
    crosses = (A[:, 1] > y) != (B[:, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xs = A[:, 0] + (y - A[:, 1]) * (B[:, 0] - A[:, 0]) / (B[:, 1] - A[:, 1])
    return ((crosses & (x < xs)).sum(1) % 2) == 1


def planar_polygon_collides(pose, a, V):
    R, t = pose_frame(pose, 2)
    W = ((V - t) @ R) / np.asarray(a)  # polygon in the frame where the robot is the unit disk
    origin = np.zeros((1, 2))
    if inside_polygon(origin, W)[0]:
        return True
    return point_segment_distance(origin, W, np.roll(W, -1, axis=0)).min() <= 1.0


def boundary(pose, a, s):
    R, t = pose_frame(pose, 2)
    s = np.atleast_1d(s)
    return t + (np.column_stack([np.cos(s), np.sin(s)]) * a) @ R.T


def refined_min(f, k=4096):
    """Minimum over [0, 2 pi) of a smooth periodic f (vectorised), sampled then refined."""
    s = np.linspace(0.0, 2 * np.pi, k, endpoint=False)
    v = f(s)
    i = int(np.argmin(v))
    h = 2 * np.pi / k
    res = minimize_scalar(
        lambda x: float(f(np.array([x]))[0]),
        bounds=(s[i] - h, s[i] + h),
        method="bounded",
        options={"xatol": 1e-12},
    )
    return min(float(v[i]), float(res.fun))


def planar_polygon_clearance(pose, a, V):
    if planar_polygon_collides(pose, a, V):
        return 0.0
    A, B = V, np.roll(V, -1, axis=0)
    return refined_min(lambda s: point_segment_distance(boundary(pose, a, s), A, B).min(1))


def random_convex_polygon(rng, center, size):
    P = center + rng.uniform(-size, size, (rng.integers(3, 12), 2))
    return P[ConvexHull(P).vertices]


def random_star_polygon(rng, center, size, k):
    """A simple (usually non-convex) polygon, star-shaped about ``center``: angular gaps
    below pi keep it simple."""
    angles = (np.arange(k) + rng.uniform(0.0, 0.9, k)) * (2 * np.pi / k)
    radii = rng.uniform(0.2, 1.0, k) * size
    return center + np.column_stack([np.cos(angles), np.sin(angles)]) * radii[:, None]


def random_robot_pose(rng, near, spread):
    return np.array([*(near + rng.normal(0, spread, 2)), rng.uniform(-np.pi, np.pi)])


@pytest.mark.parametrize("kind", ["convex", "star", "box"])
def test_planar_collision_matches_oracle(kind):
    rng = np.random.default_rng({"convex": 1, "star": 2, "box": 3}[kind])
    mismatches, hits = 0, 0
    for _ in range(150):
        a = np.sort(rng.uniform(0.5, 6.0, 2))[::-1]
        center = rng.uniform(-20, 20, 2)
        size = rng.uniform(1.0, 10.0)
        if kind == "convex":
            V = random_convex_polygon(rng, center, size)
            spec = {"polygon": {"vertices": V.tolist()}}
        elif kind == "star":
            V = random_star_polygon(rng, center, size, 12)
            spec = {"polygon": {"vertices": V.tolist()}}
        else:
            wh, yaw = rng.uniform(0.1, 12, 2), rng.uniform(-np.pi, np.pi)
            spec = {"box": {"center": center.tolist(), "size": wh.tolist(), "yaw": float(yaw)}}
            c, s = math.cos(yaw), math.sin(yaw)
            V = (
                center
                + (np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * wh / 2)
                @ np.array([[c, -s], [s, c]]).T
            )
        world = world_2d([spec], a)
        for pose in [random_robot_pose(rng, center, size) for _ in range(10)]:
            expect = planar_polygon_collides(pose, a, V)
            hits += expect
            mismatches += world.in_collision(pose) != expect
    assert mismatches == 0
    assert 200 < hits < 1300  # both answers are exercised


@pytest.mark.parametrize("kind", ["convex", "star", "box"])
def test_planar_clearance_matches_oracle(kind):
    rng = np.random.default_rng({"convex": 4, "star": 5, "box": 6}[kind])
    worst = over = 0.0
    for _ in range(60):
        a = np.sort(rng.uniform(0.5, 6.0, 2))[::-1]
        center = rng.uniform(-20, 20, 2)
        size = rng.uniform(1.0, 10.0)
        if kind == "box":
            wh = rng.uniform(0.1, 12, 2)
            V = center + np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * wh / 2
        elif kind == "convex":
            V = random_convex_polygon(rng, center, size)
        else:
            V = random_star_polygon(rng, center, size, 12)
        world = world_2d([{"polygon": {"vertices": V.tolist()}}], a)
        for pose in [random_robot_pose(rng, center, 2 * size) for _ in range(5)]:
            got, expect = world.clearance(pose), planar_polygon_clearance(pose, a, V)
            worst = max(worst, abs(got - expect) / (1.0 + expect))
            # the oracle is an upper bound of the true distance, so this bounds FCL's excess
            over = max(over, world.safe_clearance(pose) - expect)
    assert worst < 1e-5
    assert over <= 0.0


def test_near_touching_poses_are_classified_exactly():
    """Bisect the touching offset with the oracle, then probe +/- 1e-4 around it."""
    rng = np.random.default_rng(7)
    wrong = 0
    for _ in range(300):
        a = np.sort(rng.uniform(0.5, 6.0, 2))[::-1]
        V = random_star_polygon(rng, np.zeros(2), rng.uniform(2, 8), 10)
        world = world_2d([{"polygon": {"vertices": V.tolist()}}], a)
        direction = rng.normal(size=2)
        direction /= np.linalg.norm(direction)
        yaw = rng.uniform(-np.pi, np.pi)
        lo, hi = 0.0, 40.0  # at lo collides, at hi free (polygon radius <= 8, a <= 6)
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            hit = planar_polygon_collides(np.array([*(mid * direction), yaw]), a, V)
            lo, hi = (mid, hi) if hit else (lo, mid)
        for offset, expect in ((-1e-4, True), (1e-4, False)):
            pose = np.array([*((hi + offset) * direction), yaw])
            wrong += world.in_collision(pose) != expect
            if not expect:
                assert 0.0 < world.clearance(pose) < 2e-4
    assert wrong == 0


def test_discs_and_ellipses_in_the_plane():
    rng = np.random.default_rng(8)
    worst = 0.0
    for _ in range(40):
        a = np.sort(rng.uniform(0.5, 6.0, 2))[::-1]
        c, rad = rng.uniform(-10, 10, 2), rng.uniform(0.2, 5)
        e_axes, e_yaw = rng.uniform(0.3, 6, 2), rng.uniform(-np.pi, np.pi)
        world_c = world_2d([{"circle": {"center": c.tolist(), "radius": float(rad)}}], a)
        world_e = world_2d(
            [
                {
                    "ellipse": {
                        "center": c.tolist(),
                        "semi_axes": e_axes.tolist(),
                        "yaw": float(e_yaw),
                    }
                }
            ],
            a,
        )
        for _ in range(3):
            pose = random_robot_pose(rng, c, 8)
            # disc: distance from its centre to the robot ellipse, minus the radius
            R, t = pose_frame(pose, 2)
            centre_in = np.linalg.norm(((c - t) @ R) / a) <= 1
            d_c = (
                0.0
                if centre_in
                else max(
                    refined_min(
                        lambda s, p=pose, a=a, c=c: np.linalg.norm(boundary(p, a, s) - c, axis=1)
                    )
                    - rad,
                    0.0,
                )
            )
            assert world_c.in_collision(pose) == (d_c == 0.0) or abs(d_c) < 1e-9
            worst = max(worst, abs(world_c.clearance(pose) - d_c) / (1.0 + d_c))
            # ellipse: boundary-to-boundary by dense sampling (1500 x 1500)
            s = np.linspace(0, 2 * np.pi, 1500, endpoint=False)
            P = boundary(pose, a, s)
            Q = boundary(np.array([*c, e_yaw]), e_axes, s)
            Re = pose_frame(np.array([*c, e_yaw]), 2)[0]
            overlap = (np.linalg.norm(((P - c) @ Re) / e_axes, axis=1) <= 1).any() or (
                np.linalg.norm(((Q - t) @ R) / a, axis=1) <= 1
            ).any()
            d_e = 0.0 if overlap else np.sqrt(((P[:, None] - Q[None]) ** 2).sum(-1)).min()
            assert abs(world_e.clearance(pose) - d_e) < 5e-3
            if d_e > 5e-3 or d_e == 0.0:
                assert world_e.in_collision(pose) == (d_e == 0.0)
    assert worst < 1e-5


# ---------------------------------------------------------------- 3D closed forms


def test_sphere_sphere_distance():
    rng = np.random.default_rng(9)
    for _ in range(200):
        r_robot, r_ob = rng.uniform(0.2, 5, 2)
        c = rng.uniform(-10, 10, 3)
        world = world_3d([{"sphere": {"center": c.tolist(), "radius": float(r_ob)}}], [r_robot] * 3)
        q = rng.normal(size=4)
        pose = np.concatenate([rng.uniform(-15, 15, 3), q / np.linalg.norm(q)])
        expect = max(np.linalg.norm(pose[:3] - c) - r_robot - r_ob, 0.0)
        assert world.clearance(pose) == pytest.approx(expect, rel=1e-3, abs=1e-6)
        assert world.safe_clearance(pose) <= expect
        if abs(expect) > 1e-6:
            assert world.in_collision(pose) == (expect == 0.0)


def test_ellipsoid_to_half_space_distance():
    """A huge thin box acts as the half-space z <= 0; the distance from a rotated
    ellipsoid above it is c_z - |diag(a) R^T e_z| (support function)."""
    rng = np.random.default_rng(10)
    world = world_3d([{"box": {"center": [0, 0, -5], "size": [1000, 1000, 10]}}])
    a = np.array([4.0, 2.5, 2.0])
    for _ in range(200):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        pose = np.concatenate([rng.uniform(-20, 20, 2), [rng.uniform(0.0, 8.0)], q])
        R, t = pose_frame(pose, 3)
        expect = max(t[2] - np.linalg.norm(a * R[2]), 0.0)
        # a lower bound (the support functions' separation along FCL's direction),
        # within 2e-5 of the distance: near contact FCL's direction is what errs
        assert expect * (1 - 1e-3) - 2e-5 <= world.clearance(pose) <= expect + 1e-9
        assert world.safe_clearance(pose) <= expect
        if abs(t[2] - np.linalg.norm(a * R[2])) > 1e-6:
            assert world.in_collision(pose) == (expect == 0.0)


def test_rotated_3d_box_is_convex_prism_with_tight_broadphase():
    world = world_3d(
        [
            {
                "box": {
                    "center": [10, 0, 0],
                    "size": [2, 2, 2],
                    "quaternion": [0, 0, math.sin(math.pi / 8), math.cos(math.pi / 8)],
                }
            }
        ]
    )
    # the box's corner reaches x = 10 - sqrt(2) along the x axis after a 45 degree yaw
    identity = [0, 0, 0, 1]
    assert world.clearance([10 - math.sqrt(2) - 4 - 0.5, 0, 0, *identity]) == pytest.approx(
        0.5, abs=1e-6
    )
    assert world.in_collision([10 - math.sqrt(2) - 4 + 0.01, 0, 0, *identity])


def test_mesh_obstacle(tmp_path):
    from kcplan.world.mesh import read_mesh, write_stl

    V = np.array(
        [
            [-1, -1, -1],
            [1, -1, -1],
            [1, 1, -1],
            [-1, 1, -1],
            [-1, -1, 1],
            [1, -1, 1],
            [1, 1, 1],
            [-1, 1, 1],
        ],
        float,
    )
    T = np.array(
        [
            [0, 2, 1],
            [0, 3, 2],
            [4, 5, 6],
            [4, 6, 7],
            [0, 1, 5],
            [0, 5, 4],
            [2, 3, 7],
            [2, 7, 6],
            [1, 2, 6],
            [1, 6, 5],
            [0, 4, 7],
            [0, 7, 3],
        ]
    )
    write_stl(tmp_path / "cube.stl", V, T)
    V2, T2 = read_mesh(tmp_path / "cube.stl")
    assert len(V2) == 8 and len(T2) == 12
    spec = {"mesh": {"file": str(tmp_path / "cube.stl"), "scale": 2.0, "position": [10, 0, 0]}}
    world = world_3d([spec], [1.0, 1.0, 1.0])
    # cube [8, 12] in x after scaling: a unit sphere at x = 6.5 is 0.5 away
    assert world.clearance([6.5, 0, 0, 0, 0, 0, 1]) == pytest.approx(0.5, abs=1e-6)
    assert world.in_collision([7.5, 0, 0, 0, 0, 0, 1])


# ---------------------------------------------------------------- counters


def test_counters_increase_once_per_query():
    world = world_2d([{"circle": {"center": [10, 0], "radius": 1}}])
    zero = dict.fromkeys(
        ("collision_queries", "distance_queries", "region_queries", "region_pairs", "body_queries"),
        0,
    )
    assert world.counters == zero
    world.in_collision([0, 0, 0])
    assert world.counters == zero | {"collision_queries": 1, "body_queries": 1}
    world.clearance([0, 0, 0])
    one_each = {"collision_queries": 1, "distance_queries": 1, "body_queries": 2}
    assert world.counters == zero | one_each
    poses = np.zeros((7, 3))
    world.in_collision_many(poses)
    world.clearance_many(poses)
    eight = zero | {"collision_queries": 8, "distance_queries": 8, "body_queries": 16}
    assert world.counters == eight
    world.colliding_obstacles([0, 0, 0])  # diagnostics are not counted
    assert world.counters == eight
    assert world.body_query_counts == [16]
    world.reset_counters()
    assert world.counters == zero and world.body_query_counts == [0]


def test_empty_world_and_bad_pose():
    world = world_2d([])
    assert not world.in_collision([0, 0, 0]) and world.clearance([0, 0, 0]) == math.inf
    with pytest.raises(ValueError, match="expected 3 numbers"):
        world.in_collision([0, 0, 0, 1])


def test_thin_ellipsoid_clearance_is_a_lower_bound_where_fcl_overestimates():
    """The rigid world, like the arm world, trusts FCL's direction only: for the pair of
    thin ellipsoids where FCL's distance is 7 % too large (a robot of one body and an
    ellipsoid obstacle), the world's clearance stays below the sampled distance (an
    upper bound of the true one), and so do the free regions' clearances."""
    from conftest import AXES_A, AXES_B, FRAME_A, FRAME_B
    from scipy.spatial.transform import Rotation

    Fa, Fb = np.array(FRAME_A), np.array(FRAME_B)
    a, b = np.array(AXES_A), np.array(AXES_B)
    qb = Rotation.from_matrix(Fb[:, :3]).as_quat().tolist()
    obstacle = {"center": Fb[:, 3].tolist(), "semi_axes": b.tolist(), "quaternion": qb}
    world = world_3d([{"ellipsoid": obstacle}], a)
    pose = np.concatenate([Fa[:, 3], Rotation.from_matrix(Fa[:, :3]).as_quat()])
    u = np.random.default_rng(0).normal(size=(20000, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    pa, pb = Fa[:, 3] + (u * a) @ Fa[:, :3].T, Fb[:, 3] + (u[::5] * b) @ Fb[:, :3].T
    sampled = min(np.sqrt(((pa[i : i + 2000, None] - pb[None]) ** 2).sum(-1)).min()
                  for i in range(0, len(pa), 2000))  # fmt: skip
    world._place(pose)  # FCL's distance of the pair, robot first (as the world asks): 7 % over
    fcl_distance = fcl.distance(world._bodies[0], world._objects[0], fcl.DistanceRequest())
    assert fcl_distance > 1.05 * sampled
    assert 0.9 * sampled < world.clearance(pose) <= sampled
    assert world.safe_clearance(pose) <= sampled
    (region,) = world.free_regions(pose, horizon=1.0)
    assert 0.0 < region.clearances.max() <= sampled


def test_fcl_near_contact_is_climbed_to_its_distance_not_taken_for_contact():
    """Found by a suite run: an ellipsoid 0.3-0.7 mm from a box of box_field, where FCL's
    nearest points (both orders) give a direction whose separation bound is <= 0, so the
    clearance was 0 and the gap-free verifier called a free certified edge colliding.
    The bound is now climbed from FCL's direction (:func:`ascended_separation`): still
    below the distance, which dense samples of the ellipsoid's surface bound from above."""
    from kcplan.scenarios import load_scenario

    root = Path(__file__).resolve().parents[1]
    scenario = load_scenario(root / "scenarios" / "3d" / "box_field.yaml")
    world = CollisionWorld(scenario)
    pose = np.array([57.59605363295599, 38.61278549417023, 38.19139306563642,
                     -0.08675687865065408, -0.02803656084155149, -0.34795178501123286,
                     0.9330684597447663])  # fmt: skip
    R, t = pose_frame(pose, 3)
    u = np.random.default_rng(0).normal(size=(400_000, 3))
    surface = (u / np.linalg.norm(u, axis=1)[:, None] * scenario.robot.semi_axes) @ R.T + t
    sampled = min(  # an upper bound of the true distance
        np.linalg.norm(
            np.maximum(np.abs((surface - o.center) @ o.rotation) - o.extents, 0.0), axis=1
        ).min()
        for o in scenario.obstacles
    )
    assert not world.in_collision(pose)
    assert 1e-4 < world.clearance(pose) <= sampled < 1e-3


@settings(max_examples=60)
@given(
    axes=st.lists(st.floats(0.1, 3.0), min_size=3, max_size=3),
    half=st.lists(st.floats(0.1, 5.0), min_size=3, max_size=3),
    gap=st.floats(1e-5, 0.5),
    seed=st.integers(0, 2**32 - 1),
)
def test_the_ascended_separation_stays_below_the_distance(axes, half, gap, seed):
    """From any start direction the climbed bound stays a lower bound of the distance
    between an ellipsoid and a box (the exact distance bounded from above by dense surface
    samples), never below the start's."""
    from scipy.spatial.transform import Rotation

    from kcplan.world.support import (
        EllipsoidSupport,
        PointsSupport,
        ascended_separation,
        box_vertices,
        separation,
    )

    rng = np.random.default_rng(seed)
    a, h = np.array(axes), np.array(half)
    Re, Rb = Rotation.random(2, random_state=seed).as_matrix()
    # place the ellipsoid along a random direction, then slide it in until `gap` is near
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    centre = direction * (np.linalg.norm(h) + a.max() + gap + 1.0)
    box = PointsSupport(box_vertices(np.zeros(3), Rb, h))
    u = rng.normal(size=(100_000, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    local = u * a @ Re.T

    def sampled(c):
        p = (local + c) @ Rb
        return np.linalg.norm(np.maximum(np.abs(p) - h, 0.0), axis=1).min()

    centre -= direction * max(sampled(centre) - gap, 0.0)
    ellipsoid = EllipsoidSupport(centre, Re, a)
    upper = sampled(centre)
    start = rng.normal(size=3)
    start /= np.linalg.norm(start)
    value, v = ascended_separation(box, ellipsoid, start, target=np.inf)
    assert value <= upper + 1e-12
    assert value >= separation(box, ellipsoid, start) - 1e-15
    assert np.isclose(np.linalg.norm(v), 1.0)
    assert value == pytest.approx(separation(box, ellipsoid, v), abs=1e-15)
