"""Both kinds of robot keep the one robot concept's contract (kcplan.geometry.robot_model):
every point of every body, placed by ``body_frames`` along ``edge_state``, moves no
faster than ``body_speeds`` says. The check moves sampled points of the bodies (an
ellipsoid's surface, a hull's vertices) and measures their displacement: it does not use
the bounds it checks."""

import numpy as np
import pytest
from conftest import panda_arm
from hypothesis import given, settings
from hypothesis import strategies as st

from kcplan.arm import ArmModel
from kcplan.geometry.robot import Robot
from kcplan.geometry.robot_model import RobotModel
from kcplan.world.clutter import random_pose, random_robot


@pytest.fixture(scope="module")
def panda_hulls() -> ArmModel:
    return panda_arm(None)


def body_points(robot: RobotModel, k: int, rng: np.random.Generator) -> np.ndarray:
    """Points of body ``k`` in its own frame, shape ``(p, d)``: an arm's hull vertices,
    or points on an ellipsoid's surface (the farthest from any axis of rotation)."""
    if isinstance(robot, ArmModel) and robot.bodies[k].hull is not None:
        return robot.bodies[k].hull.vertices
    axes = robot.bodies[k].semi_axes
    u = rng.normal(size=(64, len(axes)))
    return axes * (u / np.linalg.norm(u, axis=1, keepdims=True))


def assert_speeds_bound_the_motion(robot: RobotModel, q1, q2, rng) -> None:
    speeds = robot.body_speeds(q1, q2)
    assert speeds.shape == (robot.body_count,) and (speeds >= 0).all()
    d = robot.workspace_dimension
    s = np.sort(rng.uniform(0.0, 1.0, 6))
    frames = [robot.body_frames(robot.edge_state(q1, q2, t)) for t in s]
    assert frames[0].shape == (robot.body_count, d + 1, d + 1)
    for k in range(robot.body_count):
        x = body_points(robot, k, rng)
        moved = [F[k, :d, :d] @ x.T + F[k, :d, d:] for F in frames]
        for i in range(len(s) - 1):
            for j in range(i + 1, len(s)):
                step = np.linalg.norm(moved[j] - moved[i], axis=0).max()
                assert step <= speeds[k] * (s[j] - s[i]) * (1 + 1e-9) + 1e-12, (k, step)


def test_both_kinds_are_the_one_concept(panda_hulls):
    for robot in (Robot.single([1.0, 0.5]), panda_hulls):
        assert isinstance(robot, RobotModel)
    assert Robot.single([1.0, 0.5, 0.2]).state_size == 7
    assert panda_hulls.state_size == 7 and panda_hulls.workspace_dimension == 3
    # the ends of an edge are its states
    q1 = np.full(7, 0.1)
    q2 = q1 + 0.3
    np.testing.assert_allclose(panda_hulls.edge_state(q1, q2, 1.0), q2)
    p1, p2 = [0.0, 0.0, 0.5], [1.0, 2.0, -2.5]
    np.testing.assert_allclose(Robot.single([1.0, 0.5]).edge_state(p1, p2, 0.0), p1)


@settings(max_examples=25, deadline=None)
@given(n=st.sampled_from([2, 3]), bodies=st.integers(1, 4), seed=st.integers(0, 2**32 - 1))
def test_rigid_body_speeds_bound_every_point(n, bodies, seed):
    rng = np.random.default_rng(seed)
    robot = random_robot(rng, n, bodies)
    q1, q2 = random_pose(rng, n, -5.0, 5.0), random_pose(rng, n, -5.0, 5.0)
    assert_speeds_bound_the_motion(robot, q1, q2, rng)


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), length=st.floats(0.01, 3.0))
def test_arm_body_speeds_bound_every_hull_vertex(panda_hulls, seed, length):
    rng = np.random.default_rng(seed)
    arm = panda_hulls
    q1 = rng.uniform(arm.lower, arm.upper)
    step = rng.normal(size=arm.dof)
    q2 = np.clip(q1 + length * step / np.linalg.norm(step), arm.lower, arm.upper)
    assert_speeds_bound_the_motion(arm, q1, q2, rng)


def test_a_bound_that_is_too_small_is_caught(panda_hulls):
    """The check can fail: halve the arm's bound and a long edge breaks it."""
    arm = panda_hulls

    class Halved(RobotModel):
        state_size = arm.state_size
        workspace_dimension = 3
        body_count = arm.body_count
        bodies = arm.bodies

        def describe(self):
            return "halved"

        def body_frames(self, state):
            return arm.body_frames(state)

        def edge_state(self, state1, state2, s):
            return arm.edge_state(state1, state2, s)

        def body_speeds(self, state1, state2):
            return 0.5 * arm.body_speeds(state1, state2)

    rng = np.random.default_rng(3)
    q1 = np.zeros(arm.dof)
    q2 = q1.copy()
    q2[0] = 1.5  # one joint, the base: every link turns about one axis
    with pytest.raises(AssertionError):
        assert_speeds_bound_the_motion(Halved(), q1, q2, rng)
