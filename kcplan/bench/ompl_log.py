"""OMPL benchmark log files and the Planner Arena database built from them.

The log is the text format of ``ompl::tools::Benchmark::saveResultsToStream`` (OMPL 2.0),
written here from kcplan's run records because ``ompl.tools.Benchmark`` keeps only the
properties it measured itself (see ``ompl-python-notes.md``, section 5). One log holds one
experiment (one scenario) and every planner run on it; kcplan's own measurements (FCL
queries, KC guards, whether the returned path collides) are extra run properties, which
``ompl_benchmark_statistics.py`` turns into columns of the ``runs`` table.

:func:`build_database` runs the script shipped in the ``ompl`` wheel
(``python -m ompl.ompl_benchmark_statistics LOG... -d results.db``), so the database is
exactly what Planner Arena (plannerarena.org) expects.
"""

from __future__ import annotations

import math
import os
import platform
import socket
import subprocess
import sys
from collections.abc import Callable, Sequence
from datetime import datetime
from pathlib import Path

from kcplan.bench.summary import solution_time
from kcplan.files import atomic_output

__all__ = ["RUN_PROPERTIES", "STATUS", "format_log", "build_database"]

STATUS = (
    "Unknown status",
    "Invalid start",
    "Invalid goal",
    "Unrecognized goal type",
    "Timeout",
    "Approximate solution",
    "Exact solution",
    "Crash",
)
"""OMPL's ``PlannerStatus`` enum, in its order (the log's ``status`` ENUM values)."""


def _status(r: dict) -> int:
    if r["status"] != "ok":
        return STATUS.index("Crash")
    return STATUS.index("Exact solution") if r["solved"] else STATUS.index("Timeout")


def _counter(name: str) -> Callable[[dict], object]:
    return lambda r: r["counters"].get(name)


def _solved_value(name: str) -> Callable[[dict], object]:
    return lambda r: r.get(name) if r["solved"] else None


RUN_PROPERTIES: tuple[tuple[str, str, Callable[[dict], object]], ...] = (
    # OMPL's own names, so Planner Arena's default plots work
    ("time", "REAL", lambda r: r["time"]),
    ("time to first solution", "REAL", solution_time),
    ("solved", "BOOLEAN", lambda r: r["solved"]),
    ("status", "ENUM", _status),
    ("approximate solution", "BOOLEAN", lambda r: False if r["status"] == "ok" else None),
    ("correct solution", "BOOLEAN", lambda r: (not r["collides"]) if r["solved"] else None),
    ("solution length", "REAL", _solved_value("raw_length")),
    ("simplified solution length", "REAL", _solved_value("length")),
    ("simplification time", "REAL", _solved_value("simplify_time")),
    ("memory", "REAL", lambda r: r.get("memory_mb")),
    # kcplan's measurements
    ("seed", "INTEGER", lambda r: r["seed"]),
    ("fcl queries", "INTEGER", _counter("fcl_queries")),
    ("fcl collision queries", "INTEGER", _counter("collision_queries")),
    ("fcl distance queries", "INTEGER", _counter("distance_queries")),
    ("fcl region queries", "INTEGER", _counter("region_queries")),
    ("fcl region pairs", "INTEGER", _counter("region_pairs")),
    ("state checks", "INTEGER", _counter("checker_calls")),
    ("kc edges", "INTEGER", _counter("kc_edges")),
    (
        "kc certified edges",
        "INTEGER",
        lambda r: (
            (r["counters"]["kc_edges"] - r["counters"]["kc_rejected"])
            if "kc_edges" in r["counters"]
            else None
        ),
    ),
    ("kc edges one guard", "INTEGER", _counter("kc_certified_one_guard")),
    ("kc edges by endpoint guards", "INTEGER", _counter("kc_certified_by_endpoints")),
    ("kc cached guards", "INTEGER", _counter("kc_cached_guards")),
    ("kc guards", "INTEGER", _counter("kc_guards")),
    ("kc bisection nodes", "INTEGER", _counter("kc_bisection_nodes")),
    ("kc rejected end state", "INTEGER", _counter("kc_rejected_end_state")),
    ("kc not proven", "INTEGER", _counter("kc_not_proven")),
    ("kc rejected sweep", "INTEGER", _counter("kc_rejected_sweep")),
    ("kc rejected occupancy", "INTEGER", _counter("kc_rejected_occupancy")),
    ("kc rejected probe", "INTEGER", _counter("kc_rejected_probe")),
    ("kc probes", "INTEGER", _counter("kc_probes")),
    ("kc covered region", "REAL", _counter("kc_covered_region")),
    ("kc covered polytope", "REAL", _counter("kc_covered_polytope")),
    ("kc covered ball", "REAL", _counter("kc_covered_ball")),
    ("path collides", "BOOLEAN", _solved_value("collides")),
    ("path min clearance", "REAL", _solved_value("min_clearance")),
    ("verify queries", "INTEGER", _solved_value("verify_queries")),
    ("worker wall time", "REAL", lambda r: r.get("wall")),
    ("failure", "VARCHAR(512)", lambda r: r.get("reason") or None),
)
"""``(name, SQL type, value of a record)`` of every run property, in log order."""


