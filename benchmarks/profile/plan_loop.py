"""Plans of MotionBenchMaker Panda problems, on their primitives or as clouds, repeated in
one process: what `perf record` samples in RESULTS 34.2 (run.sh). Prints the medians of the
whole call, the solve and the shortcuts.

    python benchmarks/profile/plan_loop.py [--prims] [--seeds N] [--problems CLASS:I,...]
"""

import argparse
import dataclasses
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, os.fspath(Path(__file__).resolve().parents[2] / "scripts"))
import cloud_mbm  # noqa: E402  (the clouds exactly as RESULTS 30 samples them)

from kcplan import plan  # noqa: E402
from kcplan.arm.mbm import load_mbm_archive  # noqa: E402

PROBLEMS = ",".join(f"{c}:{i}" for c in cloud_mbm.CLASSES for i in (1, 3))

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--problems", default=PROBLEMS)
parser.add_argument("--seeds", type=int, default=3)
parser.add_argument("--prims", action="store_true", help="plan on the primitives")
parser.add_argument("--planner", default="kc-rrtconnect-lazy-native")
args = parser.parse_args()
keys = [(c, int(i)) for c, i in (s.split(":") for s in args.problems.split(","))]
mbm = load_mbm_archive(os.fspath(cloud_mbm.MBM / "panda" / "problems.tar.bz2"), keys)
scenarios = {}
for key in keys:
    problem = mbm[key]
    scenario = cloud_mbm._scenario(problem, f"{key[0]}_{key[1]}", "panda", Path("."))
    if not args.prims:
        points = cloud_mbm.problem_cloud(problem.obstacles, 10000, 1, *key)
        cloud = cloud_mbm.cloud_obstacle(points, 0.0025)
        scenario = dataclasses.replace(scenario, obstacles=(cloud,))
    scenarios[key] = scenario
plan(scenarios[keys[0]], args.planner, seed=0, time_limit=10)  # imports, caches: not timed
rows = []
for key in keys:
    for seed in range(1, args.seeds + 1):
        t0 = time.perf_counter()
        result = plan(scenarios[key], args.planner, seed=seed, time_limit=10)
        rows.append((time.perf_counter() - t0, result.time, result.simplify_time))
print(f"plans {len(rows)}: median ms whole {statistics.median(r[0] for r in rows) * 1e3:.1f}, "
      f"solve {statistics.median(r[1] for r in rows) * 1e3:.1f}, "
      f"shortcuts {statistics.median(r[2] for r in rows) * 1e3:.1f}")
