"""What the Morton-ordered tree of a point cloud buys (issue 55): its build, and the work
and time of plans on it, against the median-split k-d tree it replaced.

The kernel's cloud (``kcplan/_kernel/point_cloud.hpp``) sorts its points along a Morton
curve by a radix sort and splits each node where its cell splits (``CloudOrder.morton``,
the default); ``CloudOrder.median`` is the k-d tree of median splits along each box's
longest side. Both answer every query alike (tested against every point); only the work
differs. Two tables:

- **build**: ``World.add_points`` of ``--sizes`` uniform random points in a cube,
  min and median of ``--repeats`` builds per order;
- **plans**: the first ``--per-class`` MotionBenchMaker Panda problems of ``--classes``,
  each scene as 10,000 surface points per object (``cloud_mbm.py``'s clouds), planned by
  ``kc-rrtconnect-lazy-native`` with seeds 1..``--seeds`` on the same world rebuilt in
  each order (``World.set_cloud_order``), side by side: solved, median solve +
  simplification, and per cloud query the tree's nodes and points bounded and the points
  measured by GJK::

    python scripts/cloud_tree_order.py [--sizes 10000 100000 1000000] [--repeats 5]
        [--per-class 2] [--classes box,cage] [--seeds 3]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))

ORDERS = ("morton", "median")
POINT_RADIUS = 0.0025  # metres: VAMP's, as cloud_mbm.py plans with by default


def build_times(sizes: list[int], repeats: int) -> list[str]:
    """The build table's rows: points, then per order min / median ms."""
    from kcplan._kernel import CloudOrder, Robot, World

    rows = []
    for n in sizes:
        points = np.random.default_rng(0).uniform(-1.0, 1.0, (n, 3))
        cells = []
        for order in ORDERS:
            seconds = []
            for _ in range(repeats):
                world = World(Robot(3, [0.1, 0.1, 0.1], [0, 0, 0, 0, 0, 0, 1]), 1.0, 0.0, 0.0)
                t0 = time.perf_counter()
                world.add_points(points, POINT_RADIUS, getattr(CloudOrder, order))
                seconds.append(time.perf_counter() - t0)
            cells.append(f"{min(seconds) * 1e3:.1f} / {statistics.median(seconds) * 1e3:.1f}")
        rows.append(f"| {n:,} | {' | '.join(cells)} |")
    return rows


def plan_rows(per_class: int, classes: list[str], seeds: int) -> list[str]:
    """The plans table's rows: per problem and order, what the plans did."""
    import dataclasses

    import cloud_mbm

    from kcplan import plan
    from kcplan._kernel import CloudOrder
    from kcplan.arm import ArmWorld
    from kcplan.arm.mbm import load_mbm_archive

    archive = str(cloud_mbm.MBM / "panda" / "problems.tar.bz2")
    keys = [(c, i) for c in classes for i in range(1, per_class + 1)]
    problems = load_mbm_archive(archive, keys)
    rows = []
    for key in keys:
        if key not in problems:
            continue
        p = problems[key]
        points = cloud_mbm.problem_cloud(p.obstacles, 10_000, 1, *key)
        scenario = cloud_mbm._scenario(p, f"{key[0]}_{key[1]}", "panda", ROOT)
        cloud = dataclasses.replace(
            scenario, obstacles=(cloud_mbm.cloud_obstacle(points, POINT_RADIUS),)
        )
        for order in ORDERS:
            done = []
            for seed in range(1, seeds + 1):
                world = ArmWorld(cloud.arm, cloud.obstacles, allowed=cloud.allowed)
                world.kernel.scene.set_cloud_order(getattr(CloudOrder, order))
                world.kernel.scene.reset_counters()
                result = plan(cloud, "kc-rrtconnect-lazy-native", seed=seed, time_limit=10,
                              world=world)  # fmt: skip
                done.append((result, world.kernel.scene.cloud_counters))
            queries = max(sum(c["queries"] for _, c in done), 1)
            per = {k: sum(c[k] for _, c in done) / queries for k in ("nodes", "points", "exact")}
            solved = sum(r.solved for r, _ in done)
            ms = statistics.median((r.time + r.simplify_time) * 1e3 for r, _ in done)
            rows.append(f"| {key[0]} {key[1]} | {len(points):,} | {order} | {solved} / "
                        f"{len(done)} | {ms:.1f} | {per['nodes']:.1f} | {per['points']:.1f} | "
                        f"{per['exact']:.2f} |")  # fmt: skip
            print(rows[-1], file=sys.stderr, flush=True)
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--per-class", type=int, default=2)
    parser.add_argument("--classes", default="table_pick,box,bookshelf_thin,cage")
    parser.add_argument("--seeds", type=int, default=3)
    args = parser.parse_args(argv)
    if min(args.sizes + [args.repeats, args.per_class, args.seeds]) < 1:
        parser.error("--sizes, --repeats, --per-class and --seeds: expected positive integers")
    print("| points | Morton build, min / median ms | median-split build, min / median ms |")
    print("|---|---|---|")
    print("\n".join(build_times(args.sizes, args.repeats)))
    print()
    print("| problem | points | tree | solved | solve + simplify, median ms | nodes / query "
          "| points / query | GJK / query |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    classes = [c for c in args.classes.split(",") if c]
    print("\n".join(plan_rows(args.per_class, classes, args.seeds)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
