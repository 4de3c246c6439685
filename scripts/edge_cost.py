"""Time per edge of a certified planner, split into FCL time and Python time (issue 12).

Plans one scenario with one seed (no simplification), then times each FCL query type the
run used (collision, clearance, region) at 1,000 random free poses of the same map and
subtracts the estimated FCL time; prints one Markdown row::

    python scripts/edge_cost.py scenarios/2d/slanted_gap.yaml kc-rrtconnect 1

Run it from another checkout (``PYTHONPATH=OTHER python scripts/edge_cost.py ...``) to
compare two versions of the validator on the same seeds.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from kcplan.planning.problem import plan
from kcplan.world import CollisionWorld, load_scenario


def per_query(fn, poses) -> float:
    t0 = time.perf_counter()
    for p in poses:
        fn(p)
    return (time.perf_counter() - t0) / len(poses)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario")
    parser.add_argument("planner")
    parser.add_argument("seed", type=int)
    args = parser.parse_args()
    scenario = load_scenario(args.scenario)
    world = CollisionWorld(scenario)
    r = plan(scenario, args.planner, 10.0, args.seed, simplify=False, world=world)
    c = dict(r.counters)
    edges = c.get("kc_edges", 0)
    rng = np.random.default_rng(0)
    low, high = scenario.bounds
    poses = []
    while len(poses) < 1000:
        t = rng.uniform(low, high)
        if scenario.dimension == 2:
            p = np.append(t, rng.uniform(-np.pi, np.pi))
        else:
            q = rng.normal(size=4)
            p = np.append(t, q / np.linalg.norm(q))
        if not world.in_collision(p):
            poses.append(p)
    fcl_time = c["collision_queries"] * per_query(world.in_collision, poses)
    fcl_time += c["distance_queries"] * per_query(world.safe_clearance, poses)
    if c.get("region_queries"):
        horizon = float(max(scenario.semi_axes))
        fcl_time += c["region_queries"] * per_query(lambda p: world.free_region(p, horizon), poses)
    calls = max(edges + c.get("checker_calls", 0), 1)
    print(
        f"| {scenario.name} | {args.planner} | {args.seed} | {r.time:.3f} | {edges} "
        f"| {c['fcl_queries']} | {1e6 * r.time / max(edges, 1):.1f} "
        f"| {1e6 * (r.time - fcl_time) / calls:.1f} |"
    )


if __name__ == "__main__":
    main()
