"""``kcplan bench``: benchmark campaigns."""

from __future__ import annotations

import argparse
import json
import shlex
import signal
import sys
from pathlib import Path

from kcplan.cli.common import (
    InputError,
    load_input,
    non_negative_float,
    positive_float,
    positive_int,
)


def run(args: argparse.Namespace) -> int:
    """Run the campaign and write its reports; exit 130 when interrupted."""
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
    from kcplan.planning.names import check_planner_for, check_planner_name

    planners = [p.strip() for p in args.planners.split(",") if p.strip()]
    if not planners:
        raise InputError(f"kcplan bench: --planners: expected planner names, got {args.planners!r}")
    for name in planners:
        try:
            check_planner_name(name)
        except ValueError as err:
            raise InputError(f"kcplan bench: --planners: {err}") from None
    scenarios = [load_input(path) for path in args.scenarios]
    for scenario in scenarios:  # planners that refuse the scenario's robot, up front
        for name in planners:
            try:
                check_planner_for(name, scenario)
            except ValueError as err:
                raise InputError(f"{scenario.source}: --planners: {err}") from None
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
        args.progress_interval or None,
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


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``kcplan bench`` on the subcommand parsers ``sub``."""
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
    p.add_argument("--runs", type=positive_int, default=10, help="runs per planner (default 10)")
    p.add_argument(
        "--time",
        type=positive_float,
        default=10.0,
        metavar="SECONDS",
        help="time limit of each solve (default 10; simplification gets as much again)",
    )
    p.add_argument("--seed", type=positive_int, default=1, help="seed of run 0 (default 1)")
    p.add_argument(
        "--jobs", type=positive_int, default=1, help="worker processes at a time (default 1)"
    )
    p.add_argument(
        "--run-timeout",
        type=positive_float,
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
        "--progress-interval",
        type=non_negative_float,
        default=0.1,
        metavar="SECONDS",
        help="sample the best cost of anytime planners (RRT*, Informed RRT*, SORRT*, AORRTC, "
        "BIT*) every SECONDS while they solve, for the logs' progress section, Planner "
        "Arena's progress plots and plots/cost_over_time.png (default 0.1; 0: off)",
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
    p.set_defaults(handler=run)
