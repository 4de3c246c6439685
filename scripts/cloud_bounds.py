"""What each of a point cloud's cheaper bounds buys (issue 55): the same plans with each
switched off.

The kernel measures a link (or ellipsoid) against a cloud by walking its k-d tree and
asking, for each node and point, bounds cheaper than GJK before GJK itself
(``kcplan/_kernel/point_cloud.hpp``): a hull's 26 fixed planes, the planes GJK's nearest
points have shown, the support along the centres' line (an ellipsoid's or a ball's; a
hull's was dropped, and the shape's own box, after this script measured them). Switched
off (``World.set_cloud_bounds``), the answers stay the same and only the work changes.
For each scenario and each setting, ``--seeds`` plans (default planner, seeds 1..N in
one fresh process per setting, so every setting sees the same sampling) report the median
solve and simplification times and the tree's work (nodes and points bounded, points
measured by GJK), side by side::

    python scripts/cloud_bounds.py [--seeds 5] [SCENARIO ...]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = [
    ROOT / "scenarios/arm/box_1_cloud.yaml",
    ROOT / "scenarios/arm/table_pick_1_depth.yaml",
]
SETTINGS = {
    "all": {},
    "no 26 planes": {"dop": False},
    "no GJK planes": {"gjk_planes": False},
    "no centre line": {"centre_line": False},
    "none": {"dop": False, "gjk_planes": False, "centre_line": False},
}


def run(scenario: str, setting: dict, seeds: int) -> dict:
    """Plan ``seeds`` times in this process (OMPL's seed is per process: seed 1, then the
    same stream) and return times and the clouds' counters."""
    from kcplan.arm.world import ArmWorld
    from kcplan.planning.problem import plan
    from kcplan.scenarios import load_scenario

    problem = load_scenario(scenario)
    rows = []
    for seed in range(1, seeds + 1):
        world = ArmWorld(problem.arm, problem.obstacles, allowed=problem.allowed)
        world.kernel.scene.set_cloud_bounds(**setting)
        result = plan(problem, seed=seed, time_limit=20, world=world)
        counters = world.kernel.scene.cloud_counters
        rows.append({"solved": result.solved, "time": result.time,
                     "simplify": result.simplify_time, **counters})  # fmt: skip
    return {"rows": rows}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", default=[str(p) for p in SCENARIOS])
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--step", help=argparse.SUPPRESS)  # one setting, in a child
    args = parser.parse_args(argv)
    if args.step:
        scenario, name = json.loads(args.step)
        print(json.dumps(run(scenario, SETTINGS[name], args.seeds)))
        return 0
    print("| scenario | bounds | solved | solve, median ms | simplify, median ms | "
          "nodes / query | points / query | GJK / query |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for scenario in args.scenarios:
        for name in SETTINGS:
            out = subprocess.run(
                [sys.executable, __file__, "--seeds", str(args.seeds), "--step",
                 json.dumps([scenario, name])],
                capture_output=True, text=True, check=True,
            ).stdout  # fmt: skip
            rows = json.loads(out)["rows"]
            queries = max(sum(r["queries"] for r in rows), 1)
            per = {k: sum(r[k] for r in rows) / queries for k in ("nodes", "points", "exact")}
            print(f"| {Path(scenario).stem} | {name} | {sum(r['solved'] for r in rows)} / "
                  f"{len(rows)} | {statistics.median(r['time'] for r in rows) * 1e3:.1f} | "
                  f"{statistics.median(r['simplify'] for r in rows) * 1e3:.1f} | "
                  f"{per['nodes']:.1f} | {per['points']:.1f} | {per['exact']:.2f} |",
                  flush=True)  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
