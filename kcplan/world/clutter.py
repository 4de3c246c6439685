"""Random clutter: scenarios of thin rotated walls, balls, boxes and ellipsoids.

For soundness studies and tests that need many different worlds
(``scripts/soundness_study.py``, ``tests/``): thin walls are where a sampling validator
steps over obstacles and rotated pieces are where bounding boxes are loose, so both are
drawn often. Every draw comes from the generator passed in, so a seed reproduces a world.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.geometry.robot import Body, Robot
from kcplan.world.scenario import Scenario, parse_rigid_scenario

__all__ = ["random_pose", "random_obstacles", "random_robot", "random_scenario"]


def random_pose(rng: np.random.Generator, n: int, low: float, high: float) -> NDArray:
    """A pose with its centre uniform in ``[low, high]^n`` and a uniform orientation:
    ``[x, y, yaw]`` or ``[x, y, z, qx, qy, qz, qw]``."""
    t = rng.uniform(low, high, n)
    if n == 2:
        return np.array([*t, rng.uniform(-np.pi, np.pi)])
    q = rng.normal(size=4)
    return np.concatenate([t, q / np.linalg.norm(q)])


def _orientation(rng: np.random.Generator, n: int) -> dict:
    if n == 2:
        return {"yaw": float(rng.uniform(-np.pi, np.pi))}
    q = rng.normal(size=4)
    return {"quaternion": (q / np.linalg.norm(q)).tolist()}


def random_obstacles(rng: np.random.Generator, n: int, count: int, spread: float) -> list:
    """``count`` obstacle entries (scenario-file dictionaries) centred uniformly in
    ``[-spread, spread]^n``, each one of: a thin wall (0.01 to 0.2 thick, 5 to 30 long)
    in a random orientation, a ball (radius 0.5 to 5), an axis-aligned box (sides 1 to 8)
    or an ellipse/ellipsoid (semi-axes 0.3 to 4) in a random orientation."""
    obstacles = []
    for _ in range(count):
        c = rng.uniform(-spread, spread, n).tolist()
        kind = int(rng.integers(4))
        if kind == 0:
            size = [float(rng.uniform(0.01, 0.2))] + [float(rng.uniform(5, 30))] * (n - 1)
            wall = {"center": c, "size": rng.permutation(size).tolist()}
            obstacles.append({"box": wall | _orientation(rng, n)})
        elif kind == 1:
            key = "circle" if n == 2 else "sphere"
            obstacles.append({key: {"center": c, "radius": float(rng.uniform(0.5, 5))}})
        elif kind == 2:
            obstacles.append({"box": {"center": c, "size": rng.uniform(1, 8, n).tolist()}})
        else:
            key = "ellipse" if n == 2 else "ellipsoid"
            body = {"center": c, "semi_axes": rng.uniform(0.3, 4, n).tolist()}
            obstacles.append({key: body | _orientation(rng, n)})
    return obstacles


def random_robot(rng: np.random.Generator, n: int, bodies: int, offset: float = 3.0) -> Robot:
    """A robot of ``bodies`` ellipses/ellipsoids with semi-axes 0.2 to 2, each centred
    uniformly within ``offset`` of the origin per coordinate (the first body too, so the
    origin may lie outside every body) in a random orientation."""
    out = []
    for _ in range(bodies):
        pose = random_pose(rng, n, -offset, offset)
        out.append(Body(rng.uniform(0.2, 2.0, n), pose))
    return Robot(out)


def random_scenario(
    rng: np.random.Generator,
    n: int,
    robot: Robot | ArrayLike,
    count: int,
    half_width: float = 25.0,
) -> Scenario:
    """A scenario with ``count`` :func:`random_obstacles` centred within
    ``half_width - 5`` of the origin, bounds ``[-half_width, half_width]^n``, and the
    robot (or the semi-axes of one body at the origin); start and goal are placeholders
    (not checked)."""
    data = {
        "name": "clutter",
        "dimension": n,
        "bounds": {"low": [-half_width] * n, "high": [half_width] * n},
        "robot": Robot.of(robot).to_spec(),
        "start": {"position": [0] * n},
        "goal": {"position": [1] + [0] * (n - 1)},
        "obstacles": random_obstacles(rng, n, count, half_width - 5.0),
    }
    return parse_rigid_scenario(data)
