"""Certified trajectories on MotionBenchMaker (issue 40): smoothing, timing, limits, meshes.

For the first ``--per-class`` problems of each class of a robot's MBM archive (the
scenarios ``kcplan import mbm`` writes, each link its own convex hull), kc-rrtconnect
plans (``--time`` seconds, seed ``--seed``, OMPL's simplifier on), then the path is
smoothed by certified blends and timed by TOPP-RA within the URDF's velocity limits and
the default acceleration limits (:func:`kcplan.trajectory.certified.certified_trajectory`).
Each trajectory is then checked by code independent of its certificate:

- its limits at 1 kHz (``|qd_j| / v_j`` and ``|qdd_j| / a_j``, the largest; tolerance
  1e-6 relative), beside the exact peaks the timing reports;
- its whole continuous curve on the links' own meshes, without gaps
  (:meth:`kcplan.arm.verify.ArmMeshChecker.check_pieces`);

and its duration is set against the same path timed alike with a stop at every corner.
With ``--corners N`` it also draws N random corners per problem (two certified edges
through a random configuration of the scene) and re-checks every blend
:func:`kcplan.trajectory.smoothing.certify_blends` accepts there on the meshes (the
smoothing's soundness study).

It prints (and writes to ``DIR/trajectory_table.md``, rows to ``DIR/rows.json``) per
class: solved, median planning time, median time to smooth and time (s), median duration
ratio smoothed / stopping, the largest 1 kHz limit ratios, colliding curves, and the
corners' blends checked and colliding; then one line on OMPL's certified shortcutting
(the path's length after and before it, the edges it had certified against the
planner's, its time against solve()'s)::

    python scripts/trajectory_bench.py [--robot panda|ur5] [--per-class 20]
        [--classes box,cage] [--time 10] [--seed 1] [--corners 0] [-o DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from kcplan.arm import ArmWorld
from kcplan.arm.mbm import MBM_CLASSES, load_mbm_archive, mbm_scenario
from kcplan.arm.verify import ArmMeshChecker
from kcplan.files import write_text_atomic
from kcplan.planning.problem import plan
from kcplan.scenarios import dump_scenario, parse_scenario
from kcplan.trajectory.curve import BlendedPath
from kcplan.trajectory.smoothing import certify_blends

ROOT = Path(__file__).resolve().parents[1]
MBM = ROOT.parent / "shared" / "data" / "external" / "mbm"
ROBOTS = {
    "panda": (ROOT / "scenarios" / "arm" / "panda" / "panda.urdf",
              ROOT / "scenarios" / "arm" / "panda" / "panda.srdf"),
    "ur5": (MBM / "ur5" / "ur5.urdf", MBM / "ur5" / "ur5.srdf"),
}  # fmt: skip
LIMIT_TOLERANCE = 1e-6


def corners(scenario, world, checker, count: int, rng) -> tuple[int, int, int]:
    """``count`` random certified corners of the scene: (blends checked, colliding, larger
    than the corner's own guard proves)."""
    from kcplan._kernel import ArmCertifier

    arm = scenario.arm
    certifier = ArmCertifier(world.kernel)
    checked = colliding = larger = tries = 0
    while checked < count and tries < 200 * count:
        tries += 1
        c = rng.uniform(arm.lower, arm.upper)
        q0 = np.clip(c + rng.normal(0.0, 0.4, arm.dof), arm.lower, arm.upper)
        q2 = np.clip(c + rng.normal(0.0, 0.4, arm.dof), arm.lower, arm.upper)
        if not (certifier.state_valid(q0.tolist()) and certifier.check(q0.tolist(), c.tolist())
                and certifier.check(c.tolist(), q2.tolist())):  # fmt: skip
            continue
        certificate = certify_blends(world, [q0, c, q2])
        path = BlendedPath([q0, c, q2], certificate.blends)
        curve = [p for p, bent in zip(path.pieces(), path.curved, strict=True) if bent]
        checked += 1
        larger += bool(certificate.blends[0] > certificate.radii[0] * (1 + 1e-9))
        colliding += bool(checker.check_pieces(curve).collides)
    return checked, int(colliding), int(larger)


def run(args: argparse.Namespace) -> list[dict]:
    """Plan, smooth, time and check every chosen problem; one row each."""
    import toppra  # noqa: F401  (imported once here, not inside the first timing)

    urdf, srdf = ROBOTS[args.robot]
    keys = [(c, i) for c in args.classes for i in range(1, args.per_class + 1)]
    problems = load_mbm_archive(Path(args.mbm) / args.robot / "problems.tar.bz2", keys)
    folder = Path(args.output) / "scenarios"
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    rows = []
    for problem_class in args.classes:
        for index in range(1, args.per_class + 1):
            if (problem_class, index) not in problems:
                continue
            problem = problems[problem_class, index]
            name = f"{problem_class}_{index}"
            path = folder / f"{name}.yaml"
            data = mbm_scenario(problem, name, urdf, srdf, path, None, None, "hulls")
            scenario = parse_scenario(data, os.fspath(path), folder, check=False)
            dump_scenario(data, path)  # to plan it again: kcplan plan PATH --trajectory T
            row = {"class": problem_class, "index": index}
            world = ArmWorld(scenario.arm, scenario.obstacles, allowed=scenario.allowed)
            if world.in_collision(scenario.start) or world.in_collision(scenario.goal):
                rows.append(row | {"valid": False})
                continue
            result = plan(scenario, "kc-rrtconnect", args.time, args.seed, world=world,
                          trajectory=True)  # fmt: skip
            row |= {"valid": True, "solved": result.solved, "plan_time": result.time,
                    "simplify_time": result.simplify_time, "length": result.length,
                    "raw_length": result.raw_length,
                    "simplify_edges": result.counters.get("kc_simplify_edges", 0),
                    "planner_edges": result.counters.get("kc_edges", 0)
                    - result.counters.get("kc_simplify_edges", 0)}  # fmt: skip
            if result.solved:
                timed = result.trajectory
                t, _, _, qd, qdd = timed.timed.sample(1000.0)
                rv, ra = timed.timed.peak_ratios()
                checker = ArmMeshChecker(scenario.arm, scenario.obstacles, scenario.allowed)
                check = checker.check_pieces(timed.path.pieces())
                row |= {
                    "smooth_time": timed.seconds,
                    "duration": timed.timed.duration,
                    "stop_duration": timed.stop_duration,
                    "velocity_1khz": float((np.abs(qd) / timed.timed.velocity_limits).max()),
                    "acceleration_1khz": float(
                        (np.abs(qdd) / timed.timed.acceleration_limits).max()
                    ),
                    "velocity_peak": rv,
                    "acceleration_peak": ra,
                    "colliding": bool(check.collides),
                    "blends": timed.certificate.summary()["blends"],
                }
                if args.corners:
                    c, bad, big = corners(scenario, world, checker, args.corners, rng)
                    row |= {"corners": c, "corners_colliding": bad, "corners_larger": big}
            rows.append(row)
            shown = {k: v for k, v in row.items() if k not in ("class", "index")}
            print(f"{name}: {json.dumps(shown)}", file=sys.stderr, flush=True)
    return rows


def _median(values: list[float], digits: int = 3) -> str:
    return f"{statistics.median(values):.{digits}f}" if values else "-"


def table(rows: list[dict], corners: bool) -> list[str]:
    """The Markdown table (module docstring)."""
    head = ("| class | solved / valid | plan, median s | smooth + time, median s | "
            "duration / stopping, median | largest qd/v, qdd/a at 1 kHz | "
            "colliding on the meshes |")  # fmt: skip
    lines = [head + (" corners: blends checked, colliding, beyond one guard |" if corners else ""),
             "|---" * (7 + corners) + "|"]  # fmt: skip
    classes = list(dict.fromkeys(r["class"] for r in rows)) + ["all"]
    for name in classes:
        rs = [r for r in rows if r["class"] == name or name == "all"]
        valid = [r for r in rs if r.get("valid")]
        solved = [r for r in valid if r.get("solved")]
        cells = [
            f"**{name}**" if name == "all" else name,
            f"{len(solved)} / {len(valid)}",
            _median([r["plan_time"] for r in valid]),
            _median([r["smooth_time"] for r in solved]),
            _median([r["duration"] / r["stop_duration"] for r in solved], 2),
            (f"{max((r['velocity_1khz'] for r in solved), default=0):.6f}, "
             f"{max((r['acceleration_1khz'] for r in solved), default=0):.6f}"),
            str(sum(r["colliding"] for r in solved)),
        ]  # fmt: skip
        if corners:
            cells.append(f"{sum(r.get('corners', 0) for r in solved)}, "
                         f"{sum(r.get('corners_colliding', 0) for r in solved)}, "
                         f"{sum(r.get('corners_larger', 0) for r in solved)}")  # fmt: skip
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--robot", choices=sorted(ROBOTS), default="panda")
    p.add_argument("--per-class", type=int, default=20)
    p.add_argument("--classes", default=",".join(MBM_CLASSES))
    p.add_argument("--time", type=float, default=10.0)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--corners", type=int, default=0, help="random corners per problem")
    p.add_argument("--mbm", default=str(MBM), help="the MBM folder (its ROBOT/problems.tar.bz2)")
    p.add_argument("-o", "--output", default="trajectory-bench")
    args = p.parse_args(argv)
    args.classes = [c for c in args.classes.split(",") if c]
    unknown = [c for c in args.classes if c not in MBM_CLASSES]
    if unknown:
        p.error(f"--classes: expected names of {', '.join(MBM_CLASSES)}, got {unknown}")
    start = time.perf_counter()
    rows = run(args)
    lines = table(rows, args.corners > 0)
    out = Path(args.output)
    write_text_atomic(out / "rows.json", json.dumps(rows, indent=1) + "\n")
    write_text_atomic(out / "trajectory_table.md", "\n".join(lines) + "\n")
    print("\n".join(lines))
    solved = [r for r in rows if r.get("solved")]
    if solved:  # what OMPL's certified shortcutting bought and cost (RESULTS 14.3)
        ratio = statistics.median(r["length"] / r["raw_length"] if r["raw_length"] else 1.0
                                  for r in solved)  # fmt: skip
        print(f"shortcutting: length after / before {ratio:.2f} (median), "
              f"{statistics.median(r['simplify_edges'] for r in solved):.0f} certified edges "
              f"against the planner's {statistics.median(r['planner_edges'] for r in solved):.0f}, "
              f"{statistics.median(r['simplify_time'] for r in solved) * 1e3:.1f} ms against "
              f"{statistics.median(r['plan_time'] for r in solved) * 1e3:.1f} ms of solve()")
    bad = sum(r.get("colliding", False) for r in rows) + sum(r.get("corners_colliding", 0)
                                                              for r in rows)  # fmt: skip
    over = [r for r in rows if r.get("solved") and max(r["velocity_1khz"], r["acceleration_1khz"])
            > 1 + LIMIT_TOLERANCE]  # fmt: skip
    print(f"{len(rows)} problems in {time.perf_counter() - start:.0f} s; {bad} colliding, "
          f"{len(over)} beyond their limits", file=sys.stderr)  # fmt: skip
    return 1 if bad or over else 0


if __name__ == "__main__":
    sys.exit(main())
