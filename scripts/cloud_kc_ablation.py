"""What KC adds against points: kc-rrtconnect vs ca-rrtconnect on primitives and their clouds.

Issue 55, item 6: KC's home ground is a rigid robot of ellipsoids among points. For each 3D
map (the bundled ``scenarios/3d`` scenes, ``*_cloud`` excepted, and HRM's 3D superquadric
maps with HRM's rabbit, imported when the data is there) the scene is planned twice: on its
primitives, and on a cloud of surface samples of every obstacle (one ``pointcloud``
obstacle). The samples are drawn uniformly by area, ``ceil(area / h^2)`` per obstacle, with
the spacing ``h = --spacing x`` the robot's smallest semi-axis; a sphere's or an
ellipsoid's samples are projected onto its exact surface, and points farther from the
bounds than the robot reaches (its bodies' offsets plus their largest semi-axes) are
dropped, which no path can notice. Every point is a ball of ``--radius x`` the smallest
semi-axis.

``kc-rrtconnect`` (the free-region certificates) and ``ca-rrtconnect`` (the same validator
with the clearance ball alone: classic conservative advancement) run ``--runs`` seeds each
on both sides, every run in a fresh process of this script (OMPL takes its seed once per
process), which verifies the returned path without gaps by conservative advancement
(:func:`kcplan.planning.verify.verify_path`, independent of the certificates): on
primitives with FCL's clearances as ``kcplan bench`` does (a mesh robot's part too), on
points with a lower bound of each ellipsoid's distance to the balls over a SciPy k-d tree
(:class:`PointsWorld`; python-fcl with one ball per point took minutes per path). Paths
are not simplified, so the guards counted (``kc_guards``) are the solve's. One Markdown
table on standard output::

    python scripts/cloud_kc_ablation.py [--runs 5] [--time 10] [--scenes box_field ...] \
        [--hrm ../shared/data/external/hrm/resources] [--hrm-maps superquadrics_cluttered ...] \
        [--spacing 0.25] [--radius 0.01] [--jobs 1] [--work DIR]

The scenarios, clouds (binary PLY) and every run's record (``runs.jsonl``) go to ``--work``
(default: a temporary folder, removed at the end); progress goes to standard error.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENES_3D = ROOT / "scenarios" / "3d"
HRM_DEFAULT = ROOT.parent / "shared" / "data" / "external" / "hrm" / "resources"
BUNDLED = sorted(p.stem for p in SCENES_3D.glob("*.yaml") if not p.stem.endswith("_cloud"))
HRM_MAPS = ("superquadrics_cluttered", "superquadrics_maze")  # free for HRM's rabbit
PLANNERS = ("kc-rrtconnect", "ca-rrtconnect")


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def smallest_semi_axis(scenario) -> float:
    return float(min(np.min(b.semi_axes) for b in scenario.robot.bodies))


def robot_reach(scenario) -> float:
    """How far from its frame's origin any point of the robot can be."""
    return float(
        max(
            np.linalg.norm(np.asarray(b.position, float)) + np.max(b.semi_axes)
            for b in scenario.robot.bodies
        )
    )


def obstacle_samples(ob, spacing: float, seed: int) -> np.ndarray:
    """Surface samples of one obstacle, ``ceil(area / spacing^2)`` of them."""
    from kcplan.views.arm import obstacle_mesh
    from kcplan.world.pointcloud import sample_surface_points

    V, T = obstacle_mesh(ob)
    e1, e2 = V[T[:, 1]] - V[T[:, 0]], V[T[:, 2]] - V[T[:, 0]]
    area = 0.5 * float(np.linalg.norm(np.cross(e1, e2), axis=1).sum())
    if ob.kind in ("sphere", "ellipsoid"):  # an icosphere's area: the exact surface's below
        a, b, c = (float(x) for x in ob.extents)
        p = 1.6075  # Knud Thomsen's formula, within 1.1 %
        area = 4 * math.pi * (((a * b) ** p + (a * c) ** p + (b * c) ** p) / 3) ** (1 / p)
    points = sample_surface_points(V, T, max(math.ceil(area / spacing**2), 1), seed=seed)
    if ob.kind in ("sphere", "ellipsoid"):  # onto the exact surface
        R, extents = np.asarray(ob.rotation, float), np.asarray(ob.extents, float)
        local = (points - ob.center) @ R / extents
        local /= np.linalg.norm(local, axis=1, keepdims=True)
        points = ob.center + (local * extents) @ R.T
    return points


