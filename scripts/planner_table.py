"""Time to a first solution of every kc planner and its stock twin on two suite maps.

Each run is a fresh process (OMPL's seed applies once per process), stopped at the first
exact solution (``plan(..., first_solution=True)``: asymptotically optimal planners do not
run on to the limit; AORRTC, which ignores that stop, is timed by its recorded first
solution, ``PlanResult.first_solution_time``); every path is verified without gaps.
Prints a markdown table::

    python scripts/planner_table.py [--runs 3] [--time 5] [--jobs 2] \
        [--maps scenarios/2d/random_clutter.yaml scenarios/3d/box_field.yaml] \
        [--planners rrtconnect prm ...]

``--planners`` names stock planners, each run with its kc twin (default: RRT-Connect, PRM
and every planner of :data:`kcplan.planning.names.CERTIFIABLE`).
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import statistics
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MAPS = ("scenarios/2d/random_clutter.yaml", "scenarios/3d/box_field.yaml")


def run(job: tuple[str, str, int, float]) -> tuple[str, str, bool, float, bool]:
    path, planner, seed, budget = job
    from kcplan import load_scenario, plan

    scenario = load_scenario(ROOT / path)
    result = plan(scenario, planner, budget, seed=seed, first_solution=True, progress=0.1)
    collides = result.solved and result.verify().collides
    first = result.time if result.first_solution_time is None else result.first_solution_time
    return path, planner, result.solved, first, collides


def main() -> None:
    from kcplan.planning.names import CERTIFIABLE

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--time", type=float, default=5.0)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--maps", nargs="+", default=list(MAPS), help="scenarios (from the root)")
    bases = ("rrtconnect", "prm", *CERTIFIABLE)
    parser.add_argument("--planners", nargs="+", default=list(bases), choices=bases)
    args = parser.parse_args()
    maps = args.maps
    planners = [p for base in args.planners for p in (f"kc-{base}", base)]
    jobs = [(m, p, 1 + i, args.time) for m in maps for p in planners for i in range(args.runs)]
    with mp.get_context("spawn").Pool(args.jobs, maxtasksperchild=1) as pool:
        results = pool.map(run, jobs, chunksize=1)
    names = [Path(m).stem for m in maps]
    print("| planner | " + " | ".join(f"{n}: solved, median s" for n in names) + " |")
    print("|---|" + "---|" * len(maps))
    for planner in planners:
        cells = []
        for m in maps:
            mine = [r for r in results if r[0] == m and r[1] == planner]
            solved = [r for r in mine if r[2]]
            median = statistics.median(r[3] for r in mine)  # unsolved at the limit
            bad = sum(r[4] for r in mine)
            cells.append(
                f"{len(solved)}/{len(mine)}, {median:.3g}" + (f" ({bad} colliding)" if bad else "")
            )
        print(f"| `{planner}` | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
