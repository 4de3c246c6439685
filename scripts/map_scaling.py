"""Cost of certified edges as maps grow, from 10 to 10,000 obstacles (issue 12).

Generated clutter fields of rotated boxes at a constant density (one box per 100 square
units, so the side grows with the square root of the count) for a robot ellipse (2, 1),
and the Moving AI maze-128 conversion as a real map. For each map: the time to build the
collision world, then 2,000 random edges 10 long from free states, decided by the kc
certifier (free-region planes) and by the ca certifier (clearance ball), with the time
and FCL queries per edge and the pieces per region query; and the median time of 3
kc-rrtconnect / rrtconnect runs between a start and a goal 30 apart::

    python scripts/map_scaling.py [--counts 10 100 1000 10000] [--edges 2000] \
        [--runs 3] [--time 20] [--backend kernel]

``--backend kernel`` (the default) certifies with the compiled
:class:`kcplan.certification.kernel.KernelCertifier` on coal (the world build includes the
kernel's) and plans with kc-rrtconnect and rrtconnect; ``python`` certifies with
:class:`kcplan.certification.certifier.EdgeCertifier` on python-fcl and plans with their
python-fcl twins, kc-rrtconnect-py and rrtconnect-fcl.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from kcplan.certification.certifier import CERTIFICATE_SETS, EdgeCertifier
from kcplan.certification.kernel import KernelCertifier
from kcplan.planning.problem import plan, seed_ompl
from kcplan.scenarios import load_scenario, parse_scenario
from kcplan.world import CollisionWorld

ROOT = Path(__file__).resolve().parents[1]
DENSITY = 0.01  # boxes per square unit
PLANNERS = {  # backend -> the certified planner and its stock twin
    "kernel": ("kc-rrtconnect", "rrtconnect"),
    "python": ("kc-rrtconnect-py", "rrtconnect-fcl"),
}


def clutter(count: int, rng: np.random.Generator):
    side = float(np.sqrt(count / DENSITY))
    mid = side / 2
    obstacles = []
    while len(obstacles) < count:
        c = rng.uniform(0, side, 2)
        if min(np.linalg.norm(c - [mid - 15, mid]), np.linalg.norm(c - [mid + 15, mid])) < 6:
            continue  # keep start and goal free
        obstacles.append(
            {
                "box": {
                    "center": c.tolist(),
                    "size": rng.uniform(1, 4, 2).tolist(),
                    "yaw": float(rng.uniform(-np.pi, np.pi)),
                }
            }
        )
    data = {
        "name": f"clutter-{count}",
        "dimension": 2,
        "bounds": {"low": [0, 0], "high": [side, side]},
        "robot": {"semi_axes": [2.0, 1.0]},
        "start": {"position": [mid - 15, mid]},
        "goal": {"position": [mid + 15, mid]},
        "obstacles": obstacles,
    }
    return parse_scenario(data, check=False)


def edge_costs(
    world, scenario, edges: int, rng: np.random.Generator, backend: str = "kernel"
) -> dict:
    low, high = (np.asarray(b) for b in scenario.bounds)
    pairs = []
    while len(pairs) < edges:
        p1 = np.append(rng.uniform(low, high), rng.uniform(-np.pi, np.pi))
        if world.in_collision(p1):
            continue
        step = rng.normal(size=2)
        p2 = p1 + np.append(10 * step / np.linalg.norm(step), rng.normal(0, 0.3))
        pairs.append((p1, p2))
    out = {}
    for name in ("kc", "ca"):
        world.reset_counters()
        make = KernelCertifier if backend == "kernel" else EdgeCertifier
        certifier = make(world, certificates=CERTIFICATE_SETS[name])
        t0 = time.perf_counter()
        accepted = sum(certifier.check(p1, p2) for p1, p2 in pairs)
        elapsed = time.perf_counter() - t0
        c = world.counters
        queries = c["collision_queries"] + c["distance_queries"] + c["region_queries"]
        out[name] = {
            "us_per_edge": 1e6 * elapsed / edges,
            "queries_per_edge": queries / edges,
            "pieces_per_region": c["region_pairs"] / max(c["region_queries"], 1),
            "accepted": accepted / edges,
        }
    return out


def solve_times(
    scenario, world, runs: int = 3, limit: float = 20.0, backend: str = "kernel"
) -> dict:
    out = {}
    for planner in PLANNERS[backend]:
        times = []
        for _ in range(runs):
            r = plan(scenario, planner, limit, simplify=False, world=world)
            times.append(r.time if r.solved else limit)
        out[planner] = statistics.median(times)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--counts", type=int, nargs="+", default=[10, 100, 1000, 10000])
    parser.add_argument("--edges", type=int, default=2000)
    parser.add_argument("--runs", type=int, default=3, help="planning runs per planner")
    parser.add_argument("--time", type=float, default=20.0, help="planning time limit [s]")
    parser.add_argument(
        "--backend",
        choices=tuple(PLANNERS),
        default="kernel",
        help="who certifies: the compiled kernel (default) or the Python certifier",
    )
    args = parser.parse_args()
    certified, stock = PLANNERS[args.backend]
    seed_ompl(1)
    rng = np.random.default_rng(1)
    maps = [(f"clutter {n}", lambda n=n: clutter(n, rng)) for n in args.counts]
    maze = ROOT / "scenarios" / "movingai" / "maze-128-128-10.yaml"
    maps.append(("movingai maze-128", lambda: load_scenario(maze)))
    print(
        "| map | FCL objects | world build [s] | kc us/edge | kc queries/edge "
        f"| pieces/region query | ca us/edge | ca queries/edge | {certified} [s] "
        f"| {stock} [s] |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for label, make in maps:
        scenario = make()
        t0 = time.perf_counter()
        world = CollisionWorld(scenario)
        if args.backend == "kernel":
            world.kernel  # noqa: B018 - built on first use: part of the build time
        build = time.perf_counter() - t0
        costs = edge_costs(world, scenario, args.edges, rng, args.backend)
        solve = solve_times(scenario, world, args.runs, args.time, args.backend)
        kc, ca = costs["kc"], costs["ca"]
        print(
            f"| {label} | {world.n_objects} | {build:.2f} | {kc['us_per_edge']:.0f} "
            f"| {kc['queries_per_edge']:.2f} | {kc['pieces_per_region']:.1f} "
            f"| {ca['us_per_edge']:.0f} | {ca['queries_per_edge']:.2f} "
            f"| {solve[certified]:.3f} | {solve[stock]:.3f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
