"""Do RRT-Connect's range and PRM's neighbour count suit certified edges? (issue 12)

Runs kc-rrtconnect, ca-rrtconnect and stock rrtconnect at several ranges (fractions of the
space's maximum extent; OMPL's default is 0.2), and kc-prm and prm with several maximum
nearest-neighbour counts (OMPL's default 10), on the same seeds, each run in a fresh
process (OMPL seeds once per process), and prints medians as a Markdown table::

    python scripts/planner_settings.py scenarios/2d/slanted_gap.yaml ... [--runs 6] \
        [--ranges 0.025 0.05 0.2] [--neighbors 5 10 20] [--time 10]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys

RANGES = (0.025, 0.05, 0.2)
NEIGHBORS = (5, 10, 20)
TIME_LIMIT = 10.0

_RUN = """
import dataclasses, json, sys
from kcplan.planning import problem
from kcplan.scenarios import load_scenario
path, planner, key, value, seed, limit = sys.argv[1:7]
spec = problem.PLANNERS[planner]
value = float(value) if key == "range_factor" else int(value)
problem.PLANNERS[planner] = dataclasses.replace(spec, **{key: value})
r = problem.plan(load_scenario(path), planner, float(limit), int(seed), simplify=False)
print(json.dumps([r.solved, r.time, r.counters["fcl_queries"]]))
"""


def run(
    path: str, planner: str, key: str, value: float, seed: int, limit: float = TIME_LIMIT
) -> tuple[bool, float, int]:
    proc = subprocess.run(
        [sys.executable, "-c", _RUN, path, planner, key, str(value), str(seed), str(limit)],
        capture_output=True,
        text=True,
    )
    if proc.returncode:
        sys.exit(f"{planner} with {key} = {value}, seed {seed} failed:\n{proc.stderr}")
    solved, t, q = json.loads(proc.stdout.strip().splitlines()[-1])
    return solved, (t if solved else limit), q


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="+")
    parser.add_argument("--runs", type=int, default=6)
    parser.add_argument(
        "--ranges", type=float, nargs="+", default=list(RANGES), help="fractions of the extent"
    )
    parser.add_argument("--neighbors", type=int, nargs="+", default=list(NEIGHBORS))
    parser.add_argument("--time", type=float, default=TIME_LIMIT, help="time limit [s]")
    args = parser.parse_args()
    print("| scenario | planner | setting | solved | median time [s] | median FCL queries |")
    print("|---|---|---|---|---|---|")
    rrts = ("kc-rrtconnect", "ca-rrtconnect", "rrtconnect")
    grid = [(p, "range_factor", v) for p in rrts for v in args.ranges]
    grid += [(p, "neighbors", v) for p in ("kc-prm", "prm") for v in args.neighbors]
    for path in args.scenarios:
        name = path.rsplit("/", 1)[-1].removesuffix(".yaml")
        for planner, key, value in grid:
            runs = [
                run(path, planner, key, value, seed, args.time) for seed in range(1, args.runs + 1)
            ]
            label = f"range {value:g}" if key == "range_factor" else f"k = {value}"
            print(
                f"| {name} | {planner} | {label} | {sum(r[0] for r in runs)}/{len(runs)} "
                f"| {statistics.median(r[1] for r in runs):.3f} "
                f"| {statistics.median(r[2] for r in runs):.0f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