def _value(v: object) -> str:
    if v is None:
        return ""  # the statistics script stores an empty field as NULL
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, float):
        return "inf" if math.isinf(v) else f"{v:.9g}"
    # text values: the fields are separated by "; " and the line ends the run
    return str(v).replace(";", ",").replace("\n", " ")


def _cpu_info() -> str:
    try:
        text = Path("/proc/cpuinfo").read_text()
        model = next(
            line.split(":", 1)[1].strip()
            for line in text.splitlines()
            if line.startswith("model name")
        )
    except (OSError, StopIteration):
        model = platform.processor() or platform.machine()
    return f"{model}\nCPU(s): {os.cpu_count()}\n"


def format_log(
    experiment: str,
    records: Sequence[dict],
    planners: Sequence[tuple[str, dict]],
    properties: dict[str, tuple[str, object]],
    setup: str,
    seed: int,
    time_limit: float,
    runs_per_planner: int,
    started: datetime,
    ompl_version: str,
) -> str:
    """The text of one OMPL benchmark log.

    Parameters
    ----------
    experiment : str
        Experiment name (the scenario's name).
    records : sequence of dict
        Run records of this experiment (any planners, any order within a planner).
    planners : sequence of (name, settings)
        Planners in log order; ``settings`` become the planner's common properties.
    properties : dict
        Experiment properties, ``name -> (SQL type, value)``.
    setup : str
        Free text for the experiment's setup block.
    """
    lines = [
        f"OMPL version {ompl_version}",
        f"Experiment {experiment}",
        f"{len(properties)} experiment properties",
        *(f"{name} {kind} = {_value(v)}" for name, (kind, v) in properties.items()),
        f"Running on {socket.gethostname()}",
        f"Starting at {started:%Y-%m-%d %H:%M:%S}",
        "<<<|",
        setup.rstrip("\n"),
        "|>>>",
        "<<<|",
        _cpu_info().rstrip("\n"),
        "|>>>",
        f"{seed} is the random seed",
        f"{time_limit:g} seconds per run",
        "0 MB per run",
        f"{runs_per_planner} runs per planner",
        f"{sum(r.get('wall') or 0.0 for r in records):.6g} seconds spent to collect the data",
        "1 enum type",
        "status|" + "|".join(STATUS),
        f"{len(planners)} planners",
    ]
    for name, settings in planners:
        runs = sorted((r for r in records if r["planner"] == name), key=lambda r: r["run"])
        lines += [name, f"{len(settings)} common properties"]
        lines += [f"{k} = {_value(v)}" for k, v in settings.items()]
        lines.append(f"{len(RUN_PROPERTIES)} properties for each run")
        lines += [f"{prop} {kind}" for prop, kind, _ in RUN_PROPERTIES]
        lines.append(f"{len(runs)} runs")
        for r in runs:
            lines.append("".join(f"{_value(get(r))}; " for _, _, get in RUN_PROPERTIES))
        lines += _progress_lines(runs)
        lines.append(".")
    return "\n".join(lines) + "\n"


def _progress_lines(runs: Sequence[dict]) -> list[str]:
    """The planner's progress section (OMPL's format: property names, then one line per
    run of ``value,...,;`` samples), or nothing when no run recorded progress."""
    names = next((list(r["progress"]) for r in runs if r.get("progress")), [])
    if not names:
        return []
    lines = [f"{len(names)} progress properties for each run", *names, f"{len(runs)} runs"]
    for r in runs:
        columns = [(r.get("progress") or {}).get(name, []) for name in names]
        samples = zip(*columns, strict=True)
        lines.append("".join("".join(f"{_value(v)}," for v in s) + ";" for s in samples))
    return lines


def build_database(logs: Sequence[str | os.PathLike], database: str | os.PathLike) -> None:
    """Build ``database`` from ``logs`` with OMPL's ``ompl_benchmark_statistics`` script.

    The database is built beside its final name and renamed into place, so an existing
    one survives a failure. Raises ``RuntimeError`` with the script's message on failure.
    """
    with atomic_output(database) as tmp:
        tmp.unlink()  # the script appends to an existing file
        done = subprocess.run(
            [
                sys.executable,
                "-m",
                "ompl.ompl_benchmark_statistics",
                *map(str, logs),
                "-d",
                str(tmp),
            ],
            capture_output=True,
            text=True,
        )
        if done.returncode != 0:
            tail = " | ".join(done.stderr.strip().splitlines()[-2:])
            raise RuntimeError(f"ompl_benchmark_statistics failed: {tail}")
