"""kcplan and VAMP-CAPT side by side on MotionBenchMaker problems turned into point clouds.

The point-cloud benchmark of issue 55, for benchmarks only: VAMP (KavrakiLab,
``vamp-planner`` 0.6.4) is never a dependency of kcplan. For the first ``--per-class``
problems of each class (``--classes``, default all seven) of VAMP's ``problems.tar.bz2``
of ``--robot`` (``panda``, default, or ``ur5``; read by :mod:`kcplan.arm.mbm`):

1. **The cloud, once per problem, for both planners.** Every obstacle (box, cylinder,
   sphere) becomes a trimesh triangle mesh (a cylinder a 32-sided prism inscribed in it,
   a sphere a level-3 icosphere inscribed in it) and ``--points-per-object`` points
   (default 10,000, as VAMP's evaluation) are drawn uniformly by area on its surface with
   :func:`kcplan.world.pointcloud.sample_surface_points` (trimesh's ``sample_surface``),
   seeded by ``--seed``, the class, the problem and the obstacle: the same command gives
   the same points. VAMP's own sampler (``vamp.pointcloud.problem_to_pointcloud``,
   numpy's global RNG seeded 0) draws the same distribution on boxes (faces by area,
   uniform on each), draws cylinders on the true surface rather than a prism and puts
   its cap points at a uniform *radius* (denser near the axis), and skips spheres (MBM
   has none); this script uses trimesh's, for both planners.
2. **kcplan** (its own venv) plans on the raw cloud: every point a ball of radius
   ``--point-radius`` (default 0.0025 m, VAMP's ``POINT_RADIUS``), no filter, since
   kcplan's proof is about the original points. The obstacle is
   ``Obstacle(kind="pointcloud", ...)`` in place of the scenario's primitives, and
   :func:`kcplan.plan` (``--planner``, default kcplan's default arm planner; ``--time``
   seconds) is timed whole: ``plan`` is ``PlanResult.time`` (solve), ``simplify`` its
   ``simplify_time``, and ``build`` the rest of the call (the collision world with the
   cloud's compiled tree, the validator, OMPL's setup; not the self pairs proven apart
   once per robot, :mod:`kcplan.arm.pairs`, made before the clock: 0.1-0.9 s, in the
   JSON as ``pair_proofs_ms``). The same problem is planned on its primitives (the MBM
   scenario as ``kcplan import mbm`` makes it) for the ratio "planning on the cloud / on
   its primitives" (median over the problems both solved, of the ratio of solve times,
   and of the whole calls).
3. **VAMP** (a Python with ``vamp``: ``--vamp-python``) gets the same raw points and then
   does what ``vamp.pointcloud.problem_dict_to_pointcloud`` does after sampling (VAMP's
   ``evaluate_mbm.py --pointcloud``): ``vamp.filter_pointcloud(points, 0.02, max radius,
   first joint, its box, cull=True)`` (``--filter-radius``; ``ROBOT_MAX_RADII`` and
   ``ROBOT_FIRST_JOINT_LOCATIONS`` of ``vamp.constants``), then CAPT:
   ``Environment().add_pointcloud(filtered, r_min, r_max, point_radius)``
   (``r_min, r_max = vamp.ROBOT.min_max_radii()``), then its default RRT-Connect
   (``configure_robot_and_planner_with_kwargs(ROBOT, "rrtc")``, Halton sampler reset) and
   ``simplify``; times are VAMP's own nanoseconds (filter, CAPT build, plan, simplify),
   the median of ``--calls`` runs of the whole pipeline; the path is the first run's.
4. **Verification** (kcplan's venv), gap-free on the links' own collision meshes
   (:class:`kcplan.arm.verify.ArmMeshChecker`, what ``PlanResult.verify`` runs), with
   the scene's allowed collision matrix: kcplan's cloud path and VAMP's path against the
   raw cloud (every original point, at ``--point-radius``) and against the true
   primitives; kcplan's primitive path against the primitives. A check's steps shrink
   with the clearance, and a query near many points costs more than one near a box, so
   each check gets ``--verify-budget`` seconds (default 600; 0: no limit): it runs
   segment by segment in a forked child, and a path whose segments were not all checked
   in time is counted *unverified* (with the segments checked and the least clearance
   so far), never free.

It prints one Markdown table (times in milliseconds, medians over the solved problems):
per class, the problems, points, what VAMP's filter kept, solved (kc, VAMP), kcplan's
build / plan / simplify / total on the cloud, its plan and total on the primitives and
the ratio, VAMP's filter / build / plan / simplify / total, and the paths that collide
with the cloud and with the primitives (kc, VAMP); then every colliding path.
``--json`` writes every time, path, counter and verdict. Times are from the machine it
runs on (indicative on a shared, loaded one). One untimed plan (the first problem on its
primitives) comes first: the first plan of a process pays about 50 ms once. OMPL is
seeded once per process (by that plan), so the kc runs depend on ``--seed`` and on the
problems chosen.

Two halves, each in a Python that has what it needs, as ``scripts/vamp_mbm.py``: the
kcplan half (clouds, planning, verification) needs kcplan's compiled kernel, the VAMP
half only ``vamp`` and numpy; whichever Python runs the script does the halves it can
import and runs the others in a subprocess of ``--vamp-python`` or ``--kcplan-python``
(JSON through the pipes, the clouds in ``.npy`` files of a temporary folder)::

    python scripts/cloud_mbm.py --vamp-python /work/vamp-venv/bin/python --per-class 5 \\
        --json benchmarks/clouds/panda.json
    python scripts/cloud_mbm.py --per-class 1 --classes table_pick   # kcplan alone

Without VAMP (no ``import vamp`` here and no ``--vamp-python``, or ``--no-vamp``) it says
so in one line and runs the kcplan half alone.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MBM = ROOT.parent / "shared" / "data" / "external" / "mbm"
ROBOTS = {  # URDF and SRDF of each robot: the bundled Panda, the UR5 as MBM ships it
    "panda": (ROOT / "scenarios" / "arm" / "panda" / "panda.urdf",
              ROOT / "scenarios" / "arm" / "panda" / "panda.srdf"),
    "ur5": (MBM / "ur5" / "ur5.urdf", MBM / "ur5" / "ur5.srdf"),
}  # fmt: skip
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


# ---------------------------------------------------------------- kcplan's half: clouds


def obstacle_mesh(ob):
    """The trimesh triangle mesh of an MBM obstacle (box, cylinder, sphere), world frame."""
    import numpy as np
    import trimesh

    T = np.eye(4)
    T[:3, :3], T[:3, 3] = ob.rotation, ob.center
    if ob.kind == "box":
        return trimesh.creation.box(extents=2.0 * np.asarray(ob.extents), transform=T)
    if ob.kind == "cylinder":  # extents (r, r, h / 2), axis along the local z
        return trimesh.creation.cylinder(
            radius=float(ob.extents[0]), height=2.0 * float(ob.extents[2]), transform=T
        )
    if ob.kind == "sphere":
        sphere = trimesh.creation.icosphere(subdivisions=3, radius=float(ob.extents[0]))
        return sphere.apply_transform(T)
    raise ValueError(f"{ob.label}: expected a box, cylinder or sphere, got {ob.kind}")


def problem_cloud(obstacles, per_object: int, seed: int, problem_class: str, index: int):
    """The raw cloud of one problem, ``(N, 3)`` float64 C-contiguous: ``per_object``
    points on each obstacle's surface (:func:`kcplan.world.pointcloud.sample_surface_points`),
    obstacle ``k`` seeded by ``(seed, class, index, k)``: deterministic."""
    import numpy as np

    from kcplan.world.pointcloud import sample_surface_points

    clouds = []
    for k, ob in enumerate(obstacles):
        mesh = obstacle_mesh(ob)
        key = [int(seed), CLASSES.index(problem_class), int(index), k]
        child = int(np.random.SeedSequence(key).generate_state(1)[0])
        clouds.append(sample_surface_points(mesh.vertices, mesh.faces, per_object, seed=child))
    return np.ascontiguousarray(np.concatenate(clouds), dtype=np.float64)


def cloud_obstacle(points, radius: float):
    """The scenario obstacle of a cloud: every point a ball of ``radius``."""
    import numpy as np

    from kcplan.world.obstacles import Obstacle

    return Obstacle(kind="pointcloud", index=0, spec={}, center=np.zeros(3),
                    rotation=np.eye(3), extents=np.full(3, float(radius)), pieces=(),
                    vertices=np.ascontiguousarray(points, dtype=np.float64),
                    triangles=None)  # fmt: skip


def make_clouds(args: argparse.Namespace, folder: str) -> list[dict]:
    """Step ``clouds``: each chosen problem's start, goal and joints, and its raw cloud
    saved as ``folder/CLASS_INDEX.npy``."""
    import numpy as np

    from kcplan.arm.mbm import MBM_CLASSES, load_mbm_archive

    if tuple(MBM_CLASSES) != CLASSES:
        raise RuntimeError(f"expected the classes {CLASSES}, kcplan has {MBM_CLASSES}")
    keys = [(c, i) for c in args.classes for i in range(1, args.per_class + 1)]
    problems = load_mbm_archive(args.archive, keys)
    out = []
    for problem_class, index in keys:
        if (problem_class, index) not in problems:
            continue
        p = problems[problem_class, index]
        t0 = time.perf_counter()
        points = problem_cloud(p.obstacles, args.points_per_object, args.seed, problem_class,
                               index)  # fmt: skip
        seconds = time.perf_counter() - t0
        path = os.path.join(folder, f"{problem_class}_{index}.npy")
        np.save(path, points)
        out.append({
            "class": problem_class, "index": index, "joints": list(p.joints),
            "start": p.start.tolist(), "goal": p.goal.tolist(),
            "obstacles": len(p.obstacles), "points": len(points), "cloud_file": path,
            "sample_seconds": seconds,
        })  # fmt: skip
    return out


# ---------------------------------------------------------------- VAMP's half


def vamp_plan(problems: list[dict], args: argparse.Namespace) -> list[dict]:
    """Step ``vamp``: per problem, VAMP's filter, CAPT, RRT-Connect and simplification on
    the raw cloud, ``--calls`` times (VAMP's nanoseconds, in ms); the first path."""
    import numpy as np
    import vamp
    from vamp.constants import ROBOT_FIRST_JOINT_LOCATIONS, ROBOT_MAX_RADII

    module, rrtc, settings, simplify_settings = vamp.configure_robot_and_planner_with_kwargs(
        args.robot, "rrtc"
    )
    joints = list(module.joint_names())
    sampler = module.halton()
    r_min, r_max = module.min_max_radii()
    # as vamp.pointcloud.problem_dict_to_pointcloud
    origin = list(ROBOT_FIRST_JOINT_LOCATIONS.get(args.robot, [0.0, 0.0, 0.0]))
    cull_radius = ROBOT_MAX_RADII.get(args.robot, 1.4)
    bbox_lo = np.asarray(origin) - cull_radius
    bbox_hi = np.asarray(origin) + cull_radius
    results = []
    for problem in problems:
        if problem["joints"] != joints:
            raise ValueError(f"{problem['class']} {problem['index']}: expected joints {joints}")
        original = np.load(problem["cloud_file"]).tolist()  # VAMP passes a list too
        start = np.asarray(problem["start"], dtype=np.float32)
        goal = np.asarray(problem["goal"], dtype=np.float32)
        times = {"filter_ms": [], "build_ms": [], "plan_ms": [], "simplify_ms": []}
        out = {"class": problem["class"], "index": problem["index"], "solved": False,
               "path": [], "raw_path_states": 0}  # fmt: skip
        for call in range(args.calls):
            filtered, filter_ns = vamp.filter_pointcloud(
                original, args.filter_radius, cull_radius, origin, bbox_lo, bbox_hi, True
            )
            env = vamp.Environment()
            build_ns = env.add_pointcloud(filtered, r_min, r_max, args.point_radius)
            if call == 0:
                out["kept"] = len(filtered)
                out["valid_for_vamp"] = bool(module.validate(start, env)) and bool(
                    module.validate(goal, env)
                )
            sampler.reset()
            result = rrtc(start, goal, env, settings, sampler)
            if not result.solved:
                break
            simple = module.simplify(result.path, env, simplify_settings, sampler)
            times["filter_ms"].append(filter_ns * 1e-6)
            times["build_ms"].append(build_ns * 1e-6)
            times["plan_ms"].append(result.nanoseconds * 1e-6)
            times["simplify_ms"].append(simple.nanoseconds * 1e-6)
            if call == 0:
                out["path"] = np.asarray(simple.path.numpy(), dtype=float).tolist()
                out["raw_path_states"] = len(result.path)
                out["iterations"] = int(result.iterations)
        out["solved"] = len(times["plan_ms"]) == args.calls
        out |= times
        results.append(out)
        print(f"vamp {problem['class']} {problem['index']}: solved {out['solved']}, kept "
              f"{out['kept']} of {problem['points']}", file=sys.stderr, flush=True)  # fmt: skip
    return results


# ---------------------------------------------------------------- kcplan's half: plans


def _scenario(problem, name: str, robot: str, folder: Path):
    """The MBM problem as kcplan's arm scenario on its primitives (``kcplan import mbm``)."""
    from kcplan.arm.mbm import mbm_scenario
    from kcplan.scenarios import parse_scenario

    urdf, srdf = ROBOTS[robot]
    path = folder / f"{name}.yaml"  # not written: robot paths are relative to its folder
    data = mbm_scenario(problem, name, urdf, srdf, path)
    return parse_scenario(data, os.fspath(path), folder, check=False)


def _timed_plan(scenario, args: argparse.Namespace) -> dict:
    """One :func:`kcplan.plan` call, timed whole; ``build`` is what is not solve or
    simplification. The result object under ``"result"`` (dropped before JSON)."""
    from kcplan import plan

    t0 = time.perf_counter()
    try:
        result = plan(scenario, args.planner, seed=args.seed, time_limit=args.time)
    except Exception as err:  # noqa: BLE001 - reported, not fatal (e.g. start in contact)
        return {"solved": False, "error": f"{type(err).__name__}: {err}"}
    wall = time.perf_counter() - t0
    return {
        "solved": bool(result.solved),
        "planner": result.planner,
        "total_ms": wall * 1e3,
        "plan_ms": result.time * 1e3,
        "simplify_ms": result.simplify_time * 1e3,
        "build_ms": (wall - result.time - result.simplify_time) * 1e3,
        "timing": dict(getattr(result, "timing", {}) or {}),
        "length": result.length,
        "states": result.states,
        "counters": result.counters,
        "result": result,
    }


def _check(checker, states, budget: float = 0.0) -> dict:
    """A path's verdict from :class:`kcplan.arm.verify.ArmMeshChecker` (what
    ``PlanResult.verify`` runs) and its seconds. With a ``budget`` (seconds, > 0) the
    path is checked segment by segment (the same queries and verdict: the checker starts
    each segment afresh) in a forked child that reports each segment as it ends, and is
    killed when the budget runs out: ``complete`` is then False and the verdict is the
    segments checked so far (``segments_checked`` of ``segments``)."""
    t0 = time.perf_counter()
    segments = len(states) - 1
    if budget <= 0:
        check = checker.check(states)
        return {"collides": bool(check.collides), "min_clearance": float(check.min_clearance),
                "where": [float(x) for x in check.where], "what": check.what,
                "queries": int(check.queries), "seconds": time.perf_counter() - t0,
                "complete": True, "segments": segments,
                "segments_checked": segments}  # fmt: skip
    done = _segments_in_child(checker, states, budget)
    out = {"collides": False, "min_clearance": math.inf, "where": [], "what": "",
           "queries": 0, "segments": segments, "segments_checked": len(done)}  # fmt: skip
    for i, seg in enumerate(done):
        out["queries"] += seg["queries"]
        out["min_clearance"] = min(out["min_clearance"], seg["min_clearance"])
        if seg["collides"]:
            out |= {"collides": True, "where": [float(i), seg["s"]], "what": seg["what"]}
            break
    out["complete"] = out["collides"] or len(done) == segments
    if not math.isfinite(out["min_clearance"]):
        out["min_clearance"] = None  # no segment checked
    out["seconds"] = time.perf_counter() - t0
    return out


def _segments_in_child(checker, states, budget: float) -> list[dict]:
    """Check ``states`` segment by segment in a forked child (stopping at the first
    contact); the segments' verdicts it reported within ``budget`` seconds."""
    import select
    import signal

    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: one JSON line per segment
        code = 0
        try:
            os.close(read)
            for i in range(len(states) - 1):
                check = checker.check(states[i : i + 2])
                line = {"collides": bool(check.collides),
                        "min_clearance": float(check.min_clearance),
                        "s": float(check.where[1]) if check.where else None,
                        "what": check.what, "queries": int(check.queries)}  # fmt: skip
                os.write(write, (json.dumps(line) + "\n").encode())
                if check.collides:
                    break
        except BaseException:  # noqa: BLE001 - the parent sees the segments missing
            code = 1
        finally:
            os._exit(code)
    os.close(write)
    deadline = time.monotonic() + budget
    buffer, done, finished = b"", [], False
    try:
        while not finished:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([read], [], [], left)[0]:
                break
            chunk = os.read(read, 65536)
            finished = not chunk
            buffer += chunk
    finally:
        os.close(read)
        if not finished:
            os.kill(pid, signal.SIGKILL)  # the child this call forked
        os.waitpid(pid, 0)
    for line in buffer.decode().splitlines():
        done.append(json.loads(line))
    return done


def kcplan_plan(problems: list[dict], vamp_results: list[dict] | None,
                args: argparse.Namespace) -> list[dict]:  # fmt: skip
    """Step ``kcplan``: plan each problem on its cloud and on its primitives, and verify
    kcplan's and VAMP's paths against the cloud and against the primitives."""
    import dataclasses

    import numpy as np

    from kcplan.arm import ArmWorld
    from kcplan.arm.mbm import load_mbm_archive
    from kcplan.arm.verify import ArmMeshChecker

    mbm = load_mbm_archive(args.archive, [(p["class"], p["index"]) for p in problems])
    vamp_of = {(v["class"], v["index"]): v for v in vamp_results or []}
    budget = args.verify_budget
    folder = Path(problems[0]["cloud_file"]).parent if problems else Path(".")
    if problems:  # the first plan of a process pays ~50 ms once (imports, OMPL): not timed
        first = problems[0]
        _timed_plan(_scenario(mbm[first["class"], first["index"]], "warm-up", args.robot,
                              folder), args)  # fmt: skip
    out = []
    for problem in problems:
        key = (problem["class"], problem["index"])
        p = mbm[key]
        name = f"{key[0]}_{key[1]}"
        scenario = _scenario(p, name, args.robot, folder)
        points = np.load(problem["cloud_file"])
        cloud = cloud_obstacle(points, args.point_radius)
        on_cloud = dataclasses.replace(scenario, obstacles=(cloud,))
        row = {"class": key[0], "index": key[1], "points": len(points)}
        # the self pairs proven apart once per robot (kcplan.arm.pairs, remembered per
        # arm): before the clock, or the first plan of each freshly loaded arm pays them
        t0 = time.perf_counter()
        ArmWorld(scenario.arm, (), allowed=scenario.allowed)
        row["pair_proofs_ms"] = (time.perf_counter() - t0) * 1e3
        row["kc_cloud"] = _timed_plan(on_cloud, args)
        row["kc_primitives"] = _timed_plan(scenario, args)
        print(f"kcplan {name}: cloud solved {row['kc_cloud']['solved']} "
              f"({row['kc_cloud'].get('total_ms', math.nan):.0f} ms), primitives solved "
              f"{row['kc_primitives']['solved']} "
              f"({row['kc_primitives'].get('total_ms', math.nan):.0f} ms)",
              file=sys.stderr, flush=True)  # fmt: skip
        # verification: the links' meshes, gap-free (PlanResult.verify's checker), built
        # once per scene for every path checked in it
        arm, allowed = scenario.arm, scenario.allowed
        t0 = time.perf_counter()
        cloud_checker = ArmMeshChecker(arm, (cloud,), allowed)
        primitive_checker = ArmMeshChecker(arm, scenario.obstacles, allowed)
        row["checker_build_seconds"] = time.perf_counter() - t0
        paths = {"kc_cloud": row["kc_cloud"].get("states") if row["kc_cloud"]["solved"] else None,
                 "kc_primitives": row["kc_primitives"].get("states")
                 if row["kc_primitives"]["solved"] else None}  # fmt: skip
        vamp = vamp_of.get(key)
        if vamp is not None and vamp["solved"]:
            paths["vamp"] = vamp["path"]
        verdicts = {}
        for who, states in paths.items():
            if states is None:
                continue
            verdicts[who] = {"primitives": _check(primitive_checker, states, budget)}
            if who != "kc_primitives":
                verdicts[who]["cloud"] = _check(cloud_checker, states, budget)
        row["verify"] = verdicts
        for who in ("kc_cloud", "kc_primitives"):
            row[who].pop("result", None)
        out.append(row)
        if args.json:  # every problem as it ends, in case the run stops
            with open(f"{args.json}.rows.jsonl", "a") as progress:
                progress.write(json.dumps(row, default=float) + "\n")
        said = ", ".join(f"{who} vs {what} {_verdict(v)}"
                         for who, d in verdicts.items() for what, v in d.items())  # fmt: skip
        print(f"verify {name}: {said}", file=sys.stderr, flush=True)
    return out


def _metres(value: float | None) -> str:
    return "unknown (no segment finished)" if value is None else f"{value:.2e} m"


def _verdict(v: dict) -> str:
    if v["collides"]:
        return "COLLIDES"
    if not v.get("complete", True):
        return f"UNVERIFIED ({v['segments_checked']} of {v['segments']} segments free)"
    return "free"


# ---------------------------------------------------------------- the two Pythons


STEPS = {"clouds": "kcplan", "vamp": "vamp", "kcplan": "kcplan"}
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


def _forwarded(args: argparse.Namespace) -> list[str]:
    return ["--robot", args.robot, "--archive", args.archive, "--per-class",
            str(args.per_class), "--classes", ",".join(args.classes), "--points-per-object",
            str(args.points_per_object), "--point-radius", repr(args.point_radius),
            "--filter-radius", repr(args.filter_radius), "--seed", str(args.seed), "--time",
            repr(args.time), "--calls", str(args.calls), "--verify-budget",
            repr(args.verify_budget)] + (["--json", args.json] if args.json else [])  # fmt: skip


def _run_step(step: str, payload: dict, args: argparse.Namespace):
    """Run one step here when this Python has its half, else in the other Python."""
    half = STEPS[step]
    if _can_import(half):
        return _step(step, payload, args)
    python = args.vamp_python if half == "vamp" else args.kcplan_python
    command = [python, os.fspath(Path(__file__).resolve()), "--step", step, *_forwarded(args)]
    proc = subprocess.run(command, input=json.dumps(payload), stdout=subprocess.PIPE,
                          stderr=None, text=True, cwd=ROOT)  # fmt: skip
    if proc.returncode != 0:
        raise RuntimeError(f"step {step} in {python} failed (exit {proc.returncode})")
    return json.loads(proc.stdout)


def _step(step: str, payload: dict, args: argparse.Namespace):
    if step == "clouds":
        return make_clouds(args, payload["folder"])
    if step == "vamp":
        return vamp_plan(payload["problems"], args)
    return kcplan_plan(payload["problems"], payload.get("vamp"), args)


@contextlib.contextmanager
def _stdout_to_stderr():
    """Send whatever C++ libraries print to stdout (OMPL) to stderr while a step runs:
    the step's stdout carries its JSON only."""
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


# ---------------------------------------------------------------- the table


def _med(values) -> float | None:
    values = [v for v in values if v is not None and math.isfinite(v)]
    return statistics.median(values) if values else None


def _fmt(value: float | None, digits: int = 1) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


def summary(rows: list[dict], vamp: dict | None) -> dict:
    """Medians and counts of a group of problems (kcplan rows; VAMP's by key)."""
    kc = [r["kc_cloud"] for r in rows if r["kc_cloud"]["solved"]]
    prim = [r["kc_primitives"] for r in rows if r["kc_primitives"]["solved"]]
    both = [r for r in rows if r["kc_cloud"]["solved"] and r["kc_primitives"]["solved"]]
    out = {
        "problems": len(rows),
        "points": _med([r["points"] for r in rows]),
        "kc_solved": len(kc),
        "kc_build_ms": _med([r["build_ms"] for r in kc]),
        "kc_plan_ms": _med([r["plan_ms"] for r in kc]),
        "kc_simplify_ms": _med([r["simplify_ms"] for r in kc]),
        "kc_total_ms": _med([r["total_ms"] for r in kc]),
        "prim_solved": len(prim),
        "prim_plan_ms": _med([r["plan_ms"] for r in prim]),
        "prim_total_ms": _med([r["total_ms"] for r in prim]),
        "ratio_plan": _med([r["kc_cloud"]["plan_ms"] / r["kc_primitives"]["plan_ms"]
                            for r in both if r["kc_primitives"]["plan_ms"] > 0]),
        "ratio_total": _med([r["kc_cloud"]["total_ms"] / r["kc_primitives"]["total_ms"]
                             for r in both]),
    }  # fmt: skip
    for who in ("kc_cloud", "kc_primitives", "vamp"):
        for what in ("cloud", "primitives"):
            verdicts = [r["verify"][who][what] for r in rows
                        if what in r["verify"].get(who, {})]  # fmt: skip
            out[f"{who}_vs_{what}"] = [sum(v["collides"] for v in verdicts), len(verdicts)]
            out[f"{who}_vs_{what}_unverified"] = sum(
                not v["collides"] and not v.get("complete", True) for v in verdicts
            )
    if vamp is not None:
        mine = [vamp[(r["class"], r["index"])] for r in rows]
        solved = [v for v in mine if v["solved"]]
        out["vamp_solved"] = len(solved)
        out["vamp_valid"] = sum(bool(v.get("valid_for_vamp")) for v in mine)
        out["vamp_kept"] = _med([v.get("kept") for v in mine])
        for part in ("filter", "build", "plan", "simplify"):
            out[f"vamp_{part}_ms"] = _med([statistics.median(v[f"{part}_ms"]) for v in solved])
        out["vamp_total_ms"] = _med([
            statistics.median(
                [sum(t) for t in zip(v["filter_ms"], v["build_ms"], v["plan_ms"],
                                     v["simplify_ms"], strict=True)]
            ) for v in solved
        ])  # fmt: skip
    return out


def table(rows: list[dict], vamp: dict | None, robot: str) -> tuple[list[str], dict]:
    """The Markdown table of one robot and the summaries it shows."""
    groups = [(c, [r for r in rows if r["class"] == c]) for c in CLASSES]
    groups = [(c, g) for c, g in groups if g] + [("all", rows)]
    sums = {c: summary(g, vamp) for c, g in groups}
    v = vamp is not None
    head = ["class", "problems", "points", "solved kc / VAMP", "kc build", "kc plan",
            "kc simplify", "kc total", "prim. plan", "prim. total", "cloud/prim. plan",
            "cloud/prim. total"]  # fmt: skip
    if v:
        head += ["VAMP kept", "VAMP filter", "VAMP build", "VAMP plan", "VAMP simplify",
                 "VAMP total"]  # fmt: skip
    head += ["colliding vs cloud kc / VAMP", "colliding vs primitives kc / VAMP"]
    planners = sorted({r["kc_cloud"].get("planner", "?") for r in rows if "kc_cloud" in r})
    lines = [f"**{robot}**: kcplan ({', '.join(planners)}) on the raw cloud vs VAMP-CAPT "
             "(filtered); times in ms, medians over the solved problems", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]  # fmt: skip

    def pair(s: dict, what: str) -> str:
        def one(who: str) -> str:
            hit, of = s[f"{who}_vs_{what}"]
            open_ = s[f"{who}_vs_{what}_unverified"]
            return f"{hit}/{of}" + (f" ({open_} unverified)" if open_ else "")

        return f"{one('kc_cloud')} / " + (one("vamp") if v else "-")

    for name, _ in groups:
        s = sums[name]
        cells = [name, str(s["problems"]), _fmt(s["points"], 0),
                 f"{s['kc_solved']} / {s['vamp_solved'] if v else '-'}",
                 _fmt(s["kc_build_ms"]), _fmt(s["kc_plan_ms"]), _fmt(s["kc_simplify_ms"]),
                 _fmt(s["kc_total_ms"]), _fmt(s["prim_plan_ms"]), _fmt(s["prim_total_ms"]),
                 _fmt(s["ratio_plan"], 2), _fmt(s["ratio_total"], 2)]  # fmt: skip
        if v:
            cells += [_fmt(s["vamp_kept"], 0), _fmt(s["vamp_filter_ms"], 2),
                      _fmt(s["vamp_build_ms"], 2), _fmt(s["vamp_plan_ms"], 3),
                      _fmt(s["vamp_simplify_ms"], 3), _fmt(s["vamp_total_ms"], 2)]  # fmt: skip
        cells += [pair(s, "cloud"), pair(s, "primitives")]
        lines.append("| " + " | ".join(cells) + " |")
    return lines, sums


def notes(rows: list[dict], vamp: dict | None) -> list[str]:
    """One line per colliding path, error and unsolved problem."""
    lines = []
    for r in rows:
        name = f"{r['class']} {r['index']}"
        for who in ("kc_cloud", "kc_primitives"):
            if "error" in r[who]:
                lines.append(f"- {name}: kcplan on the {who[3:]}: {r[who]['error']}")
            elif not r[who]["solved"]:
                lines.append(f"- {name}: kcplan on the {who[3:]}: not solved")
        if vamp is not None:
            v = vamp[(r["class"], r["index"])]
            if not v["solved"]:
                lines.append(f"- {name}: VAMP not solved (start and goal valid for VAMP: "
                             f"{v.get('valid_for_vamp')})")  # fmt: skip
        for who, verdicts in r["verify"].items():
            for what, d in verdicts.items():
                if d["collides"]:
                    seg, s = d["where"]
                    lines.append(f"- {name}: {who} path collides with the {what} at segment "
                                 f"{int(seg)}, s = {s:.4f} ({d['what']})")  # fmt: skip
                elif not d.get("complete", True):
                    lines.append(f"- {name}: {who} path against the {what}: {_verdict(d)} "
                                 f"after the verify budget of {d['seconds']:.0f} s, least "
                                 f"clearance so far {_metres(d['min_clearance'])}")  # fmt: skip
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", choices=sorted(ROBOTS), default="panda")
    parser.add_argument("--archive", help="VAMP's problems.tar.bz2 (default: the robot's)")
    parser.add_argument("--per-class", type=int, default=1, help="problems per class (first N)")
    parser.add_argument("--classes", default=",".join(CLASSES),
                        help="comma-separated classes (default: all seven)")  # fmt: skip
    parser.add_argument("--points-per-object", type=int, default=10_000)
    parser.add_argument("--point-radius", type=float, default=0.0025, help="metres")
    parser.add_argument("--filter-radius", type=float, default=0.02,
                        help="VAMP's filter: least distance of kept points (m)")  # fmt: skip
    parser.add_argument("--seed", type=int, default=1, help="clouds and OMPL's seed")
    parser.add_argument("--time", type=float, default=10.0, help="kcplan's time limit (s)")
    parser.add_argument("--planner", default=None,
                        help="kcplan's planner (default: its default for arms)")
    parser.add_argument("--calls", type=int, default=5, help="VAMP runs per problem (median)")
    parser.add_argument("--verify-budget", type=float, default=600.0,
                        help="seconds per path and scene to check it (0: no limit)")  # fmt: skip
    parser.add_argument("--vamp-python", help="a Python with vamp, when this one has none")
    parser.add_argument("--no-vamp", action="store_true", help="run the kcplan half alone")
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
    if args.json and args.step is None:  # the steps may run in another folder (ROOT)
        args.json = os.path.abspath(args.json)
    args.classes = [c for c in args.classes.split(",") if c]
    unknown = [c for c in args.classes if c not in CLASSES]
    if unknown or not args.classes:
        parser.error(f"--classes: expected some of {', '.join(CLASSES)}, got {unknown}")
    if min(args.per_class, args.points_per_object, args.calls) < 1:
        parser.error("--per-class, --points-per-object and --calls: expected positive integers")
    if not (args.point_radius > 0 and args.filter_radius >= 0 and args.time > 0):
        parser.error("--point-radius and --time: expected positive numbers")
    if args.step is not None:  # one half, for the other Python: JSON in, JSON out
        payload = json.loads(sys.stdin.read() or "{}")
        with _stdout_to_stderr():
            result = _step(args.step, payload, args)
        print(json.dumps(result, default=float))
        return 0
    with_vamp = not args.no_vamp and (args.vamp_python is not None or _can_import("vamp"))
    if not with_vamp:
        why = ("left out (--no-vamp)" if args.no_vamp else f"not available (no vamp in "
               f"{sys.executable} and no --vamp-python; build it with `{BUILD}`)")  # fmt: skip
        print(f"cloud_mbm.py: VAMP {why}: running the kcplan half alone", file=sys.stderr)
    if args.json:  # the rows of each problem as it ends (kcplan_plan), for this run only
        Path(f"{args.json}.rows.jsonl").unlink(missing_ok=True)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="cloud_mbm_") as folder:
        problems = _run_step("clouds", {"folder": folder}, args)
        vamp_results = _run_step("vamp", {"problems": problems}, args) if with_vamp else None
        rows = _run_step("kcplan", {"problems": problems, "vamp": vamp_results}, args)
    seconds = time.perf_counter() - t0
    vamp = None if vamp_results is None else {(v["class"], v["index"]): v for v in vamp_results}
    lines, sums = table(rows, vamp, args.robot)
    lines += ["", *(notes(rows, vamp) or ["- every problem solved, no colliding path"])]
    lines.append(f"\n({len(rows)} problems, {args.points_per_object} points per object, "
                 f"radius {args.point_radius} m, seed {args.seed}, kcplan time limit "
                 f"{args.time:g} s, VAMP {f'median of {args.calls} runs' if vamp else 'not run'}; "
                 f"{seconds:.0f} s in all)")  # fmt: skip
    print("\n".join(lines))
    if args.json:
        for p in problems:
            p.pop("cloud_file", None)
        document = {
            "settings": {k: v for k, v in vars(args).items() if k != "step"},
            "seconds": seconds,
            "problems": problems,
            "kcplan": rows,
            "vamp": vamp_results,
            "summary": sums,
            "table": lines,
        }
        Path(args.json).write_text(json.dumps(document, default=float) + "\n")
        Path(f"{args.json}.rows.jsonl").unlink(missing_ok=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
