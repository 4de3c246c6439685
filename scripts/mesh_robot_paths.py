"""Plan a mesh robot's scenario and check every path against the part's own mesh.

The robot of ``scenarios/3d/hand_through_slot.yaml`` is the Panda hand's collision mesh,
covered by ellipsoids (``robot: {mesh: ..., bodies: 4}``). Each planner runs ``--runs``
times (interleaved, one process, one OMPL seed); every path is checked without gaps
twice with python-fcl (:func:`kcplan.planning.verify.verify_path`): the cover the planner
used, and the hand's own mesh (``kcplan verify --mesh``)::

    python scripts/mesh_robot_paths.py [SCENARIO] [--runs 10] [--time 10] [--planners ...]
"""

from __future__ import annotations

import argparse
import statistics
from pathlib import Path

from kcplan.planning.problem import plan, seed_ompl
from kcplan.planning.verify import verify_path
from kcplan.scenarios import load_scenario
from kcplan.world import CollisionWorld
from kcplan.world.part import PartWorld

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "3d" / "hand_through_slot.yaml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", nargs="?", default=str(SCENARIO))
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--time", type=float, default=10.0)
    parser.add_argument("--planners", default="kc-rrtconnect,rrtconnect,rrtconnect-fcl")
    args = parser.parse_args()
    scenario = load_scenario(args.scenario)
    if scenario.part is None:
        parser.error(f"{args.scenario}: expected a scenario whose robot is a mesh (robot.mesh)")
    seed_ompl(1)
    names = args.planners.split(",")
    world = CollisionWorld(scenario)
    part = PartWorld(CollisionWorld(scenario), scenario.part)
    cover = CollisionWorld(scenario)
    rows: dict[str, list] = {name: [] for name in names}
    for _ in range(args.runs):
        for name in names:
            r = plan(scenario, name, args.time, world=world)
            if not r.solved:
                rows[name].append((False, r.time, None, None))
                continue
            rows[name].append(
                (True, r.time, verify_path(cover, r.states), verify_path(part, r.states))
            )
    print(f"{scenario.name}: {scenario.robot.describe()} covering {scenario.part.describe()}")
    print("| planner | solved | median s | max s | cover colliding | part colliding "
          "| part min clearance |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    for name in names:
        runs = rows[name]
        solved = [x for x in runs if x[0]]
        times = [x[1] for x in runs]
        clear = min((x[3].min_clearance for x in solved if not x[3].collides), default=0.0)
        print(
            f"| {name} | {len(solved)}/{len(runs)} | {statistics.median(times):.3f} | "
            f"{max(times):.3f} | {sum(x[2].collides for x in solved)} | "
            f"{sum(x[3].collides for x in solved)} | {clear:.4g} |"
        )


if __name__ == "__main__":
    main()
