"""How many MotionBenchMaker starts and goals are valid for kcplan's covered arm (issue 25).

For each problem class, reads the first ``--per-class`` problems of VAMP's
``problems.tar.bz2`` (:mod:`kcplan.arm.mbm`), and checks the request's start and goal
twice: for the arm covered by ``--bodies`` ellipsoids per link
(:class:`kcplan.arm.ArmWorld`, what a certifier plans with) and for the links' own
collision meshes (:func:`kcplan.arm.verify.verify_arm_path` at the one state), both with
the scene's allowed collision matrix. A state valid on the meshes but not for the cover
is one the cover makes unreachable. Prints a Markdown table, and with ``--offsets`` a
second one: how far each link's cover sticks out of its mesh
(:func:`kcplan.cover.offset.cover_offsets`)::

    python scripts/mbm_validity.py [--per-class 100] [--bodies 1,2] [--offsets]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from kcplan.arm import ArmWorld, load_arm
from kcplan.arm.mbm import MBM_CLASSES, load_mbm_archive
from kcplan.arm.model import mesh_cover
from kcplan.arm.verify import verify_arm_path
from kcplan.cover.offset import cover_offsets

ROOT = Path(__file__).resolve().parents[1]
ARCHIVE = ROOT.parent / "shared" / "data" / "external" / "mbm" / "panda" / "problems.tar.bz2"
PANDA = ROOT / "scenarios" / "arm" / "panda"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--archive", default=os.fspath(ARCHIVE))
    parser.add_argument("--urdf", default=os.fspath(PANDA / "panda.urdf"))
    parser.add_argument("--srdf", default=os.fspath(PANDA / "panda.srdf"))
    parser.add_argument("--per-class", type=int, default=100)
    parser.add_argument("--bodies", default="1", help="bodies per link, comma-separated")
    parser.add_argument("--offsets", action="store_true", help="also how far covers stick out")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    problems = load_mbm_archive(args.archive)
    print(f"{len(problems)} problems read in {time.perf_counter() - t0:.1f} s")
    groups = {p.joints for p in problems.values()}
    if len(groups) != 1:
        parser.error(f"archive: expected one planning group, got {sorted(groups)}")
    (joints,) = groups
    print("| bodies per link | class | problems | starts valid: cover / meshes | "
          "goals valid: cover / meshes | lost to the cover |")  # fmt: skip
    print("|---|---|---|---|---|---|")
    for bodies in (int(b) for b in args.bodies.split(",")):
        arm = load_arm(args.urdf, joints, srdf=args.srdf, bodies_per_link=bodies)
        totals = [0, 0, 0, 0, 0, 0]
        for problem_class in MBM_CLASSES:
            chosen = [problems[problem_class, i] for i in range(1, args.per_class + 1)
                      if (problem_class, i) in problems]  # fmt: skip
            counts = [0, 0, 0, 0, 0]
            for problem in chosen:
                world = ArmWorld(arm, problem.obstacles, allowed=problem.allowed)
                for k, q in enumerate((problem.start, problem.goal)):
                    cover = arm.within_limits(q) and not world.in_collision(q)
                    meshes = not verify_arm_path(
                        arm, problem.obstacles, [q, q], allowed=problem.allowed
                    ).collides
                    counts[2 * k] += cover
                    counts[2 * k + 1] += meshes
                    counts[4] += meshes and not cover
            row = [len(chosen), *counts]
            totals = [a + b for a, b in zip(totals, row, strict=True)]
            print(f"| {bodies} | {problem_class} | {row[0]} | {row[1]} / {row[2]} | "
                  f"{row[3]} / {row[4]} | {row[5]} |")  # fmt: skip
        print(f"| {bodies} | all | {totals[0]} | {totals[1]} / {totals[2]} | "
              f"{totals[3]} / {totals[4]} | {totals[5]} |")  # fmt: skip
    if args.offsets:
        print_offsets(arm, [int(b) for b in args.bodies.split(",")])
    return 0


def print_offsets(arm, counts: list[int]) -> None:
    """How far each link's cover sticks out of its mesh, in mm, per bodies per link."""
    print(f"\n| link | {' | '.join(f'{k} bodies: offset mm' for k in counts)} |")
    print(f"|---|{'---|' * len(counts)}")
    for obj in arm.geometry.geometryObjects:
        if not obj.meshPath:
            continue
        cells = []
        for k in counts:
            cover, _ = mesh_cover(obj.meshPath, k, float(obj.meshScale[0]))
            cells.append(f"{1000 * cover_offsets(cover.solid, cover.bodies).max():.0f}")
        print(f"| {obj.name} | {' | '.join(cells)} |")


if __name__ == "__main__":
    raise SystemExit(main())
