"""VAMP's RRT-Connect on MotionBenchMaker problems (Panda, UR5), its paths checked on the meshes.

The peer of issue 25 (item 6), for benchmarks only: VAMP (KavrakiLab, ``vamp-planner``
0.6.4) is never a dependency of kcplan. For the first ``--per-class`` problems of each
class of VAMP's ``problems.tar.bz2`` of ``--robot`` (``panda``, default, or ``ur5``; read
by :mod:`kcplan.arm.mbm`):

1. the scene is converted the way VAMP's own ``problem_tar_to_pkl_json.py`` and
   ``vamp.problem_dict_to_vamp`` do it: boxes are cuboids, cylinders capsules (in the
   ``box`` class cuboids of half extents ``(r, r, h / 2)``, VAMP's hack for its top-down
   grasp), spheres spheres; orientations as VAMP's ``euler_from_matrix`` (static xyz);
2. VAMP's RRT-Connect plans with its default settings
   (``vamp.configure_robot_and_planner_with_kwargs(ROBOT, "rrtc")``, Halton sampler
   reset before every call), ``--calls`` times per problem; the time is the median of
   VAMP's own ``PlanningResult.nanoseconds`` over the calls (planning, then
   simplification), in milliseconds;
3. the path of the first call is simplified as VAMP does (``vamp.panda.simplify`` with the
   default ``SimplifySettings``), and the simplified path (its waypoints, joined by
   straight joint-space segments) is checked without gaps on the links' own collision
   meshes by :func:`kcplan.arm.verify.verify_arm_path`, the verifier of kcplan's own
   paths, with the scene's allowed collision matrix and every joint outside the group
   fixed at its start value.

It prints one Markdown table: per class, problems, solved, median planning and
simplification time, and how many simplified paths collide on the meshes (then where
each colliding path first touches: segment and fraction ``s`` along it); ``--json``
also writes every path, time and verdict. Times are from the machine it runs on
(indicative on a shared, loaded one).

Two halves, each in a Python that has what it needs. kcplan's half (reading the problems,
verifying the paths) imports kcplan, whose collision world needs kcplan's compiled kernel
(kcplan's own environment); VAMP's half (steps 1-3 but the verification) needs only
``vamp`` and numpy. Whichever Python runs the script does the halves it can import and
runs the others in a subprocess of ``--vamp-python`` or ``--kcplan-python`` (default: the
repository's ``.venv``), passing JSON through the pipes (``--step read|plan|verify``)::

    # VAMP built into its own venv (bash ../shared/tools/vamp/build-vamp.sh PYTHON):
    /work/vamp-venv/bin/python scripts/vamp_mbm.py [--per-class 3] [--calls 5]
    python scripts/vamp_mbm.py --vamp-python /work/vamp-venv/bin/python ...  # kcplan's venv

Without VAMP (no ``import vamp`` and no ``--vamp-python``) it prints one line saying how
to build it and exits 2.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MBM = ROOT.parent / "shared" / "data" / "external" / "mbm"
ROBOTS = {  # URDF folder of each robot: the bundled Panda, the UR5 as MBM ships it
    "panda": ROOT / "scenarios" / "arm" / "panda",
    "ur5": MBM / "ur5",
}
BUILD = "bash ../shared/tools/vamp/build-vamp.sh PYTHON"
CLASSES = (
    "table_pick",
    "table_under_pick",
    "box",
    "bookshelf_small",
    "bookshelf_tall",
    "bookshelf_thin",
    "cage",
)  # kcplan.arm.mbm.MBM_CLASSES, here too for VAMP's half (which cannot import kcplan)


def read_problems(archive: str, per_class: int) -> list[dict]:
    """kcplan's half: the first ``per_class`` problems of each class as plain data
    (obstacles with their rotation matrices, metres; start and goal in radians)."""
    from kcplan.arm.mbm import MBM_CLASSES, load_mbm_archive

    if tuple(MBM_CLASSES) != CLASSES:
        raise RuntimeError(f"expected the classes {CLASSES}, kcplan has {MBM_CLASSES}")
    problems = load_mbm_archive(archive, [(c, i) for c in CLASSES for i in range(1, per_class + 1)])
    out = []
    for problem_class in CLASSES:
        for index in range(1, per_class + 1):
            if (problem_class, index) not in problems:
                continue
            p = problems[problem_class, index]
            obstacles = []
            for ob in p.obstacles:
                item = {
                    "kind": ob.kind,
                    "name": f"obstacle{ob.index}",
                    "position": ob.center.tolist(),
                    "rotation": ob.rotation.tolist(),
                }
                if ob.kind == "box":
                    item["half_extents"] = ob.extents.tolist()
                elif ob.kind == "cylinder":  # extents (r, r, h / 2)
                    item |= {"radius": float(ob.extents[0]), "length": 2 * float(ob.extents[2])}
                else:  # sphere
                    item["radius"] = float(ob.extents[0])
                obstacles.append(item)
            out.append(
                {
                    "class": problem_class,
                    "index": index,
                    "joints": list(p.joints),
                    "start": p.start.tolist(),
                    "goal": p.goal.tolist(),
                    "obstacles": obstacles,
                }
            )
    return out


def vamp_problem(problem: dict) -> dict:
    """A problem in the dictionary format of VAMP's ``problems.pkl`` (what
    ``problem_tar_to_pkl_json.py`` writes and ``vamp.problem_dict_to_vamp`` reads)."""
    import numpy as np
    from vamp.transformations import euler_from_matrix

    out: dict = {"problem": problem["class"], "sphere": [], "cylinder": [], "box": []}
    for ob in problem["obstacles"]:
        pose = np.eye(4)
        pose[:3, :3] = ob["rotation"]
        item = {
            "name": ob["name"],
            "position": list(ob["position"]),
            "orientation_euler_xyz": list(euler_from_matrix(pose)),
        }
        for key in ("half_extents", "radius", "length"):
            if key in ob:
                item[key] = ob[key]
        out[ob["kind"]].append(item)
    return out


def plan_problems(problems: list[dict], calls: int, robot: str = "panda") -> list[dict]:
    """VAMP's half: plan every problem ``calls`` times with VAMP's default RRT-Connect and
    simplify the first path; times in milliseconds (VAMP's own clock)."""
    import numpy as np
    import vamp

    module, rrtc, settings, simplify_settings = vamp.configure_robot_and_planner_with_kwargs(
        robot, "rrtc"
    )
    joints = list(module.joint_names())
    sampler = module.halton()
    results = []
    for problem in problems:
        if problem["joints"] != joints:
            raise ValueError(f"{problem['class']} {problem['index']}: expected joints {joints}")
        env = vamp.problem_dict_to_vamp(vamp_problem(problem))
        start = np.asarray(problem["start"], dtype=np.float32)
        goal = np.asarray(problem["goal"], dtype=np.float32)
        valid = bool(module.validate(start, env)) and bool(module.validate(goal, env))
        plan_ms, simplify_ms, path, solved = [], [], [], False
        for call in range(calls):
            sampler.reset()
            result = rrtc(start, goal, env, settings, sampler)
            if not result.solved:
                break
            simple = module.simplify(result.path, env, simplify_settings, sampler)
            plan_ms.append(result.nanoseconds * 1e-6)
            simplify_ms.append(simple.nanoseconds * 1e-6)
            if call == 0:
                solved = True
                path = np.asarray(simple.path.numpy(), dtype=float).tolist()
        results.append(
            {
                "class": problem["class"],
                "index": problem["index"],
                "valid_for_vamp": valid,
                "solved": solved and len(plan_ms) == calls,
                "plan_ms": plan_ms,
                "simplify_ms": simplify_ms,
                "path": path,
            }
        )
    return results


def verify_paths(archive: str, results: list[dict], robot: str = "panda") -> list[dict]:
    """kcplan's half: each solved path checked without gaps on the links' collision meshes
    (:func:`kcplan.arm.verify.verify_arm_path`); ``collides`` None when not solved."""
    import numpy as np

    from kcplan.arm import load_arm
    from kcplan.arm.mbm import load_mbm_archive
    from kcplan.arm.verify import verify_arm_path

    problems = load_mbm_archive(archive, [(r["class"], r["index"]) for r in results])
    arms: dict = {}
    verdicts = []
    for result in results:
        problem = problems[result["class"], result["index"]]
        verdict = {"class": result["class"], "index": result["index"], "collides": None}
        if result["solved"]:
            fixed = tuple(sorted((j, v) for j, v in problem.start_state.items()
                                 if j not in problem.joints))  # fmt: skip
            key = (problem.joints, fixed)
            if key not in arms:
                arms[key] = _arm(load_arm, robot, problem.joints, dict(fixed))
            check = verify_arm_path(
                arms[key], problem.obstacles, np.asarray(result["path"]), allowed=problem.allowed
            )
            verdict |= {
                "collides": bool(check.collides),
                "min_clearance": float(check.min_clearance),
                "where": [float(x) for x in check.where],  # (segment, s) of the first contact
            }
        verdicts.append(verdict)
    return verdicts


def _arm(load_arm, robot: str, joints, fixed: dict):
    """kcplan's arm of the MBM problems: the group, and the other joints that the URDF
    has fixed at their start values (as ``kcplan import mbm`` does). The verifier checks
    the links' meshes, not their cover: one body per link, the quickest cover to fit."""
    import pinocchio as pin

    urdf, srdf = ROBOTS[robot] / f"{robot}.urdf", ROBOTS[robot] / f"{robot}.srdf"
    model = pin.buildModelFromUrdf(os.fspath(urdf))
    fixed = {j: v for j, v in fixed.items() if model.existJointName(j)}
    return load_arm(urdf, joints, srdf=srdf, fixed=fixed, bodies_per_link=1)


STEPS = {"read": "kcplan", "plan": "vamp", "verify": "kcplan"}
"""Which half each step belongs to."""


def _can_import(name: str) -> bool:
    try:
        if name == "vamp":
            import vamp  # noqa: F401
        else:
            import kcplan.arm.verify  # noqa: F401  (needs kcplan's compiled kernel)
    except ImportError:
        return False
    return True


def _run_step(step: str, payload: dict, args: argparse.Namespace) -> list[dict]:
    """Run one step here when this Python has its half, else in the other Python."""
    half = STEPS[step]
    if _can_import(half):
        return _step(step, payload, args)
    python = args.vamp_python if half == "vamp" else args.kcplan_python
    command = [python, os.fspath(Path(__file__).resolve()), "--step", step,
               "--archive", args.archive, "--per-class", str(args.per_class),
               "--calls", str(args.calls), "--robot", args.robot]  # fmt: skip
    proc = subprocess.run(
        command, input=json.dumps(payload), capture_output=True, text=True, cwd=ROOT
    )
    if proc.returncode != 0:
        raise RuntimeError(f"{step} in {python} failed:\n{proc.stderr[-4000:]}")
    return json.loads(proc.stdout)


def _step(step: str, payload: dict, args: argparse.Namespace) -> list[dict]:
    if step == "read":
        return read_problems(args.archive, args.per_class)
    if step == "plan":
        return plan_problems(payload["problems"], args.calls, args.robot)
    return verify_paths(args.archive, payload["results"], args.robot)


def table(results: list[dict], verdicts: list[dict]) -> list[str]:
    """The Markdown table: per class, solved, median times (ms) and colliding paths."""
    lines = [
        "| class | problems | valid for VAMP | solved | median plan ms | median simplify ms "
        "| colliding paths (meshes) |",
        "|---|---|---|---|---|---|---|",
    ]
    rows = [(c, [r for r in results if r["class"] == c]) for c in CLASSES]
    for name, chosen in [*rows, ("all", results)]:
        if not chosen:
            continue
        keys = {(r["class"], r["index"]) for r in chosen}
        mine = [v for v in verdicts if (v["class"], v["index"]) in keys]
        solved = [r for r in chosen if r["solved"]]
        plan = [statistics.median(r["plan_ms"]) for r in solved]
        simplify = [statistics.median(r["simplify_ms"]) for r in solved]
        lines.append(
            f"| {name} | {len(chosen)} | {sum(r['valid_for_vamp'] for r in chosen)} "
            f"| {len(solved)} | {_median(plan)} | {_median(simplify)} "
            f"| {sum(bool(v['collides']) for v in mine)} of {len(solved)} |"
        )
    return lines


def _median(values: list[float]) -> str:
    return f"{statistics.median(values):.3f}" if values else "-"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", choices=sorted(ROBOTS), default="panda")
    parser.add_argument("--archive", help="VAMP's problems.tar.bz2 (default: the robot's)")
    parser.add_argument("--per-class", type=int, default=3, help="problems per class (first N)")
    parser.add_argument("--calls", type=int, default=5, help="VAMP calls per problem (median)")
    parser.add_argument("--vamp-python", help="a Python with vamp, when this one has none")
    parser.add_argument(
        "--kcplan-python",
        default=os.fspath(ROOT / ".venv" / "bin" / "python"),
        help="a Python with kcplan, when this one has none (default: the repository's .venv)",
    )
    parser.add_argument("--json", help="also write every result and verdict to this file")
    parser.add_argument("--step", choices=sorted(STEPS), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.archive is None:
        args.archive = os.fspath(MBM / args.robot / "problems.tar.bz2")
    if args.per_class < 1 or args.calls < 1:
        parser.error("--per-class and --calls: expected positive integers")
    if args.step is not None:  # one half, for the other Python: JSON in, JSON out
        payload = json.loads(sys.stdin.read() or "{}")
        print(json.dumps(_step(args.step, payload, args)))
        return 0
    if args.vamp_python is None and not _can_import("vamp"):
        print(
            f"vamp_mbm.py: VAMP is not installed in {sys.executable}: build it into a venv "
            f"with `{BUILD}` (see ../shared/tools/vamp/SOURCE.md), then run this script with "
            "that Python or pass --vamp-python",
            file=sys.stderr,
        )
        return 2
    problems = _run_step("read", {}, args)
    results = _run_step("plan", {"problems": problems}, args)
    verdicts = _run_step("verify", {"results": results}, args)
    for line in table(results, verdicts):
        print(line)
    if args.json:
        Path(args.json).write_text(json.dumps({"results": results, "verdicts": verdicts}) + "\n")
    for r, v in zip(results, verdicts, strict=True):
        if v["collides"]:
            segment, s = v["where"]
            print(f"colliding: {r['class']} {r['index']}: segment {int(segment)} of "
                  f"{len(r['path']) - 1}, at s = {s:.3f}")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