def surface_cloud(scenario, spacing: float, margin: float, seed: int) -> np.ndarray:
    points = np.concatenate(
        [obstacle_samples(ob, spacing, seed + i) for i, ob in enumerate(scenario.obstacles)]
    )
    low, high = np.asarray(scenario.bounds, float) + [[-margin], [margin]]
    keep = np.all((points >= low) & (points <= high), axis=1)
    return np.ascontiguousarray(points[keep], dtype=np.float64)


def write_ply(points: np.ndarray, path: Path) -> None:
    import trimesh

    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.PointCloud(points).export(path, file_type="ply", encoding="binary")


def cloud_scenario(source: Path, work: Path, args) -> tuple[Path, dict]:
    """Write ``work/NAME_points.yaml``: ``source`` with its obstacles as one cloud."""
    from kcplan.scenarios import dump_scenario, load_scenario
    from kcplan.world.fields import read_scenario_data

    scenario = load_scenario(source)
    s_min = smallest_semi_axis(scenario)
    spacing, radius = args.spacing * s_min, args.radius * s_min
    points = surface_cloud(scenario, spacing, robot_reach(scenario) + radius, args.seed)
    name = source.stem
    write_ply(points, work / "clouds" / f"{name}.ply")
    data, _, folder = read_scenario_data(source)
    robot = dict(data["robot"])
    if "mesh" in robot:  # a mesh robot's file, relative to the new scenario
        robot["mesh"] = os.path.relpath((folder / robot["mesh"]).resolve(), work.resolve())
    kinds: dict[str, int] = {}
    for ob in scenario.obstacles:
        kinds[ob.kind] = kinds.get(ob.kind, 0) + 1
    data = {
        **data,
        "name": f"{scenario.name}_points",
        "description": f"{scenario.name}'s {len(scenario.obstacles)} obstacles as "
        f"{len(points):,} surface points (spacing {spacing:.4g}, radius {radius:.4g}); made "
        "by scripts/cloud_kc_ablation.py",
        "robot": robot,
        "obstacles": [{"pointcloud": {"file": f"clouds/{name}.ply", "point_radius": radius}}],
    }
    target = work / f"{name}_points.yaml"
    dump_scenario(data, target)
    world = PointsWorld(scenario.robot, points, radius)
    for key in ("start", "goal"):
        if world.safe_clearance(getattr(scenario, key)) <= 0.0:
            raise SystemExit(f"cloud_kc_ablation.py: {name}: the {key} touches the points")
    info = {
        "primitives": len(scenario.obstacles),
        "kinds": kinds,
        "points": len(points),
        "s_min": s_min,
        "spacing": spacing,
        "radius": radius,
        "name": scenario.name,
    }
    return target, info


def import_hrm(resources: Path, maps, work: Path) -> list[Path]:
    from kcplan.cli import main as kcplan

    out = []
    for name in maps:
        target = work / "hrm" / f"{name}.yaml"
        target.parent.mkdir(parents=True, exist_ok=True)
        log(f"importing HRM's {name} with the rabbit ...")
        with contextlib.redirect_stdout(sys.stderr):
            code = kcplan(
                ["import", "hrm", str(resources), "--map", name, "--dimension", "3"]
                + ["--robot", "rabbit", "-o", str(target)]
            )
        if code:
            raise SystemExit(f"cloud_kc_ablation.py: kcplan import hrm {name}: exit {code}")
        out.append(target)
    return out


