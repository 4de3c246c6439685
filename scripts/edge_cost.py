"""Time per edge of a certified planner, split into FCL time and Python time (issue 12).

Plans one scenario with one seed (no simplification) and prints one Markdown row::

    python scripts/edge_cost.py scenarios/2d/slanted_gap.yaml kc-rrtconnect-py 1

Columns: scenario, planner, seed, solve seconds, certified edges, queries, solve µs per
certified edge, µs per call, seconds outside the calls.

For a planner on the Python backend (``kc-*-py``, ``*-fcl``) the FCL queries are timed per
type the run used (collision, clearance, region) at 1,000 random free poses of the same
map, and "µs per call" is the remaining (Python) time per certified edge or state check.
For a planner on the compiled kernel (``kc-*``, stock planners) the queries column holds
the kernel world's query counts (coal) and "µs per call" is the time spent in the
validator's and the state checker's calls (reading the OMPL states and the one call into
the kernel; timed around each call, which adds about 0.1 µs) per certified edge or state
check. The rest of the solve time is OMPL's own work (sampling, nearest neighbours, tree
bookkeeping, the calls' way in and out of Python): the last column, in seconds (``-`` on
the Python backend). No validator, however fast, makes the run shorter than that.

Run it from another checkout (``PYTHONPATH=OTHER python scripts/edge_cost.py ...``) to
compare two versions of the validator on the same seeds.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from kcplan.planning import setups
from kcplan.planning.problem import plan
from kcplan.planning.validator import KCMotionValidator
from kcplan.scenarios import load_scenario
from kcplan.world import CollisionWorld

QUERY_KEYS = ("collision_queries", "distance_queries", "region_queries")


def per_query(fn, poses) -> float:
    t0 = time.perf_counter()
    for p in poses:
        fn(p)
    return (time.perf_counter() - t0) / len(poses)


def free_poses(scenario, world: CollisionWorld, count: int) -> list[np.ndarray]:
    rng = np.random.default_rng(0)
    low, high = scenario.bounds
    poses = []
    while len(poses) < count:
        t = rng.uniform(low, high)
        if scenario.dimension == 2:
            p = np.append(t, rng.uniform(-np.pi, np.pi))
        else:
            q = rng.normal(size=4)
            p = np.append(t, q / np.linalg.norm(q))
        if not world.in_collision(p):
            poses.append(p)
    return poses


def fcl_time(scenario, world: CollisionWorld, counts: dict, poses: int) -> float:
    """Estimated seconds the run spent in python-fcl queries of ``counts``."""
    sample = free_poses(scenario, world, poses)
    seconds = counts["collision_queries"] * per_query(world.in_collision, sample)
    distances = counts["distance_queries"]
    if counts["region_queries"]:
        horizon = float(world.robot.largest_semi_axis)  # the certifier's default horizon
        before = world.counters["distance_queries"]
        seconds += counts["region_queries"] * per_query(
            lambda p: world.free_regions(p, horizon), sample
        )
        # a region query in open space issues a distance query, timed with the region
        inner = (world.counters["distance_queries"] - before) / len(sample)
        distances = max(distances - inner * counts["region_queries"], 0.0)
    return seconds + distances * per_query(world.safe_body_clearances, sample)


class CallTimer:
    """Seconds spent in the kernel-backed validator and state checker of :func:`plan`,
    by wrapping the functions it binds (restored on exit)."""

    def __init__(self):
        self.seconds = 0.0
        self._saved = []

    def _timed(self, fn):
        def timed(*args):
            t0 = time.perf_counter()
            try:
                return fn(*args)
            finally:
                self.seconds += time.perf_counter() - t0

        return timed

    def __enter__(self) -> CallTimer:
        for name in ("_check_kernel_se2", "_check_kernel_se3", "_valid_kernel_se2",
                     "_valid_kernel_se3"):  # fmt: skip
            self._saved.append((KCMotionValidator, name, getattr(KCMotionValidator, name)))
            setattr(KCMotionValidator, name, self._timed(getattr(KCMotionValidator, name)))
        checker = setups.kernel_state_checker
        self._saved.append((setups, "kernel_state_checker", checker))
        setups.kernel_state_checker = lambda kernel, n: self._timed(checker(kernel, n))
        return self

    def __exit__(self, *exc) -> None:
        for owner, name, value in reversed(self._saved):
            setattr(owner, name, value)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario")
    parser.add_argument("planner")
    parser.add_argument("seed", type=int)
    parser.add_argument("--time", type=float, default=10.0, help="solve time limit [s]")
    parser.add_argument("--poses", type=int, default=1000, help="free poses to time FCL on")
    args = parser.parse_args()
    scenario = load_scenario(args.scenario)
    world = CollisionWorld(scenario)
    with CallTimer() as timer:
        r = plan(scenario, args.planner, args.time, args.seed, simplify=False, world=world)
    c = dict(r.counters)
    edges = c.get("kc_edges", 0)
    calls = max(edges + c.get("checker_calls", 0), 1)
    if r.backend == "python":
        queries = c["fcl_queries"]
        rest = r.time - fcl_time(scenario, world, c, args.poses)
        outside = "-"
    else:
        kernel = world.kernel.counters
        queries = sum(kernel[key] for key in QUERY_KEYS)
        rest = timer.seconds
        outside = f"{max(r.time - timer.seconds, 0.0):.3f}"
    per_edge = f"{1e6 * r.time / edges:.1f}" if edges else "-"  # a stock planner has none
    print(
        f"| {scenario.name} | {args.planner} | {args.seed} | {r.time:.3f} | {edges} "
        f"| {queries} | {per_edge} | {1e6 * rest / calls:.1f} | {outside} |"
    )


if __name__ == "__main__":
    main()
