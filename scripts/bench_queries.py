"""Cost of one collision query and one clearance query per scenario, python-fcl and kernel.

Times ``CollisionWorld.in_collision`` and ``CollisionWorld.clearance`` (python-fcl), the
compiled kernel's collision query as a stock state check makes it
(``World.in_collision_se2`` / ``_se3``, coal), and the kernel's distance query
(``World.body_distances``) and region query (``World.free_regions`` with the certifier's
default horizon, the robot's largest semi-axis), at random poses inside each scenario's
bounds (fixed seed), in repeated blocks, and prints the median time per query over
blocks, in microseconds. Collision queries are timed at all poses (those that collide
stop early), distance and region queries at the free ones (as the certifier asks)::

    python scripts/bench_queries.py scenarios/*/*.yaml [--poses 2000] [--blocks 7]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from kcplan.scenarios import load_scenario
from kcplan.world import CollisionWorld


def random_poses(scenario, k: int, rng: np.random.Generator) -> np.ndarray:
    low, high = scenario.bounds
    t = rng.uniform(low, high, (k, scenario.dimension))
    if scenario.dimension == 2:
        return np.column_stack([t, rng.uniform(-np.pi, np.pi, k)])
    q = rng.normal(size=(k, 4))
    return np.column_stack([t, q / np.linalg.norm(q, axis=1, keepdims=True)])


def per_query_us(fn, poses: np.ndarray, blocks: int) -> float:
    times = []
    for _ in range(blocks):
        t0 = time.perf_counter()
        for p in poses:
            fn(p)
        times.append((time.perf_counter() - t0) / len(poses) * 1e6)
    return float(np.median(times))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="+")
    parser.add_argument("--poses", type=int, default=2000)
    parser.add_argument("--blocks", type=int, default=7)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    print(
        f"{'scenario':<18} {'fcl objects':>11} {'collision us':>13} "
        f"{'clearance us':>13} {'ratio':>6} {'kernel collision us':>20} "
        f"{'kernel distance us':>19} {'kernel region us':>17}"
    )
    for path in args.scenarios:
        scenario = load_scenario(path)
        world = CollisionWorld(scenario)
        poses = random_poses(scenario, args.poses, rng)
        c = per_query_us(world.in_collision, poses, args.blocks)
        d = per_query_us(world.clearance, poses, args.blocks)
        kernel = world.kernel
        fast = kernel.in_collision_se2 if scenario.dimension == 2 else kernel.in_collision_se3
        rows = [p.tolist() for p in poses]  # plain floats, as the state checker passes
        k = per_query_us(lambda p, fast=fast: fast(*p), rows, args.blocks)
        free = [p for p in rows if not kernel.in_collision(p)] or rows
        kd = per_query_us(kernel.body_distances, free, args.blocks)
        horizon = float(world.robot.largest_semi_axis)
        regions = kernel.free_regions
        kr = per_query_us(lambda p, h=horizon, f=regions: f(p, h), free, args.blocks)
        print(
            f"{scenario.name:<18} {world.n_objects:>11} {c:>13.1f} {d:>13.1f} {d / c:>6.2f} "
            f"{k:>20.2f} {kd:>19.2f} {kr:>17.2f}"
        )


if __name__ == "__main__":
    main()