class PointsWorld:
    """Safe clearances of the robot's ellipsoids to a cloud's balls, for
    :func:`kcplan.planning.verify.verify_path`: lower bounds, independent of the certifier
    and of the kernel (SciPy's k-d tree and NumPy).

    For a body ``E`` (centre ``c``, semi-axes ``a``) whose centre is ``d0`` from the nearest
    point (itself at most ``d0 - a_min`` from ``E``), a point beyond ``d0 + a_max - a_min``
    of ``c`` is at least ``d0 - a_min`` from ``E``: only the points within can be nearer.
    Each of those (``y``, body frame) is at least ``n . y - |a * n|`` from ``E`` for any
    unit ``n`` (a separating plane; ``n`` from a few Newton steps towards the nearest point
    of ``E``, which only makes it tight), and at least ``a_min (rho - 1)``, ``rho = |y /
    a|`` (the triangle inequality of the ellipsoid's norm); every point is at
    least ``d0 - a_max`` from it. The point radius comes off."""

    dimension = 3

    def __init__(self, robot, points: np.ndarray, radius: float):
        from scipy.spatial import cKDTree

        self.robot, self.radius = robot, float(radius)
        self.reach = robot.reach
        self.points = np.asarray(points, dtype=float)
        self.tree = cKDTree(self.points)

    def body_clearance(self, R: np.ndarray, c: np.ndarray, a: np.ndarray) -> float:
        d0, _ = self.tree.query(c)
        ball = d0 - a.max()
        near = self.tree.query_ball_point(c, d0 + a.max() - a.min())
        y = (self.points[near] - c) @ R  # body frame
        rho = np.linalg.norm(y / a, axis=1)
        if len(y) and rho.min() <= 1.0:
            return -math.inf  # a point inside the body
        a2, ay2 = a * a, (a * y) ** 2
        t = np.zeros(len(y))
        for _ in range(12):  # f(t) = sum (a y / (a^2 + t))^2 - 1, convex and decreasing
            q = a2 + t[:, None]
            f = (ay2 / q**2).sum(axis=1) - 1.0
            t = t + f / (2.0 * (ay2 / q**3).sum(axis=1))
        v = y - a2 * y / (a2 + t[:, None])
        n = v / np.linalg.norm(v, axis=1, keepdims=True)
        plane = (n * y).sum(axis=1) - np.linalg.norm(a * n, axis=1)
        each = np.maximum(plane, a.min() * (rho - 1.0))
        inner = each.min(initial=math.inf)
        return max(ball, min(inner, d0 - a.min())) - self.radius

    def safe_clearance(self, pose) -> float:
        from kcplan.geometry.pose import pose_frame

        lowest = math.inf
        for body, body_pose in zip(self.robot.bodies, self.robot.body_poses(pose), strict=True):
            R, c = pose_frame(body_pose, 3)
            a = np.asarray(body.semi_axes, dtype=float)
            lowest = min(lowest, self.body_clearance(R, c, a))
        return max(lowest, 0.0)


def execute(spec: dict) -> dict:
    """One run in this process: plan, then verify the path without gaps."""
    from kcplan.planning.problem import plan
    from kcplan.planning.verify import verify_path
    from kcplan.scenarios import load_scenario
    from kcplan.world import CollisionWorld

    t0 = time.perf_counter()
    # a cloud's start and goal were checked once, on the points (the loader's check builds
    # python-fcl's world of one ball per point: half a minute for 640,000)
    scenario = load_scenario(spec["scenario"], check=spec["side"] == "primitives")
    result = plan(scenario, spec["planner"], spec["time"], seed=spec["seed"], simplify=False)
    record = {
        "solved": bool(result.solved),
        "time": result.time,
        "counters": result.counters,
        "collides": None,
        "min_clearance": None,
        "verify_queries": None,
        "verify_time": None,
    }
    if result.solved:
        t1 = time.perf_counter()
        clouds = [ob for ob in scenario.obstacles if ob.kind == "pointcloud"]
        if clouds:  # the points alone (the robot's ellipsoids contain any part)
            (ob,) = clouds
            world = PointsWorld(scenario.robot, ob.vertices, float(ob.extents[0]))
            check = verify_path(world, result.states, padding=scenario.padding)
            collides = check.collides
        else:  # kcplan bench's check: FCL clearances, and a mesh robot's part too
            from kcplan.world.part import PartWorld

            world = CollisionWorld(scenario)
            check = verify_path(world, result.states, padding=scenario.padding)
            collides = check.collides
            if scenario.part is not None:
                part = verify_path(PartWorld(world, scenario.part), result.states)
                collides = collides or part.collides
        record.update(
            collides=bool(collides),
            min_clearance=float(check.min_clearance),
            verify_queries=check.queries,
            verify_time=time.perf_counter() - t1,
        )
    record["wall"] = time.perf_counter() - t0
    return record


