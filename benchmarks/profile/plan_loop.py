"""Plans of MotionBenchMaker Panda problems, on their primitives or as clouds, repeated in
one process: what `perf record` samples in RESULTS 34.2 (run.sh). Prints the medians of the
whole call, the solve, the shortcuts and the rest (the world's build).

    python benchmarks/profile/plan_loop.py [--prims] [--seeds N] [--problems CLASS:I,...]
        [--fresh [--forget]] [--no-reach]

``--fresh`` reads each problem's scenario again before each plan, so that each plan has
an arm of its own, as ``scripts/cloud_mbm.py``'s problems do; ``--forget`` then empties
the kernel's chains and the pairs' proofs kept in memory before each plan, as each new
arm found them before RESULTS 36.1 (the ablation of those caches). ``--no-reach`` keeps
every point of a cloud, those beyond the arm's reach too (the ablation of RESULTS 36.2).
"""

import argparse
import dataclasses
import math
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, os.fspath(Path(__file__).resolve().parents[2] / "scripts"))
import cloud_mbm  # noqa: E402  (the clouds exactly as RESULTS 30 samples them)

from kcplan import _kernel, plan  # noqa: E402
from kcplan.arm import pairs  # noqa: E402
from kcplan.arm.mbm import load_mbm_archive  # noqa: E402
from kcplan.arm.world import ArmWorld  # noqa: E402

PROBLEMS = ",".join(f"{c}:{i}" for c in cloud_mbm.CLASSES for i in (1, 3))

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--problems", default=PROBLEMS)
parser.add_argument("--seeds", type=int, default=3)
parser.add_argument("--prims", action="store_true", help="plan on the primitives")
parser.add_argument("--planner", default="kc-rrtconnect-lazy-native")
parser.add_argument("--fresh", action="store_true", help="each plan on a scenario read anew")
parser.add_argument("--forget", action="store_true", help="each plan without the arm caches")
parser.add_argument("--no-reach", action="store_true",
                    help="clouds keep the points beyond the arm's reach (the ablation)")
args = parser.parse_args()
if args.no_reach:  # a ball of infinite radius: every point kept, as before RESULTS 36.2
    ArmWorld.reach = property(lambda self: ([0.0, 0.0, 0.0], math.inf))
keys = [(c, int(i)) for c, i in (s.split(":") for s in args.problems.split(","))]
mbm = load_mbm_archive(os.fspath(cloud_mbm.MBM / "panda" / "problems.tar.bz2"), keys)


def read(key):
    """The problem's scenario, read anew (a new arm), as a cloud unless ``--prims``."""
    problem = mbm[key]
    scenario = cloud_mbm._scenario(problem, f"{key[0]}_{key[1]}", "panda", Path("."))
    if not args.prims:
        scenario = dataclasses.replace(scenario, obstacles=(clouds[key],))
    return scenario


clouds = {key: cloud_mbm.cloud_obstacle(cloud_mbm.problem_cloud(mbm[key].obstacles, 10000, 1, *key),
                                        0.0025) for key in keys}  # fmt: skip
scenarios = {key: read(key) for key in keys}
plan(scenarios[keys[0]], args.planner, seed=0, time_limit=10)  # imports, caches: not timed
rows = []
for key in keys:
    for seed in range(1, args.seeds + 1):
        scenario = read(key) if args.fresh else scenarios[key]
        if args.forget:
            _kernel._CHAINS.clear()
            pairs._PROOFS.clear()
        t0 = time.perf_counter()
        result = plan(scenario, args.planner, seed=seed, time_limit=10)
        rows.append((time.perf_counter() - t0, result.time, result.simplify_time))
print(f"plans {len(rows)}: median ms whole {statistics.median(r[0] for r in rows) * 1e3:.1f}, "
      f"solve {statistics.median(r[1] for r in rows) * 1e3:.1f}, "
      f"shortcuts {statistics.median(r[2] for r in rows) * 1e3:.1f}, "
      f"build {statistics.median(r[0] - r[1] - r[2] for r in rows) * 1e3:.1f}")
