"""The ``kcplan`` command.

Exit codes: 0 success, 2 bad input (one line on stderr, no traceback).
"""

from __future__ import annotations

import argparse
import json
import shlex
import signal
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

__all__ = ["main"]


class InputError(Exception):
    """Bad user input; reported as one line with exit code 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, exit 2, no usage dump
        raise InputError(f"{self.prog}: {message}")


def bounds_report(semi_axes: Sequence[float], inflation: float) -> dict:
    """Vertex count and volumes of both bounds and of the true KC set, with ratios.

    Volumes are in rad^r * length^n over the identity component, exponential-coordinate
    measure (see :mod:`kcplan.kc.volume`).
    """
    from kcplan.kc import ConvexLowerBound, GeometricLowerBound, kc_volume

    t0 = time.perf_counter()
    convex = ConvexLowerBound(semi_axes, inflation)
    geometric = GeometricLowerBound(semi_axes, inflation)
    v_convex = convex.volume()
    v_geometric = geometric.volume()
    v_true = kc_volume(semi_axes, inflation)
    return {
        "semi_axes": [float(x) for x in convex.a],
        "inflation": convex.inflation,
        "convex_vertices": convex.n_vertices,
        "convex_halfspaces": int(len(convex.halfspaces[1])),
        "convex_rotation_extent": convex.rotation_extent,
        "volume_convex": v_convex,
        "volume_geometric": v_geometric,
        "volume_kc": v_true,
        "ratio_convex": v_convex / v_true,
        "ratio_geometric": v_geometric / v_true,
        "seconds": time.perf_counter() - t0,
        "_bound": convex,
    }


def _cmd_bounds(args: argparse.Namespace) -> int:
    if len(args.semi_axes) not in (2, 3):
        raise InputError(
            f"kcplan bounds: --semi-axes: expected 2 or 3 numbers, got {len(args.semi_axes)}"
        )
    try:
        report = bounds_report(args.semi_axes, args.inflation)
    except ValueError as err:
        raise InputError(f"kcplan bounds: {err}") from None
    bound = report.pop("_bound")
    if args.plot:
        from kcplan.viz import plot_convex_bound

        plot_convex_bound(bound, args.plot)
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    n = len(report["semi_axes"])
    unit = "rad * length^2" if n == 2 else "rad^3 * length^3"
    print(f"robot semi-axes {report['semi_axes']}, inflation {report['inflation']:g}")
    print(
        f"convex lower bound : {report['convex_vertices']} vertices, "
        f"{report['convex_halfspaces']} half-spaces, rotation extent "
        f"{report['convex_rotation_extent']:.4f} rad"
    )
    print(f"volume convex      : {report['volume_convex']:.6g} {unit}")
    print(f"volume geometric   : {report['volume_geometric']:.6g} {unit}")
    print(f"volume true KC     : {report['volume_kc']:.6g} {unit}")
    print(f"convex / true      : {report['ratio_convex']:.4f}")
    print(f"geometric / true   : {report['ratio_geometric']:.4f}")
    if args.plot:
        print(f"plot written to {args.plot}")
    return 0


def _output_file(path: str | None, option: str, suffixes: tuple[str, ...] = ()) -> None:
    """Refuse an output file before any work: its folder must exist (no lost plan)."""
    if path is None:
        return
    out = Path(path)
    if suffixes and out.suffix.lower() not in suffixes:
        raise InputError(
            f"{out}: {option}: expected a {' or '.join(suffixes)} file name, got {out.name!r}"
        )
    if not out.parent.is_dir():
        raise InputError(
            f"{out}: {option}: expected a file in an existing folder, got {out.parent}"
        )
    if out.is_dir():
        raise InputError(f"{out}: {option}: expected a file name, got a folder")


def _load(path: str, check: bool = True):
    """Load a scenario, turning every problem with it into an :class:`InputError`."""
    from kcplan.world import ScenarioError, load_scenario

    try:
        return load_scenario(path, check=check)
    except ScenarioError as err:
        raise InputError(str(err)) from None


def _cmd_validate(args: argparse.Namespace) -> int:
    from kcplan.world import ScenarioError, load_scenario

    failed = 0
    for path in args.scenarios:
        try:
            s = load_scenario(path)
        except ScenarioError as err:
            failed += 1
            print(f"INVALID {err}")
            continue
        print(
            f"ok      {path}: {s.name}, {s.dimension}D, {len(s.obstacles)} obstacles, "
            f"robot {s.robot.describe()}"
        )
    if failed:
        print(f"{failed} of {len(args.scenarios)} scenario files are invalid", file=sys.stderr)
    return 2 if failed else 0


def _cmd_show(args: argparse.Namespace) -> int:
    _output_file(args.output, "-o", (".png",))
    scenario = _load(args.scenario)
    out = args.output or str(Path(args.scenario).with_suffix(".png"))
    from kcplan.viz import plot_scenario

    plot_scenario(scenario, out, guards=scenario.inflation)
    print(f"picture written to {out}")
    return 0


def _print_counters(counters: dict) -> None:
    keys = [
        "fcl_queries",
        "collision_queries",
        "distance_queries",
        "region_queries",
        "region_pairs",
        "checker_calls",
    ]
    print("fcl queries     : " + ", ".join(f"{k} {counters[k]}" for k in keys if k in counters))
    kc = {k[3:]: v for k, v in counters.items() if k.startswith("kc_")}
    if kc:
        print("kc validator    : " + ", ".join(f"{k} {v}" for k, v in kc.items()))


def _cmd_plan(args: argparse.Namespace) -> int:
    _output_file(args.output, "-o")
    _output_file(args.plot, "--plot", (".png",))
    scenario = _load(args.scenario)
    from kcplan.planning.problem import plan

    result = plan(scenario, args.planner, args.time, args.seed, args.simplify)
    status = "solved" if result.solved else "NOT solved"
    print(
        f"{scenario.name}: {status} by {args.planner} in {result.time:.3f} s "
        f"(simplification {result.simplify_time:.3f} s)"
    )
    if result.solved:
        print(f"path            : {len(result.states)} states, length {result.length:.4g}")
    _print_counters(result.counters)
    if args.output:
        from kcplan.files import write_text_atomic

        write_text_atomic(args.output, json.dumps(result.to_json(), indent=1) + "\n")
        print(f"path written to {args.output}")
    if args.plot:
        from kcplan.viz import plot_path

        guards = None
        if args.guards and result.solved:
            guards = path_guards(scenario, result.states)
        plot_path(
            scenario,
            result.states,
            args.plot,
            guards=guards,
            title=f"{scenario.name}: {args.planner}, {status}",
        )
        print(f"plot written to {args.plot}")
    return 0 if result.solved else 1


def path_guards(scenario, states) -> list:
    """The guards (pose, inflation) that certify each edge of a path, for plotting."""
    from kcplan.planning.certifier import EdgeCertifier
    from kcplan.world import CollisionWorld

    certifier = EdgeCertifier(CollisionWorld(scenario))
    certifier.guard_log = []
    for p, q in zip(states[:-1], states[1:], strict=True):
        certifier.check(p, q)
    return certifier.guard_log


def _read_path(path: str, scenario) -> np.ndarray:
    try:
        data = json.loads(Path(path).read_text())
    except OSError as err:
        raise InputError(f"{path}: cannot read the file: {err.strerror or err}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise InputError(f"{path}: expected a JSON path file, got invalid JSON ({err})") from None
    if not isinstance(data, dict) or "states" not in data:
        raise InputError(f"{path}: states: expected a JSON object with a 'states' list")
    width = 3 if scenario.dimension == 2 else 7
    try:
        states = np.array(data["states"], dtype=float)
    except (TypeError, ValueError):
        states = np.zeros((0, 0))
    if states.ndim != 2 or states.shape[1] != width or len(states) < 1:
        raise InputError(
            f"{path}: states: expected a non-empty list of poses with {width} numbers each "
            f"(scenario {scenario.source} is {scenario.dimension}D)"
        )
    if not np.isfinite(states).all():
        raise InputError(f"{path}: states: expected finite numbers")
    if scenario.dimension == 2:  # yaw in [-pi, pi), as OMPL and the scenario loader keep it
        from kcplan.geometry.pose import wrap_angle

        states[:, 2] = wrap_angle(states[:, 2])
    if data.get("dimension", scenario.dimension) != scenario.dimension:
        raise InputError(
            f"{path}: dimension: expected {scenario.dimension}, got {data['dimension']}"
        )
    return states


def _cmd_verify(args: argparse.Namespace) -> int:
    scenario = _load(args.scenario)
    states = _read_path(args.path, scenario)
    from kcplan.planning.verify import verify_path
    from kcplan.world import CollisionWorld

    check = verify_path(CollisionWorld(scenario), states, tolerance=args.tolerance)
    edges = max(len(states) - 1, 1)
    if check.collides:
        pose = ", ".join(f"{v:.6g}" for v in check.first_collision)
        print(
            f"COLLISION on edge {check.edge_index} at s = {check.s:.6f}: pose [{pose}] "
            f"({check.queries} clearance queries)"
        )
        return 1
    print(
        f"clean: {edges} edges checked without gaps, minimum clearance "
        f"{check.min_clearance:.6g}, {check.queries} clearance queries"
    )
    return 0


def _cmd_bench(args: argparse.Namespace) -> int:
    from kcplan.bench.campaign import (
        DaskExecutor,
        LocalExecutor,
        Progress,
        campaign_metadata,
        campaign_specs,
        ordered,
        run_campaign,
    )
    from kcplan.bench.report import prepare_output, write_reports
    from kcplan.planning.names import PLANNER_NAMES

    planners = [p.strip() for p in args.planners.split(",") if p.strip()]
    unknown = [p for p in planners if p not in PLANNER_NAMES]
    if unknown or not planners:
        raise InputError(
            f"kcplan bench: --planners: expected a comma-separated list of "
            f"{', '.join(PLANNER_NAMES)}, got {args.planners!r}"
        )
    scenarios = [_load(path) for path in args.scenarios]
    names = [s.name for s in scenarios]
    if len(set(names)) != len(names):
        twice = sorted({n for n in names if names.count(n) > 1})
        raise InputError(f"kcplan bench: scenarios: expected distinct names, got {twice} twice")
    try:
        prepare_output(args.output, args.force)
    except ValueError as err:
        raise InputError(str(err)) from None
    specs = campaign_specs(
        [(s.source, s.name) for s in scenarios],
        planners,
        args.runs,
        args.seed,
        args.time,
        args.simplify,
    )
    meta = campaign_metadata(
        specs,
        scenarios,
        planners,
        args.runs,
        args.seed,
        args.time,
        shlex.join(["kcplan", *args.argv]),
    )
    from kcplan.files import write_text_atomic

    write_text_atomic(Path(args.output) / "campaign.json", json.dumps(meta, indent=1) + "\n")
    if args.scheduler:
        executor = DaskExecutor(args.scheduler, timeout=args.run_timeout)
        where = f"on the Dask cluster at {args.scheduler}"
    else:
        executor = LocalExecutor(args.jobs, timeout=args.run_timeout)
        where = f"in {args.jobs} worker process{'es' if args.jobs > 1 else ''}"
    print(
        f"kcplan bench: {len(specs)} runs ({len(scenarios)} scenarios x {len(planners)} "
        f"planners x {args.runs}), {args.time:g} s each, {where}; results in {args.output}",
        file=sys.stderr,
    )
    # a batch system's SIGTERM ends the campaign like Ctrl-C: finished runs are reported
    previous = signal.signal(signal.SIGTERM, signal.default_int_handler)
    try:
        records, complete = run_campaign(specs, args.output, executor, Progress(len(specs)))
    finally:
        signal.signal(signal.SIGTERM, previous)
    if complete:
        executor.shutdown()
    records = ordered(records, specs)
    written = write_reports(args.output, records, meta)
    failed = sum(r["status"] != "ok" for r in records)
    solved = sum(bool(r["solved"]) for r in records)
    colliding = sum(bool(r.get("collides")) for r in records)
    print(
        f"{len(records)} of {len(specs)} runs finished: {solved} solved, {failed} failed, "
        f"{colliding} returned paths collide"
    )
    if "summary.md" in written:
        print(
            f"summary: {written['summary.md']}, {written['summary.csv']}; "
            f"database: {written['database']}"
        )
    if not complete:
        print("interrupted: the reports cover the finished runs", file=sys.stderr)
        return 130
    return 0


def _positive_float(text: str) -> float:
    value = _finite_float(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return value


def _cmd_import(args: argparse.Namespace) -> int:
    from kcplan.maps import MapImportError
    from kcplan.world import ScenarioError, dump_scenario, parse_scenario

    out = Path(args.output)
    _output_file(args.output, "-o", (".yaml", ".yml"))
    try:
        if args.source == "hrm":
            from kcplan.maps.hrm import import_hrm

            if not Path(args.resources).is_dir():
                raise MapImportError(f"{args.resources}: expected HRM's resources folder")
            data = import_hrm(
                args.resources, args.map, args.dimension, out, args.inflation, args.robot
            )
        else:
            from kcplan.maps.movingai import import_movingai

            if args.index is not None and args.scen is None:
                raise MapImportError("--index: expected --scen FILE.scen as well")
            data = import_movingai(
                args.map_file, args.scen, args.index or 0, args.cell, args.robot, args.inflation
            )
        scenario = parse_scenario(data, str(out), out.parent, check=True)
    except (MapImportError, ScenarioError) as err:
        raise InputError(str(err)) from None
    dump_scenario(data, out)
    print(
        f"{out}: {scenario.name}, {scenario.dimension}D, {len(data['obstacles'])} obstacles, "
        f"robot {scenario.robot.describe()}"
    )
    print(data["description"])
    return 0


def _rows_csv(rows: Sequence[dict]) -> str:
    import csv
    import io

    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()


def _cmd_pick_place(args: argparse.Namespace) -> int:
    from kcplan.files import write_text_atomic
    from kcplan.pickplace.analysis import noise_study
    from kcplan.pickplace.plots import plot_noise_inflation_entropy

    if any(s < 0 for s in args.sigma_deg):
        raise InputError(
            f"kcplan pick-place: --sigma-deg: expected numbers >= 0, got {args.sigma_deg}"
        )
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise InputError(f"{out}: expected an output folder, got an existing file")
    out.mkdir(parents=True, exist_ok=True)

    def report(row: dict) -> None:
        print(
            f"sigma {row['sigma_deg']:g} deg: eps exact {row['eps_exact_median']:.4g} "
            f"[{row['eps_exact_p10']:.4g}, {row['eps_exact_p90']:.4g}], geometric "
            f"{row['eps_geometric_median']:.4g}; contained at eps {args.inflation:g}: exact "
            f"{row['contained_exact_fraction']:.0%}, geometric "
            f"{row['contained_geometric_fraction']:.0%} of trials; S true "
            f"{row['entropy_true']:.3f}, S geometric {row['entropy_geometric']:.3f}",
            flush=True,
        )

    trials, sigmas = noise_study(
        args.sigma_deg, args.trials, args.poses, args.inflation, args.seed, progress=report
    )
    write_text_atomic(out / "trials.csv", _rows_csv(trials))
    write_text_atomic(out / "summary.csv", _rows_csv(sigmas))
    plot_noise_inflation_entropy(sigmas, args.inflation, out / "pick_place.png")
    print(f"written: {out / 'summary.csv'}, {out / 'trials.csv'}, {out / 'pick_place.png'}")
    return 0


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return value


def _finite_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not np.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="kcplan", description=__doc__.splitlines()[0])
    from kcplan import __version__

    parser.add_argument("--version", action="version", version=f"kcplan {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    p = sub.add_parser(
        "bounds",
        help="volumes of the convex and geometric lower bounds and of the true KC set",
        description="Build the convex lower bound of E_a in (1 + eps) E_a and compare the "
        "volumes of both lower bounds with the true KC volume (identity component, "
        "exponential coordinates).",
    )
    p.add_argument(
        "--semi-axes",
        nargs="+",
        type=_finite_float,
        required=True,
        metavar="A",
        help="robot semi-axes, 2 (ellipse) or 3 (ellipsoid) numbers",
    )
    p.add_argument(
        "--inflation",
        type=_finite_float,
        required=True,
        metavar="EPS",
        help="guard inflation eps > 0; the guard is (1 + eps) times the robot",
    )
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.add_argument("--plot", metavar="FILE.png", help="draw the convex lower bound")
    p.set_defaults(handler=_cmd_bounds)

    p = sub.add_parser(
        "validate",
        help="check scenario files",
        description="Check scenario files: format, values, start and goal inside the bounds and "
        "free of obstacles. One line per file; exit 0 when all are valid, 2 otherwise.",
    )
    p.add_argument("scenarios", nargs="+", metavar="SCENARIO", help="YAML scenario files")
    p.set_defaults(handler=_cmd_validate)

    p = sub.add_parser(
        "show",
        help="draw a scenario",
        description="Draw a scenario: obstacles, bounds, start (green) and goal (red) robots "
        "with their guards (dotted). 2D top view, 3D perspective.",
    )
    p.add_argument("scenario", metavar="SCENARIO", help="YAML scenario file")
    p.add_argument(
        "-o",
        "--output",
        metavar="FILE.png",
        help="image file (default: beside the scenario, same name, .png)",
    )
    p.set_defaults(handler=_cmd_show)

    from kcplan.planning.names import PLANNER_NAMES

    p = sub.add_parser(
        "plan",
        help="plan a path with a stock OMPL planner, with or without KC certificates",
        description="Plan from start to goal. Exit 0 solved, 1 not solved in time, 2 bad input.",
    )
    p.add_argument("scenario", metavar="SCENARIO", help="YAML scenario file")
    p.add_argument(
        "--planner",
        default="kc-rrtconnect",
        choices=PLANNER_NAMES,
        help="planner (default kc-rrtconnect)",
    )
    p.add_argument(
        "--time",
        type=_positive_float,
        default=10.0,
        metavar="SECONDS",
        help="planning time limit (default 10)",
    )
    p.add_argument("--seed", type=int, help="OMPL random seed, for reproducible runs")
    p.add_argument(
        "--simplify",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="simplify the path (every new edge is validated again; default on)",
    )
    p.add_argument("-o", "--output", metavar="PATH.json", help="write the path as JSON")
    p.add_argument("--plot", metavar="FILE.png", help="draw the map and the path")
    p.add_argument("--guards", action="store_true", help="also draw the guards certifying the path")
    p.set_defaults(handler=_cmd_plan)

    p = sub.add_parser(
        "verify",
        help="check a path for collisions without gaps (conservative advancement)",
        description="Check every edge of a path, interpolated as OMPL does, with FCL "
        "clearances and conservative advancement (independent of the KC bounds). Exit 0 "
        "clean, 1 collision, 2 bad input.",
    )
    p.add_argument("scenario", metavar="SCENARIO", help="YAML scenario file")
    p.add_argument("path", metavar="PATH.json", help="path file written by kcplan plan")
    p.add_argument(
        "--tolerance",
        type=_positive_float,
        default=1e-6,
        help="clearance below which a pose counts as colliding (default 1e-6)",
    )
    p.set_defaults(handler=_cmd_verify)

    p = sub.add_parser(
        "bench",
        help="benchmark planners on scenarios: OMPL logs, Planner Arena database, summary, plots",
        description="Run every planner on every scenario RUNS times, each run a fresh worker "
        "process with its own recorded seed (run i uses SEED + i for every planner), verify "
        "every returned path, and write OMPL benchmark logs, results.db (Planner Arena), "
        "summary.csv, summary.md and plots into DIR. Exit 0 done, 2 bad input, 130 "
        "interrupted (the reports then cover the finished runs).",
    )
    p.add_argument("scenarios", nargs="+", metavar="SCENARIO", help="YAML scenario files")
    p.add_argument(
        "--planners",
        default="kc-rrtconnect,rrtconnect,kc-prm,prm",
        metavar="LIST",
        help="comma-separated planner names (default kc-rrtconnect,rrtconnect,kc-prm,prm)",
    )
    p.add_argument("--runs", type=_positive_int, default=10, help="runs per planner (default 10)")
    p.add_argument(
        "--time",
        type=_positive_float,
        default=10.0,
        metavar="SECONDS",
        help="time limit of each solve (default 10; simplification gets as much again)",
    )
    p.add_argument("--seed", type=_positive_int, default=1, help="seed of run 0 (default 1)")
    p.add_argument(
        "--jobs", type=_positive_int, default=1, help="worker processes at a time (default 1)"
    )
    p.add_argument(
        "--run-timeout",
        type=_positive_float,
        metavar="SECONDS",
        help="kill a worker after this long (default 2 x --time + 60)",
    )
    p.add_argument(
        "--simplify",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="simplify returned paths (default on)",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on a dask.distributed scheduler instead of local processes "
        '(pip install "kcplan[dask]")',
    )
    p.add_argument(
        "-o",
        "--output",
        default="bench-results",
        metavar="DIR",
        help="output folder (default bench-results)",
    )
    p.add_argument("--force", action="store_true", help="replace kcplan's earlier results in DIR")
    p.set_defaults(handler=_cmd_bench)

    p = sub.add_parser(
        "pick-place",
        help="pick-and-place error analysis: required target inflation and parts entropy",
        description="The paper's Sec. 9.2 study with a KUKA LWR (Table 2 setting): for each "
        "joint noise level, TRIALS error spaces of POSES placements; the smallest target "
        "inflation containing each (exact margin, geometric lower bound), whether the "
        "target inflated by --inflation contains it, and the parts entropy log V at the "
        "median required inflation. Writes summary.csv, trials.csv and pick_place.png.",
    )
    p.add_argument(
        "--sigma-deg",
        nargs="+",
        type=_finite_float,
        default=[0.0, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5],
        metavar="S",
        help="joint noise standard deviations in degrees (default 0 0.02 0.05 0.1 0.2 0.3 0.5)",
    )
    p.add_argument("--trials", type=_positive_int, default=20, help="trials per level (default 20)")
    p.add_argument(
        "--poses", type=_positive_int, default=100, help="placements per trial (default 100)"
    )
    p.add_argument(
        "--inflation",
        type=_positive_float,
        default=0.05,
        metavar="EPS",
        help="the target's inflation for the containment question (default 0.05)",
    )
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument(
        "-o",
        "--output",
        default="pick-place",
        metavar="DIR",
        help="output folder (default pick-place)",
    )
    p.set_defaults(handler=_cmd_pick_place)

    p = sub.add_parser(
        "import",
        help="convert public benchmark maps (HRM, Moving AI) into scenario files",
        description="Convert a public benchmark map into a kcplan scenario YAML; the "
        "result is validated (start and goal free) before it is written.",
    )
    kinds = p.add_subparsers(dest="source", required=True, parser_class=_Parser)
    q = kinds.add_parser(
        "hrm",
        help="a Highway RoadMap map (CSV, github.com/ChirikjianLab/hrm)",
        description="Convert an HRM map with one of HRM's robots (every body kept, rigid). "
        "Superellipses become circumscribed polygons, superquadrics circumscribed convex "
        "polytopes (outer approximations); the arena is kept by walls outside its inscribed "
        "polygon (3D: a mesh surface and an inscribed box for the robot's origin); the "
        "bound on the geometric error is in the scenario's description.",
    )
    q.add_argument("resources", metavar="RESOURCES_DIR", help="HRM's resources folder")
    q.add_argument("--map", required=True, help="map name, e.g. ellipse_maze or maze")
    q.add_argument("--dimension", type=int, choices=(2, 3), default=2, help="2 (default) or 3")
    q.add_argument(
        "--robot",
        help="HRM robot: 2D NAO_silhouette, S_shape, rabbit, single_body (default); "
        "3D chair, rabbit (default), rabbit2, snake, tree",
    )
    q.add_argument("--inflation", type=_positive_float, default=0.1, help="guard inflation")
    q.add_argument("-o", "--output", required=True, metavar="SCENARIO.yaml")
    q.set_defaults(handler=_cmd_import)
    q = kinds.add_parser(
        "movingai",
        help="a Moving AI grid map (.map, optional .scen row)",
        description="Convert a Moving AI grid map: blocked cells become boxes merged into "
        "rectangles, walls keep the robot on the map, start and goal from a .scen row.",
    )
    q.add_argument("map_file", metavar="MAP.map")
    q.add_argument("--scen", metavar="FILE.scen", help="scenario file with start/goal rows")
    q.add_argument("--index", type=int, help="0-based row of --scen (default 0)")
    q.add_argument("--cell", type=_positive_float, default=1.0, help="cell size (default 1)")
    q.add_argument(
        "--robot",
        nargs=2,
        type=_positive_float,
        metavar=("A1", "A2"),
        help="robot semi-axes (default 0.7 and 0.4 times the narrowest corridor)",
    )
    q.add_argument("--inflation", type=_positive_float, default=0.1, help="guard inflation")
    q.add_argument("-o", "--output", required=True, metavar="SCENARIO.yaml")
    q.set_defaults(handler=_cmd_import)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``kcplan`` console script; returns the exit code."""
    try:
        args = build_parser().parse_args(argv)
        args.argv = list(sys.argv[1:] if argv is None else argv)
        return args.handler(args)
    except InputError as err:
        print(str(err), file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
