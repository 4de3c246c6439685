"""Whole-body problems in a bundled scene (issue 57): random starts and goals, free on the
meshes, for a robot whose base drives or whose two arms move at once.

Each problem is the scene of ``--scenario`` (its robot, its obstacles) with a start and a
goal drawn uniformly (seeded) in the planning group's box, kept when they are free for
the certifier (the links' hulls) and hence on the links' own meshes. With ``--across
AXIS`` (a moving base: ``world_joint/x``) the start's value of that joint is below
``-MARGIN`` and the goal's above ``MARGIN``, so that every problem crosses the scene (the
PR2 doorway's wall stands at x = 0). Writes ``DIR/NAME_K.yaml``, ``K = 1..N``::

    python scripts/make_whole_body_problems.py scenarios/arm/example_pr2_doorway.yaml \\
        --problems 10 --across world_joint/x -o benchmarks/whole-body/pr2
    kcplan bench benchmarks/whole-body/pr2/*.yaml --runs 5 --time 10 \\
        --planners kc-rrtconnect-lazy-native,rrtconnect-32-native -o ...
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import yaml

from kcplan.arm import ArmWorld
from kcplan.scenarios import dump_scenario, load_scenario

ATTEMPTS = 200_000
"""Random states drawn at most, in all."""


def draw(path: Path, problems: int, seed: int, across: str | None, margin: float, out: Path):
    """Write ``problems`` scenarios beside the scene of ``path`` into ``out``; their paths."""
    scenario = load_scenario(path)
    arm = scenario.arm
    world = ArmWorld(arm, scenario.obstacles, allowed=scenario.allowed,
                     padding=scenario.padding)  # fmt: skip
    data = yaml.safe_load(path.read_text())  # the robot as written: states in its order
    axis = None if across is None else arm.joints.index(across)
    rng = np.random.default_rng(seed)
    out.mkdir(parents=True, exist_ok=True)
    written, pending = [], None
    for _ in range(ATTEMPTS):
        q = rng.uniform(arm.lower, arm.upper)
        if axis is not None:  # the start before the margin, the goal beyond it
            wrong_side = q[axis] > -margin if pending is None else q[axis] < margin
            if wrong_side:
                continue
        if world.in_collision(q):  # the hulls hold the meshes: free here is free there
            continue
        if pending is None:
            pending = q
            continue
        name = f"{scenario.name}_{len(written) + 1}"
        problem = {**data, "name": name, "description": f"{scenario.name} with a random start "
                   f"and goal (scripts/make_whole_body_problems.py, seed {seed})"}  # fmt: skip
        problem["start"] = {"joints": [round(float(v), 6) for v in pending]}
        problem["goal"] = {"joints": [round(float(v), 6) for v in q]}
        target = out / f"{name}.yaml"
        dump_scenario(problem, target)
        load_scenario(target)  # read back: the start and the goal are checked on the meshes
        written.append(target)
        pending = None
        if len(written) == problems:
            return written
    raise SystemExit(f"{path}: {len(written)} of {problems} problems in {ATTEMPTS} states")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", type=Path)
    parser.add_argument("--problems", type=int, default=10)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--across", metavar="JOINT", help="the start below -MARGIN, the goal "
                        "above MARGIN along this joint")  # fmt: skip
    parser.add_argument("--margin", type=float, default=0.3)
    parser.add_argument("-o", "--output", type=Path, required=True)
    args = parser.parse_args(argv)
    for path in draw(args.scenario, args.problems, args.seed, args.across, args.margin,
                     args.output):  # fmt: skip
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
