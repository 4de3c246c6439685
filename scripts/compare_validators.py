"""Side-by-side comparison of kc planners with their stock twins (issue 4 performance).

Runs each planner ``--runs`` times per scenario in one process (same machine, same
moment), verifies every path with gap-free conservative advancement, and prints medians::

    python scripts/compare_validators.py scenarios/2d/narrow_corridor.yaml ... [--runs 7]
"""

from __future__ import annotations

import argparse
import statistics

from kcplan.planning.problem import plan, seed_ompl
from kcplan.planning.verify import verify_path
from kcplan.scenarios import load_scenario
from kcplan.world import CollisionWorld

PAIRS = [("kc-rrtconnect", "rrtconnect"), ("kc-prm", "prm")]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="+")
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--time", type=float, default=10.0)
    args = parser.parse_args()
    seed_ompl(1)
    print("| scenario | planner | solved | median time s | median FCL queries | colliding paths |")
    print("|---|---|---|---|---|---|")
    for path in args.scenarios:
        scenario = load_scenario(path)
        world = CollisionWorld(scenario)
        for pair in PAIRS:
            rows = {}
            for _ in range(args.runs):  # interleave the twins so both see the same load
                for name in pair:
                    r = plan(scenario, name, args.time, world=world)
                    bad = r.solved and verify_path(CollisionWorld(scenario), r.states).collides
                    rows.setdefault(name, []).append(
                        (r.solved, r.time, r.counters["fcl_queries"], bad)
                    )
            for name in pair:
                runs = rows[name]
                t = statistics.median(x[1] for x in runs)
                q = statistics.median(x[2] for x in runs)
                print(
                    f"| {scenario.name} | {name} | {sum(x[0] for x in runs)}/{len(runs)} | "
                    f"{t:.3f} | {q:.0f} | {sum(x[3] for x in runs)} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
