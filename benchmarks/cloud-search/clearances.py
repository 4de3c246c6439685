"""RESULTS 34.3: the same work on every kernel: a guard's clearances (`safe_clearances`)
and a state check (`in_collision`) on 400 fixed states of each of 14 MotionBenchMaker
Panda clouds (classes x indices 1 and 3; states about the start-goal line), best of 5
passes, and the clouds' counters. Swap the kernel's module between runs to compare.

    python benchmarks/cloud-search/clearances.py
"""

import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, os.fspath(Path(__file__).resolve().parents[2] / "scripts"))
import cloud_mbm  # noqa: E402

from kcplan.arm import ArmWorld  # noqa: E402
from kcplan.arm.mbm import load_mbm_archive  # noqa: E402

keys = [(c, i) for c in cloud_mbm.CLASSES for i in (1, 3)]
mbm = load_mbm_archive(os.fspath(cloud_mbm.MBM / "panda" / "problems.tar.bz2"), keys)
worlds = []
for key in keys:
    problem = mbm[key]
    scenario = cloud_mbm._scenario(problem, f"{key[0]}_{key[1]}", "panda", Path("."))
    points = cloud_mbm.problem_cloud(problem.obstacles, 10000, 1, *key)
    world = ArmWorld(scenario.arm, (cloud_mbm.cloud_obstacle(points, 0.0025),),
                     allowed=scenario.allowed)
    rng = np.random.default_rng(7)
    a, b = np.asarray(problem.start), np.asarray(problem.goal)
    t = rng.random((400, 1))
    states = np.clip(a + t * (b - a) + rng.normal(0.0, 0.4, (400, len(a))),
                     scenario.arm.lower, scenario.arm.upper)
    worlds.append((world.kernel, [list(map(float, q)) for q in states]))
best_clear = best_check = np.inf
for _ in range(5):
    clear = check = 0.0
    for kernel, states in worlds:
        t0 = time.perf_counter()
        for q in states:
            kernel.safe_clearances(q)
        clear += time.perf_counter() - t0
        t0 = time.perf_counter()
        for q in states:
            kernel.in_collision(q)
        check += time.perf_counter() - t0
    best_clear, best_check = min(best_clear, clear), min(best_check, check)
n = sum(len(states) for _, states in worlds)
print(f"states {n}: safe_clearances {best_clear / n * 1e6:.1f} us, "
      f"in_collision {best_check / n * 1e6:.2f} us (best of 5)")
counters = [kernel.scene.cloud_counters for kernel, _ in worlds]
print("cloud counters, 5 passes:", {k: sum(c[k] for c in counters) for k in counters[0]})