def worker() -> None:
    """``--worker``: one run specification (JSON) on stdin, one record on stdout's last line."""
    try:
        record = {"status": "ok", **execute(json.loads(sys.stdin.read()))}
    except Exception as exc:  # a failed run, reported by the parent
        record = {"status": "error", "reason": f"{type(exc).__name__}: {exc}"}
    sys.stdout.write("\n" + json.dumps(record) + "\n")
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)  # skip nanobind's shutdown, as kcplan.bench.worker does


def run_one(spec: dict, timeout: float) -> dict:
    """``spec`` in a fresh process of this script (OMPL takes its seed once per process)."""
    try:
        proc = subprocess.run(
            [sys.executable, __file__, "--worker"], input=json.dumps(spec), cwd=ROOT,
            capture_output=True, text=True, timeout=timeout,
        )  # fmt: skip
        lines = proc.stdout.strip().splitlines()
        record = (
            json.loads(lines[-1]) if lines else {"status": "error", "reason": proc.stderr[-400:]}
        )
    except subprocess.TimeoutExpired:
        record = {"status": "error", "reason": f"no result after {timeout:g} s"}
    return {**spec, **record}


def progress(r: dict) -> str:
    """One run's line for standard error."""
    head = f"{r['scenario_name']} {r['planner']} seed {r['seed']}: "
    if r["status"] != "ok":
        return head + f"failed: {r['reason']}"
    head += f"{'solved' if r['solved'] else 'unsolved'} in {r['time']:.3g} s, "
    head += f"{r['counters'].get('kc_guards', 0)} guards"
    if r["solved"]:
        verdict = "COLLIDES" if r["collides"] else "clean"
        head += f", path {verdict} (verified in {r['verify_time']:.1f} s)"
    return head


def median(values):
    return statistics.median(values) if values else float("nan")


def cell(runs: list[dict], limit: float) -> tuple[str, float]:
    """``solved/N, median s, median guards`` and the median time (unsolved: the limit)."""
    ok = [r for r in runs if r.get("status") == "ok"]
    solved = sum(bool(r["solved"]) for r in ok)
    times = [r["time"] if r["solved"] else limit for r in ok]
    guards = [r["counters"].get("kc_guards", 0) for r in ok]
    t = median(times)
    text = f"{solved}/{len(runs)}, {t:.3g} s, {median(guards):,.0f}" if ok else "failed"
    return text, t


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="seeds per planner and side")
    parser.add_argument("--time", type=float, default=10.0, help="time limit of a solve, s")
    parser.add_argument("--seed", type=int, default=1, help="seed of run 0 and of the samples")
    parser.add_argument(
        "--scenes", nargs="+", default=BUNDLED, choices=BUNDLED, help="bundled 3D scenes"
    )
    parser.add_argument("--hrm", type=Path, default=HRM_DEFAULT, help="HRM's resources folder")
    parser.add_argument(
        "--hrm-maps", nargs="*", default=list(HRM_MAPS), help="HRM 3D maps (none: skip HRM)"
    )
    parser.add_argument(
        "--spacing", type=float, default=0.25, help="sample spacing / smallest semi-axis"
    )
    parser.add_argument(
        "--radius", type=float, default=0.01, help="point radius / smallest semi-axis"
    )
    parser.add_argument("--jobs", type=int, default=1, help="worker processes at a time")
    parser.add_argument(
        "--run-timeout", type=float, default=600.0, help="kill a worker after this long, s"
    )
    parser.add_argument("--work", type=Path, help="keep scenarios, clouds and runs.jsonl here")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        worker()
    t0 = time.perf_counter()

    work = args.work or Path(tempfile.mkdtemp(prefix="cloud_kc_"))
    work.mkdir(parents=True, exist_ok=True)
    try:
        sources = [SCENES_3D / f"{name}.yaml" for name in args.scenes]
        if args.hrm_maps:
            if (args.hrm / "3D").is_dir():
                sources += import_hrm(args.hrm, args.hrm_maps, work)
            else:
                log(f"no HRM data at {args.hrm}: HRM maps skipped")
        scenes = []
        for source in sources:
            cloud, info = cloud_scenario(source, work, args)
            log(f"{info['name']}: {info['primitives']} obstacles -> {info['points']:,} points")
            scenes.append((source, cloud, info))

        specs = [
            {"scenario": str(path), "scenario_name": name, "side": side, "planner": planner,
             "seed": args.seed + i, "time": args.time}
            for source, cloud, info in scenes
            for side, path, name in (("primitives", source, info["name"]),
                                     ("points", cloud, f"{info['name']}_points"))
            for planner in PLANNERS
            for i in range(args.runs)
        ]  # fmt: skip
        records = []
        with (work / "runs.jsonl").open("w") as out, ThreadPoolExecutor(args.jobs) as pool:
            futures = [pool.submit(run_one, spec, args.run_timeout) for spec in specs]
            for k, future in enumerate(futures, 1):
                r = future.result()
                records.append(r)
                out.write(json.dumps(r) + "\n")
                out.flush()
                log(f"[{k}/{len(specs)}] {progress(r)}")
        print_table(scenes, records, args, time.perf_counter() - t0)
    finally:
        if args.work is None:
            shutil.rmtree(work, ignore_errors=True)
    return 0


