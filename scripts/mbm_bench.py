"""The MotionBenchMaker table of issue 25: kc and stock planners (and VAMP) per problem class.

For the first ``--per-class`` problems of each class of a robot's ``problems.tar.bz2``
(VAMP's MBM archive, :mod:`kcplan.arm.mbm`):

1. each problem becomes an arm scenario, as ``kcplan import mbm`` writes it
   (:func:`kcplan.arm.mbm.mbm_scenario`), in ``DIR/scenarios/CLASS_INDEX.yaml``, with the
   representation chosen here (default: kcplan's, each link its own convex hull; or an
   ellipsoid cover, ``--bodies-per-link``, ``--max-offset``); a problem whose start
   or goal the cover touches (valid on the meshes, but not for the covered arm) is
   counted as *invalid for the cover* and not planned: no planner on that cover can
   solve it; with ``--padding P`` (metres) every scenario keeps ``robot.padding: P``
   (MoveIt's link padding: every certified path at least ``P`` from every obstacle), and a
   start or goal nearer than ``P`` to an obstacle is counted there too;
2. ``kcplan bench`` runs every ``--planners`` on the others, one run each (seed
   ``--seed``), ``--time`` seconds, no simplification (``--simplify``: with it, and its
   median milliseconds and the median path length in the table), into ``DIR/bench`` (its OMPL
   logs, ``results.db`` and ``summary.csv``; every path verified without gaps on the
   links' own collision meshes);
3. with ``--vamp-python`` (a Python with VAMP, ``bash ../shared/tools/vamp/build-vamp.sh
   PYTHON``), ``scripts/vamp_mbm.py`` plans the same problems with VAMP's RRT-Connect
   and its own sphere model, its paths checked by the same mesh verifier.

It prints (and writes to ``DIR/mbm_table.md``) one Markdown table: per class, the
problems, how many are invalid for the cover, and per planner solved / planned, the
median time in milliseconds over the planned problems (an unsolved one counts at the time
limit, so a planner cannot look fast by failing) and how many returned paths collide on
the meshes; VAMP's columns are over all the class's problems, its time VAMP's own
planning time in milliseconds::

    python scripts/mbm_bench.py [--robot panda|ur5] [--per-class 20] [--classes box,cage]
        [--planners kc-rrtconnect,rrtconnect,...] [--time 10] [--representation R]
        [--bodies-per-link K] [--max-offset D] [--jobs J] [--simplify] [--padding P]
        [--vamp-python PY] [-o DIR]

A shared, loaded machine makes the times indicative; the counts are what they are.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import yaml

from kcplan.arm import ArmWorld
from kcplan.arm.mbm import MBM_CLASSES, load_mbm_archive, mbm_scenario
from kcplan.scenarios import dump_scenario, parse_scenario

ROOT = Path(__file__).resolve().parents[1]
MBM = ROOT.parent / "shared" / "data" / "external" / "mbm"
PLANNERS = ",".join((
    "kc-rrtconnect", "kc-rrtconnect-lazy", "rrtconnect", "rrtconnect-32", "rrtconnect-32-near",
    "rrtconnect-pin",
))  # fmt: skip
ROBOTS = {  # URDF and SRDF of each robot: the bundled Panda, the UR5 as MBM ships it
    "panda": (ROOT / "scenarios" / "arm" / "panda" / "panda.urdf",
              ROOT / "scenarios" / "arm" / "panda" / "panda.srdf"),
    "ur5": (MBM / "ur5" / "ur5.urdf", MBM / "ur5" / "ur5.srdf"),
}  # fmt: skip


def write_scenarios(args: argparse.Namespace, folder: Path) -> dict[str, list]:
    """Step 1: the scenarios of the chosen problems in ``folder``; per class the written
    files and the problems invalid for the cover (``(index, "start"|"goal"|"both")``)."""
    urdf, srdf = ROBOTS[args.robot]
    keys = [(c, i) for c in args.classes for i in range(1, args.per_class + 1)]
    problems = load_mbm_archive(Path(args.mbm) / args.robot / "problems.tar.bz2", keys)
    folder.mkdir(parents=True, exist_ok=True)
    out: dict[str, list] = {}
    arms: dict = {}
    t0 = time.perf_counter()
    for problem_class in args.classes:
        written, invalid = [], []
        for index in range(1, args.per_class + 1):
            if (problem_class, index) not in problems:
                continue
            problem = problems[problem_class, index]
            name = f"{problem_class}_{index}"
            path = folder / f"{name}.yaml"
            data = mbm_scenario(problem, name, urdf, srdf, path, args.bodies_per_link,
                                args.max_offset, args.representation)  # fmt: skip
            key = yaml.safe_dump(data["robot"], sort_keys=True)
            if key not in arms:  # one cover per robot description (fixed joints included)
                arms[key] = parse_scenario(data, os.fspath(path), folder, check=False).arm
            if args.padding > 0:
                data["robot"]["padding"] = args.padding
            world = ArmWorld(arms[key], problem.obstacles, allowed=problem.allowed,
                             padding=args.padding)  # fmt: skip
            # the kernel's query pads; python-fcl's (ArmWorld.in_collision) does not
            touched = [k for k, q in (("start", problem.start), ("goal", problem.goal))
                       if (world.kernel.in_collision(q.tolist()) if args.padding > 0
                           else world.in_collision(q))]  # fmt: skip
            if touched:
                invalid.append((index, "both" if len(touched) == 2 else touched[0]))
                continue
            dump_scenario(data, path)
            written.append(path)
        out[problem_class] = [written, invalid]
        print(f"{problem_class}: {len(written)} scenarios, {len(invalid)} invalid for the "
              f"cover ({time.perf_counter() - t0:.0f} s)", file=sys.stderr, flush=True)  # fmt: skip
    return out


def run_bench(args: argparse.Namespace, files: list[Path], folder: Path) -> list[dict]:
    """Step 2: ``kcplan bench`` on ``files``; the rows of its ``summary.csv``."""
    command = [sys.executable, "-m", "kcplan.cli", "bench", *map(os.fspath, files),
               "--planners", args.planners, "--runs", "1", "--seed", str(args.seed),
               "--time", str(args.time), *(() if args.simplify else ("--no-simplify",)),
               "--progress-interval", "0",
               "--jobs", str(args.jobs),
               "-o", os.fspath(folder), "--force"]  # fmt: skip
    subprocess.run(command, check=True, cwd=ROOT)
    with open(folder / "summary.csv", newline="") as f:
        return list(csv.DictReader(f))


def run_vamp(args: argparse.Namespace, folder: Path) -> dict:
    """Step 3: ``vamp_mbm.py`` on the same problems; its results and verdicts by
    ``(class, index)``."""
    out = folder / "vamp.json"
    command = [sys.executable, os.fspath(ROOT / "scripts" / "vamp_mbm.py"),
               "--robot", args.robot, "--per-class", str(args.per_class), "--calls", "1",
               "--vamp-python", args.vamp_python, "--json", os.fspath(out)]  # fmt: skip
    subprocess.run(command, check=True, cwd=ROOT, stdout=sys.stderr)
    data = json.loads(out.read_text())
    by_key = {(v["class"], v["index"]): v for v in data["verdicts"]}
    return {(r["class"], r["index"]): (r, by_key[r["class"], r["index"]]) for r in data["results"]}


def table(args: argparse.Namespace, scenarios: dict, rows: list[dict], vamp: dict) -> list[str]:
    """The Markdown table (module docstring)."""
    planners = args.planners.split(",")
    padded = f" or nearer than {args.padding:g} m" if args.padding > 0 else ""
    head = ["class", "problems", f"invalid for the cover{padded}"]
    for planner in planners:
        head += [f"{planner} solved", "median ms", "colliding"]
        if args.simplify:
            head += ["simplify ms", "length"]
    if vamp:
        head += ["VAMP solved", "median ms", "colliding"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    by_class = {c: [r for r in rows if r["scenario"].rsplit("_", 1)[0] == c] for c in scenarios}
    groups = [(c, [c]) for c in scenarios] + [("all", list(scenarios))]
    for label, classes in groups:
        planned = sum(len(scenarios[c][0]) for c in classes)
        invalid = sum(len(scenarios[c][1]) for c in classes)
        cells = [label, str(planned + invalid), str(invalid)]
        for planner in planners:
            mine = [r for c in classes for r in by_class[c] if r["planner"] == planner]
            solved = sum(int(r["solved"]) for r in mine)
            times = [1e3 * float(r["median_time"]) for r in mine]
            colliding = sum(int(r["colliding_paths"]) for r in mine)
            cells += [f"{solved} / {len(mine)}", _median(times), str(colliding)]
            if args.simplify:
                done = [r for r in mine if int(r["solved"])]
                cells += [_median([1e3 * float(r["median_simplify_time"]) for r in done]),
                          _median([float(r["median_length"]) for r in done])]  # fmt: skip
        if vamp:
            mine = [v for (c, _), v in vamp.items() if c in classes]
            solved = [r for r, _ in mine if r["solved"]]
            times = [statistics.median(r["plan_ms"]) if r["solved"] else 1e3 * args.time
                     for r, _ in mine]  # fmt: skip
            colliding = sum(bool(v["collides"]) for _, v in mine)
            cells += [f"{len(solved)} / {len(mine)}", _median(times), str(colliding)]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def _median(values: list[float], digits: int = 2) -> str:
    return f"{statistics.median(values):.{digits}f}" if values else "-"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", choices=sorted(ROBOTS), default="panda")
    parser.add_argument("--mbm", default=os.fspath(MBM), help="the MBM data folder")
    parser.add_argument("--per-class", type=int, default=20, help="problems per class (first N)")
    parser.add_argument("--classes", default=",".join(MBM_CLASSES), help="comma-separated")
    parser.add_argument("--planners", default=PLANNERS, help=f"default {PLANNERS}")
    parser.add_argument("--time", type=float, default=10.0, help="seconds per solve")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--jobs", type=int, default=1, help="runs at once (kcplan bench)")
    parser.add_argument("--simplify", action="store_true",
                        help="simplify the paths too, and show its median ms and the length")
    parser.add_argument(
        "--representation",
        choices=("hulls", "ellipsoids"),
        default=None,
        help="the links' bodies (default: kcplan's, hulls)",
    )
    parser.add_argument("--bodies-per-link", type=int, default=None,
                        help="the cover: exactly K bodies per link (or, with --max-offset, "
                        "at most K)")  # fmt: skip
    parser.add_argument("--max-offset", type=float, default=None,
                        help="the cover: metres it may stick out of each link's mesh")  # fmt: skip
    parser.add_argument("--padding", type=float, default=0.0,
                        help="metres every path keeps from the obstacles (robot.padding)")
    parser.add_argument("--vamp-python", help="a Python with VAMP: also run VAMP")
    parser.add_argument("-o", "--output", default="mbm-bench", help="output folder")
    args = parser.parse_args(argv)
    args.classes = args.classes.split(",")
    unknown = sorted(set(args.classes) - set(MBM_CLASSES))
    if unknown or args.per_class < 1 or args.time <= 0:
        parser.error(f"--classes: expected some of {', '.join(MBM_CLASSES)}; --per-class "
                     f"and --time: positive (got {unknown or ''})")  # fmt: skip
    if not (args.padding >= 0 and math.isfinite(args.padding)):
        parser.error(f"--padding: expected a finite number >= 0 (metres), got {args.padding}")
    folder = Path(args.output).resolve()  # the bench runs from the repository's root
    scenarios = write_scenarios(args, folder / "scenarios")
    files = [path for written, _ in scenarios.values() for path in written]
    rows = run_bench(args, files, folder / "bench") if files else []
    vamp = run_vamp(args, folder) if args.vamp_python else {}
    if vamp:
        vamp = {k: v for k, v in vamp.items() if k[0] in scenarios}
    lines = table(args, scenarios, rows, vamp)
    for problem_class, (_, invalid) in scenarios.items():
        if invalid:
            lines.append(f"\ninvalid for the cover, {problem_class}: "
                         + ", ".join(f"{i} ({which})" for i, which in invalid))  # fmt: skip
    text = "\n".join(lines) + "\n"
    (folder / "mbm_table.md").write_text(text)
    print(text, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
