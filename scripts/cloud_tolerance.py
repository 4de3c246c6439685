"""What a cloud's distance tolerance buys (issue 55): the same plans with the kernel's
cloud searches exact and at a relative tolerance, side by side, and on the primitives.

A guard needs a lower bound of a link's distance to the cloud, not the distance: the
kernel's tree search may stop once no unvisited point can be nearer than the nearest
found divided by 1 + tolerance (``DistanceTolerance`` in
``kcplan/_kernel/point_cloud.hpp``; ``World.cloud_tolerance``, 0.25 by default). For the
MotionBenchMaker Panda problems ``--problems`` (default the first two of each class),
sampled as clouds exactly as ``scripts/cloud_mbm.py`` samples them (10,000 points per
object, every point a ball of 2.5 mm), each seed plans once per setting: the cloud at
each tolerance of ``--tolerances``, then the problem's primitives, one after another in
one process, so that the machine's noise falls on every setting alike. The world (the
cloud's tree) is built before the clock for every setting: only the solve and its
shortcuts are timed. It prints, per setting, the plans solved and the medians of the
solve, the shortcuts and their sum (ms), the cloud's queries and its points measured by
GJK per plan, and the
median over the plans of each setting's planning time divided by that of the exact
search (tolerance 0) and by that of the primitives::

    python scripts/cloud_tolerance.py [--seeds 3] [--tolerances 0,0.25,0.5] [--json out.json]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import statistics
import sys
from pathlib import Path

sys.path.insert(0, os.fspath(Path(__file__).resolve().parent))
import cloud_mbm  # noqa: E402  (the clouds exactly as RESULTS 30 samples them)

PROBLEMS = ",".join(f"{c}:{i}" for c in cloud_mbm.CLASSES for i in (1, 2))
PRIMITIVES = "primitives"


def _scenarios(keys: list[tuple[str, int]]) -> dict:
    """{key: (cloud scenario, primitive scenario)} of the MBM Panda problems."""
    from kcplan.arm.mbm import load_mbm_archive

    mbm = load_mbm_archive(os.fspath(cloud_mbm.MBM / "panda" / "problems.tar.bz2"), keys)
    out = {}
    for key in keys:
        problem = mbm[key]
        prims = cloud_mbm._scenario(problem, f"{key[0]}_{key[1]}", "panda", Path("."))
        points = cloud_mbm.problem_cloud(problem.obstacles, 10000, 1, *key)
        cloud = dataclasses.replace(prims, obstacles=(cloud_mbm.cloud_obstacle(points, 0.0025),))
        out[key] = (cloud, prims)
    return out


def _plan(scenario, tolerance: float | None, seed: int) -> dict:
    """One plan of the default arm planner, its world built (and its cloud tolerance set)
    before the clock."""
    from kcplan import plan
    from kcplan.arm.world import ArmWorld

    world = ArmWorld(scenario.arm, scenario.obstacles, allowed=scenario.allowed)
    if tolerance is not None:
        world.kernel.scene.cloud_tolerance = tolerance
    before = world.kernel.scene.cloud_counters
    result = plan(scenario, seed=seed, time_limit=10, world=world)
    after = world.kernel.scene.cloud_counters
    return {"solved": result.solved, "solve": result.time, "simplify": result.simplify_time,
            **{key: after[key] - before[key] for key in ("queries", "exact")}}  # fmt: skip


def run(keys: list[tuple[str, int]], tolerances: list[float], seeds: int) -> dict:
    """{setting: [plan rows]}, the settings interleaved plan by plan."""
    scenarios = _scenarios(keys)
    _plan(scenarios[keys[0]][1], None, 0)  # imports and caches: not measured
    names = [f"{t:g}" for t in tolerances] + [PRIMITIVES]
    rows: dict[str, list[dict]] = {name: [] for name in names}
    for key in keys:
        cloud, prims = scenarios[key]
        for seed in range(1, seeds + 1):
            for name, tolerance in zip(names, [*tolerances, None], strict=True):
                row = _plan(prims if tolerance is None else cloud, tolerance, seed)
                rows[name].append({"problem": f"{key[0]}:{key[1]}", "seed": seed, **row})
            print(f"{key[0]}:{key[1]} done", file=sys.stderr, flush=True)
    return rows


def table(rows: dict[str, list[dict]]) -> list[str]:
    """The Markdown table of :func:`run`'s rows."""
    names = list(rows)
    exact, prims = rows[names[0]], rows[PRIMITIVES]

    def planning(r: dict) -> float:
        return r["solve"] + r["simplify"]

    def ratio(setting: list[dict], base: list[dict]) -> str:
        both = [planning(a) / planning(b) for a, b in zip(setting, base, strict=True)
                if a["solved"] and b["solved"] and planning(b) > 0]  # fmt: skip
        return f"{statistics.median(both):.2f}" if both else "-"

    lines = [
        "| setting | solved | solve ms | shortcuts ms | planning ms | cloud queries | "
        f"GJK calls | planning / tolerance {names[0]} | planning / primitives |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name in names:
        setting = rows[name]
        solved = [r for r in setting if r["solved"]]

        def med(f, solved=solved):
            return statistics.median(f(r) for r in solved) if solved else float("nan")

        label = name if name == PRIMITIVES else f"cloud, tolerance {name}"
        lines.append(
            f"| {label} | {len(solved)}/{len(setting)} | {med(lambda r: r['solve']) * 1e3:.2f} | "
            f"{med(lambda r: r['simplify']) * 1e3:.2f} | {med(planning) * 1e3:.2f} | "
            f"{med(lambda r: r['queries']):.0f} | {med(lambda r: r['exact']):.0f} | "
            f"{ratio(setting, exact)} | {ratio(setting, prims)} |"
        )  # fmt: skip
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--problems", default=PROBLEMS, help="CLASS:INDEX,... (MBM Panda)")
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--tolerances", default="0,0.25,0.5",
                        help="relative tolerances, the first the ratios' base")  # fmt: skip
    parser.add_argument("--json", help="write every plan's row here")
    args = parser.parse_args(argv)
    try:
        keys = [(c, int(i)) for c, i in (s.split(":") for s in args.problems.split(","))]
        tolerances = [float(t) for t in args.tolerances.split(",")]
    except ValueError:
        print("cloud_tolerance.py: --problems expects CLASS:INDEX,... and --tolerances "
              "numbers separated by commas", file=sys.stderr)  # fmt: skip
        return 2
    if args.seeds < 1 or any(not t >= 0 for t in tolerances):
        print("cloud_tolerance.py: expected --seeds >= 1 and tolerances >= 0", file=sys.stderr)
        return 2
    rows = run(keys, tolerances, args.seeds)
    print("\n".join(table(rows)))
    if args.json:
        from kcplan.files import write_text_atomic

        write_text_atomic(args.json, json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