def print_table(scenes, records, args, elapsed: float) -> None:
    by = {}
    for r in records:
        by.setdefault((r["scenario_name"], r["planner"]), []).append(r)
    print(
        "| scene | obstacles (primitives / points) | primitives: kc solved, median s, "
        "guards | ca | kc/ca time | points: kc solved, median s, guards | ca | kc/ca time |"
    )
    print("|---|---|---|---|---|---|---|---|")
    ratios = {"primitives": [], "points": []}
    for _source, _cloud, info in scenes:
        kinds = ", ".join(f"{n} {k}" for k, n in info["kinds"].items())
        row = [info["name"], f"{info['primitives']} ({kinds}) / {info['points']:,}"]
        for side, name in (("primitives", info["name"]), ("points", f"{info['name']}_points")):
            (kc, t_kc), (ca, t_ca) = (cell(by.get((name, p), []), args.time) for p in PLANNERS)
            ratio = t_kc / t_ca if t_ca > 0 else float("nan")
            ratios[side].append(ratio)
            row += [kc, ca, f"{ratio:.2f}"]
        print("| " + " | ".join(row) + " |")
    print()
    geo = {k: math.exp(statistics.fmean(map(math.log, v))) for k, v in ratios.items() if v}
    print(
        "- kc/ca of the median times, geometric mean over the scenes: "
        + ", ".join(f"{side} {g:.2f}" for side, g in geo.items())
    )
    solved = [r for r in records if r.get("status") == "ok" and r["solved"]]
    colliding = sum(bool(r["collides"]) for r in solved)
    failed = sum(r.get("status") != "ok" for r in records)
    print(
        f"- colliding paths: {colliding} of {len(solved)} returned paths, each verified "
        "without gaps by conservative advancement (kcplan.planning.verify.verify_path: on "
        "primitives FCL's clearances as kcplan bench, a mesh robot's part as well; on points "
        "PointsWorld's bounds of each ellipsoid's distance to the balls over a SciPy k-d "
        "tree); failed runs: "
        f"{failed} of {len(records)}"
    )
    seeds = f"{args.seed}" if args.runs == 1 else f"{args.seed}-{args.seed + args.runs - 1}"
    print(
        f"- {args.runs} seed{'s' * (args.runs > 1)} ({seeds}) per planner and "
        f"side, each a fresh process, limit {args.time:g} s, paths not simplified; median "
        "solve time with an unsolved run counted at the limit; guards: the validator's "
        "kc_guards counter over the solve"
    )
    print(
        f"- clouds: uniform surface samples, spacing {args.spacing:g} x and point radius "
        f"{args.radius:g} x the robot's smallest semi-axis ("
        + "; ".join(
            f"{i['name']} {i['s_min']:.3g}: {i['spacing']:.3g}, {i['radius']:.3g}"
            for *_, i in scenes
        )
        + ")"
    )
    print(f"- run time {elapsed:.0f} s")


if __name__ == "__main__":
    sys.exit(main())
