"""The kernel's primitive shortcut (kcplan/_kernel/primitive_bound.hpp): a box, ball or
cylinder obstacle is first measured against a body by the two shapes' separation along
one line, and GJK runs only where that does not decide the query. Every clearance and
verdict of such a world is checked here against exact point-to-primitive distances of
points sampled densely on the body's surface, independent of coal."""

import numpy as np
from conftest import sphere_points
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kcplan._kernel import COAL_CLEARANCE_FLOOR, COAL_CLEARANCE_RTOL
from kcplan._kernel import Robot as KernelRobot
from kcplan._kernel import World as KernelWorld

KINDS = ("box", "ball", "cylinder")
SURFACE = 6000  # sampled points of the body's surface




UNIT = sphere_points(SURFACE)


def _distance(kind: str, centre, R, size, points: np.ndarray) -> np.ndarray:
    """Exact distances from points (m, 3) to a solid box (half sides), ball (radius
    size[0]) or cylinder (radius size[0], half height size[2], local z axis)."""
    local = (points - centre) @ R
    if kind == "box":
        return np.linalg.norm(np.maximum(np.abs(local) - size, 0.0), axis=1)
    if kind == "ball":
        return np.maximum(np.linalg.norm(local, axis=1) - size[0], 0.0)
    radial = np.maximum(np.hypot(local[:, 0], local[:, 1]) - size[0], 0.0)
    axial = np.maximum(np.abs(local[:, 2]) - size[2], 0.0)
    return np.hypot(radial, axial)


@st.composite
def cases(draw):
    f = st.floats
    kind = draw(st.sampled_from(KINDS))
    size = np.array([draw(f(0.02, 0.5)) for _ in range(3)])
    if kind != "box":
        size[1] = size[0]
    if kind == "ball":
        size[2] = size[0]
    turn = Rotation.from_rotvec([draw(f(-3.0, 3.0)) for _ in range(3)])
    axes = np.array([draw(f(0.01, 0.3)) for _ in range(3)])
    position = np.array([draw(f(-1.0, 1.0)) for _ in range(3)])
    q = Rotation.from_rotvec([draw(f(-3.0, 3.0)) for _ in range(3)]).as_quat()  # x, y, z, w
    return kind, size, turn.as_matrix(), axes, position, q


def _world(kind, size, R, axes):
    robot = KernelRobot(3, axes.tolist(), [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    world = KernelWorld(robot, 1.0, COAL_CLEARANCE_RTOL, COAL_CLEARANCE_FLOOR)
    centre = [0.1, -0.2, 0.05]
    rotation = R.reshape(-1).tolist()
    if kind == "box":
        world.add_box(centre, rotation, size.tolist())
    elif kind == "ball":
        world.add_sphere(centre, float(size[0]))
    else:
        world.add_cylinder(centre, rotation, float(size[0]), float(size[2]))
    world.finalize()
    return world, np.array(centre)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cases())
@example(  # a ball inside the body: its surface 12.5 mm from the ball, the solids overlapping
    ("ball", np.full(3, 0.125), np.eye(3), np.full(3, 0.25), np.array([0.0, -0.1875, 0.0]),
     np.array([0.0, 0.0, 0.0, 1.0])),
)  # fmt: skip
def test_clearances_and_verdicts_against_primitives_hold_on_the_sampled_body(case):
    """The clearance never exceeds the sampled surface's distance (which is at least the
    true one) and is close to it; a body whose sampled surface touches the obstacle is
    in collision; a body with a positive clearance is not."""
    kind, size, R, axes, position, q = case
    world, centre = _world(kind, size, R, axes)
    pose = [*position.tolist(), *q.tolist()]
    body = Rotation.from_quat(q).as_matrix()
    surface = position + (UNIT * axes) @ body.T
    sampled = float(_distance(kind, centre, R, size, surface).min())
    if np.sum((((centre - position) @ body) / axes) ** 2) <= 1.0:
        sampled = 0.0  # the obstacle's centre inside the body: the solids overlap, however
        # far the body's surface is from the obstacle (a ball inside it, found by CI)
    clearance = world.safe_body_clearances(pose)[0]
    colliding = world.in_collision(pose)
    assert clearance <= sampled + 1e-9, (clearance, sampled)
    # the sampled surface lies within a few millimetres of the true one here
    assert clearance >= (1.0 - 1e-3) * sampled - 0.004 - 2.0 * COAL_CLEARANCE_FLOOR
    if sampled == 0.0:
        assert colliding
    if clearance > 0.0:
        assert not colliding


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cases(), st.floats(0.01, 0.4))
def test_ball_verdicts_against_primitives_are_exact(case, radius):
    """A ball's separation from a box, ball or cylinder along the line to its nearest
    point is the distance itself: the ball is in collision exactly when its centre is
    within its radius of the obstacle (away from a 1e-9 band)."""
    kind, size, R, axes, position, _ = case
    world, centre = _world(kind, size, R, axes)
    d = float(_distance(kind, centre, R, size, position[None, :])[0])
    if abs(d - radius) < 1e-9:
        return
    assert world.ball_collides(position.tolist(), radius) == (d < radius)


def test_an_overlap_gjk_ends_a_hair_off_is_a_collision():
    """coal 3.0.3 without EPA reports this deep overlap (a ball of radius 0.25 whose centre
    is inside the box) with GJK's last distance, 4e-12, and counted it as free below its
    default contact threshold of 1e-12 (kcplan/_kernel/coal_requests.hpp); Hypothesis
    found it. The kernel's threshold is GJK's tolerance: a collision."""
    world, _ = _world("box", np.array([0.25, 0.25, 0.5]), np.eye(3), np.full(3, 0.25))
    assert world.body_distances([0.0] * 6 + [1.0])[0] < 1e-6  # GJK's hair, not 0
    assert world.in_collision([0.0] * 6 + [1.0])
    assert world.safe_body_clearances([0.0] * 6 + [1.0]) == [0.0]
