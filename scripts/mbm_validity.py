"""How many MotionBenchMaker starts and goals are valid for kcplan's covered arm (issue 25).

For each problem class, reads the first ``--per-class`` problems of VAMP's
``problems.tar.bz2`` (:mod:`kcplan.arm.mbm`), and checks the request's start and goal
twice: for the arm covered by ``--bodies`` ellipsoids per link
(:class:`kcplan.arm.ArmWorld`, what a certifier plans with) and for the links' own
collision meshes (:func:`kcplan.arm.verify.verify_arm_path` at the one state), both with
the scene's allowed collision matrix. A state valid on the meshes but not for the cover
is one the cover makes unreachable. Representations: ``--hulls`` (each link its own convex
hull, kcplan's default, :mod:`kcplan.arm.hulls`), ``--bodies K,...`` (exactly K per link, the
smallest union) and ``--max-offset D,...`` (metres: as many per link as it takes to
stick out by at most D, :func:`kcplan.arm.load_arm`; ``default`` is
:data:`kcplan.arm.model.DEFAULT_MAX_OFFSET`). Prints a Markdown table, one line per cover
(bodies, self pairs, time to load), and with ``--offsets`` how far each link's cover
sticks out of its mesh (mm: the fit's proved bound for ``--max-offset`` covers, the
sampled estimate :func:`kcplan.cover.offset.cover_offsets` for ``--bodies`` ones) and
how many bodies it has::

    python scripts/mbm_validity.py [--per-class 100] [--hulls] [--bodies 1,2] [--max-offset default]
        [--most K] [--offsets]
"""

from __future__ import annotations

import argparse
import math
import os
import time
from pathlib import Path

from kcplan.arm import ArmWorld, load_arm
from kcplan.arm.mbm import MBM_CLASSES, load_mbm_archive
from kcplan.arm.model import DEFAULT_MAX_OFFSET, mesh_cover
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
    parser.add_argument("--hulls", action="store_true", help="each link its own convex hull")
    parser.add_argument("--bodies", default="", help="bodies per link, comma-separated")
    parser.add_argument("--max-offset", default="", help="metres (or 'default'), comma-separated")
    parser.add_argument(
        "--most", type=int, default=None, help="most bodies per link of --max-offset covers"
    )
    parser.add_argument("--offsets", action="store_true", help="also how far covers stick out")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    problems = load_mbm_archive(args.archive)
    print(f"{len(problems)} problems read in {time.perf_counter() - t0:.1f} s")
    groups = {p.joints for p in problems.values()}
    if len(groups) != 1:
        parser.error(f"archive: expected one planning group, got {sorted(groups)}")
    (joints,) = groups
    covers = [("hulls", None, None)] if args.hulls else []
    covers += [("ellipsoids", b, None) for b in (int(k) for k in args.bodies.split(",") if k)]
    for text in (t for t in args.max_offset.split(",") if t):
        offset = DEFAULT_MAX_OFFSET if text == "default" else float(text)
        covers.append(("ellipsoids", args.most, offset))
    if not covers:
        parser.error("expected --hulls, --bodies or --max-offset")
    print("| cover | class | problems | starts valid: cover / meshes | "
          "goals valid: cover / meshes | lost to the cover |")  # fmt: skip
    print("|---|---|---|---|---|---|")
    arms, notes = [], []
    for representation, bodies, max_offset in covers:
        t0 = time.perf_counter()
        arm = load_arm(args.urdf, joints, srdf=args.srdf, bodies_per_link=bodies,
                       max_offset=max_offset, progress=_fitted,
                       representation=representation)  # fmt: skip
        label = f"{bodies}" if max_offset is None else f"<= {1000 * max_offset:g} mm"
        if max_offset is not None and bodies is not None:
            label += f", at most {bodies}"
        if representation == "hulls":
            label = "hulls"
        else:
            arms.append((label, bodies, max_offset, arm))
        notes.append(f"{label}: {len(arm.bodies)} bodies, {len(arm.self_pairs)} self pairs, "
                     f"loaded in {time.perf_counter() - t0:.1f} s")  # fmt: skip
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
            print(f"| {label} | {problem_class} | {row[0]} | {row[1]} / {row[2]} | "
                  f"{row[3]} / {row[4]} | {row[5]} |")  # fmt: skip
        print(f"| {label} | all | {totals[0]} | {totals[1]} / {totals[2]} | "
              f"{totals[3]} / {totals[4]} | {totals[5]} |")  # fmt: skip
    print()
    for line in notes:
        print(f"- {line}")
    if args.offsets:
        print_offsets(arms)
    return 0


def _fitted(line: str) -> None:
    """Say how long each link's cover took when it was fitted (not cached)."""
    if "cached" not in line:
        print(f"- covered {line}", flush=True)


def print_offsets(arms: list) -> None:
    """How far each link's cover sticks out of its mesh, in mm: the sampled estimate for a
    cover of K bodies per link, the fit's proved bound and the number of bodies for a
    ``--max-offset`` cover."""
    heads = [
        f"{label} bodies: offset mm (sampled)" if max_offset is None
        else f"{label}: offset mm, proved (bodies)"
        for label, _, max_offset, _ in arms
    ]  # fmt: skip
    print(f"\n| link | {' | '.join(heads)} |")
    print(f"|---|{'---|' * len(arms)}")
    for obj in arms[0][3].geometry.geometryObjects:
        if not obj.meshPath or type(obj.geometry).__name__ in ("Box", "Cylinder", "Sphere"):
            continue  # a primitive: covered exactly, not fitted
        cells = []
        for _, bodies, max_offset, _ in arms:
            cover, _ = mesh_cover(obj.meshPath, bodies, float(obj.meshScale[0]), max_offset)
            if max_offset is None or math.isnan(cover.offset):
                cells.append(f"{1000 * cover_offsets(cover.solid, cover.bodies).max():.0f}")
            else:
                cells.append(f"{1000 * cover.offset:.1f} ({len(cover.bodies)})")
        print(f"| {obj.name} | {' | '.join(cells)} |")


if __name__ == "__main__":
    raise SystemExit(main())
