"""Per scenario and planner statistics of a campaign: ``summary.csv`` and ``summary.md``.

Conventions: times are seconds of ``solve()`` to the first solution (anytime planners
such as RRT* run on to the time limit; their first solution is found from their progress
samples, :func:`solution_time`); a run that did not solve (or whose worker failed) counts
at the time limit in ``median_time`` and ``p90_time``, so a planner cannot
look fast by failing; ``median_fcl_queries`` (collision plus distance queries, state checks
and guards together) is over runs whose worker finished; ``median_length`` is over solved
runs (OMPL path length after simplification). A kc planner's *twin* is the stock planner
it wraps (``kc-prm`` -> ``prm``), or its 0.1 % resolution version (``prm-fine``) when
only that ran; its *ca twin* is the same planner with the plain clearance-ball
certificate (``kc-prm`` -> ``ca-prm``, the ablation baseline). Ratios are twin / kc, so
above 1 means kc wins. ``share_*`` columns are the share of the certified edge parameter
each certificate won (from the ``kc_covered_*`` counters; medians over runs).
``median_cost_10pct``, ``median_cost_50pct`` and ``median_cost_final`` are the median best
cost at 10 %, 50 % and 100 % of the time limit over all runs, of planners that record
progress (inf when more than half the runs have no solution yet; empty without progress).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence

import numpy as np

from kcplan.planning.names import PLANNER_NAMES

__all__ = [
    "SUMMARY_COLUMNS",
    "solution_time",
    "cost_at",
    "twin_of",
    "ca_twin_of",
    "summarize",
    "summary_csv",
    "summary_markdown",
]

SUMMARY_COLUMNS = (
    "scenario",
    "planner",
    "runs",
    "solved",
    "success_rate",
    "median_time",
    "p90_time",
    "median_fcl_queries",
    "median_length",
    "colliding_paths",
)
"""The first columns of ``summary.csv``, in this order (issue 5)."""

COST_FRACTIONS = {"median_cost_10pct": 0.1, "median_cost_50pct": 0.5, "median_cost_final": 1.0}
COST_COLUMNS = tuple(COST_FRACTIONS)

EXTRA_COLUMNS = (
    "checked_parts",
    "colliding_parts",
    "failed_runs",
    "median_collision_queries",
    "median_distance_queries",
    "median_kc_guards",
    "median_certified_edges",
    "median_simplify_time",
    "twin",
    "time_ratio",
    "query_ratio",
    "ca_twin",
    "ca_time_ratio",
    "ca_query_ratio",
    "share_region",
    "share_polytope",
    "share_ball",
    *COST_COLUMNS,
)


def twin_of(planner: str) -> str | None:
    """The stock planner a certified planner wraps, or None (``kc-rrtconnect-discrete``,
    ``ca-rrtconnect``, ``kc-rrtconnect-paper`` -> ``rrtconnect``)."""
    if not planner.startswith(("kc-", "ca-")):
        return None
    base = planner[3:].removesuffix("-discrete").removesuffix("-paper")
    return base if base in PLANNER_NAMES else None


def ca_twin_of(planner: str) -> str | None:
    """The clearance-ball ablation of a ``kc-*`` planner (``kc-prm-paper`` -> ``ca-prm``),
    or None."""
    base = twin_of(planner)
    if not planner.startswith("kc-") or base is None:
        return None
    twin = f"ca-{base}"
    return twin if twin in PLANNER_NAMES else None


def solution_time(record: dict) -> float | None:
    """Seconds to the first solution of a run: the recorded first-solution time of an
    anytime planner (which runs to the time limit), else the solve time; None unsolved."""
    if not record.get("solved"):
        return None
    first = record.get("first_solution_time")
    return record["time"] if first is None else first


def cost_at(record: dict, t: float) -> float:
    """A run's best cost at ``t`` seconds into ``solve()`` from its progress samples
    (the last sample at or before ``t``; inf before the first solution or without
    samples)."""
    progress = record.get("progress") or {}
    times = progress.get("time REAL", [])
    i = int(np.searchsorted(times, t, side="right")) - 1
    return float(progress["best cost REAL"][i]) if i >= 0 else math.inf


def _median(values: Sequence[float]) -> float:
    return float(np.median(values)) if len(values) else math.nan


def summarize(records: Sequence[dict]) -> list[dict]:
    """One row per (scenario, planner), in the order they first appear in ``records``."""
    groups: dict[tuple[str, str], list[dict]] = {}
    for r in records:
        groups.setdefault((r["scenario_name"], r["planner"]), []).append(r)
    rows = []
    for (scenario, planner), runs in groups.items():
        finished = [r for r in runs if r["status"] == "ok"]
        solved = [r for r in finished if r["solved"]]
        charged = [r["time_limit"] if (t := solution_time(r)) is None else t for r in runs]

        def counter(name: str, runs=finished) -> float:
            return _median([r["counters"][name] for r in runs if name in r["counters"]])

        certified = [
            r["counters"]["kc_edges"] - r["counters"]["kc_rejected"]
            for r in finished
            if "kc_edges" in r["counters"]
        ]
        rows.append(
            {
                "scenario": scenario,
                "planner": planner,
                "runs": len(runs),
                "solved": len(solved),
                "success_rate": len(solved) / len(runs),
                "median_time": _median(charged),
                "p90_time": float(np.percentile(charged, 90)),
                "median_fcl_queries": counter("fcl_queries"),
                "median_length": _median([r["length"] for r in solved]),
                "colliding_paths": sum(bool(r["collides"]) for r in solved),
                "checked_parts": sum(r.get("part_collides") is not None for r in solved),
                "colliding_parts": sum(bool(r.get("part_collides")) for r in solved),
                "failed_runs": len(runs) - len(finished),
                "median_collision_queries": counter("collision_queries"),
                "median_distance_queries": counter("distance_queries"),
                "median_kc_guards": counter("kc_guards"),
                "median_certified_edges": _median(certified),
                "median_simplify_time": _median([r["simplify_time"] for r in solved]),
                "twin": twin_of(planner) or "",
                "ca_twin": ca_twin_of(planner) or "",
                **_shares(finished),
                **_costs(runs),
            }
        )
    by_key = {(r["scenario"], r["planner"]): r for r in rows}
    for row in rows:
        if row["twin"] and (row["scenario"], row["twin"]) not in by_key:
            fine = row["twin"] + "-fine"  # the campaign ran the 0.1 % resolution twin instead
            row["twin"] = fine if (row["scenario"], fine) in by_key else row["twin"]
        twin = by_key.get((row["scenario"], row["twin"]))
        row["time_ratio"] = _ratio(twin, row, "median_time")
        row["query_ratio"] = _ratio(twin, row, "median_fcl_queries")
        ca = by_key.get((row["scenario"], row["ca_twin"]))
        row["ca_time_ratio"] = _ratio(ca, row, "median_time")
        row["ca_query_ratio"] = _ratio(ca, row, "median_fcl_queries")
    return rows


def _shares(runs: Sequence[dict]) -> dict:
    """Median share of the covered edge parameter won by each certificate."""
    out = {}
    for name in ("region", "polytope", "ball"):
        shares = []
        for r in runs:
            covered = {k: v for k, v in r["counters"].items() if k.startswith("kc_covered_")}
            total = sum(covered.values())
            if total > 0:
                shares.append(covered.get(f"kc_covered_{name}", 0.0) / total)
        out[f"share_{name}"] = _median(shares)
    return out


def _costs(runs: Sequence[dict]) -> dict:
    """Median best cost at fractions of the time limit (NaN when no run has progress)."""
    if not any(r.get("progress") for r in runs):
        return dict.fromkeys(COST_COLUMNS, math.nan)
    limit = runs[0]["time_limit"]
    return {
        column: _median([cost_at(r, f * limit) for r in runs])
        for column, f in COST_FRACTIONS.items()
    }


def _ratio(twin: dict | None, row: dict, column: str) -> float:
    if twin is None or not row[column] > 0:
        return math.nan
    return twin[column] / row[column]


def _cell(v: object) -> str:
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.6g}"
    return str(v)


def summary_csv(rows: Sequence[dict]) -> str:
    """CSV text: :data:`SUMMARY_COLUMNS`, then the extra columns; NaN is an empty cell."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    columns = SUMMARY_COLUMNS + EXTRA_COLUMNS
    writer.writerow(columns)
    for row in rows:
        writer.writerow([_cell(row[c]) for c in columns])
    return buf.getvalue()


def _fmt(v: float, spec: str) -> str:
    return "–" if math.isnan(v) else format(v, spec)


def summary_markdown(rows: Sequence[dict], title: str = "Benchmark summary") -> str:
    """A Markdown table of the rows, with kc / stock-twin ratios."""
    out = [
        f"# {title}",
        "",
        "Times are seconds in `solve()`, unsolved runs counted at the time limit; FCL "
        "queries are collision, distance and region queries (a region query is one "
        "broad-phase query plus one distance per obstacle piece within the horizon); "
        "*colliding* counts returned paths that gap-free verification (`kcplan verify`) "
        "found in collision. *twin/kc* compares a certified planner with the stock planner "
        "it wraps, *ca/kc* a kc planner with its clearance-ball ablation (`ca-*`): "
        "twin / kc, so above 1 means kc wins. *region* and *polytope* are the median "
        "shares of the certified edge parameter won by those certificates.",
        "",
        "| scenario | planner | solved | median time | p90 time | median FCL queries "
        "| median length | colliding | failed | time twin/kc | queries twin/kc "
        "| time ca/kc | queries ca/kc | region | polytope |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        out.append(
            f"| {r['scenario']} | {r['planner']} | {r['solved']}/{r['runs']} "
            f"| {_fmt(r['median_time'], '.3f')} | {_fmt(r['p90_time'], '.3f')} "
            f"| {_fmt(r['median_fcl_queries'], '.0f')} | {_fmt(r['median_length'], '.2f')} "
            f"| {r['colliding_paths']} | {r['failed_runs']} "
            f"| {_fmt(r['time_ratio'], '.2f')} | {_fmt(r['query_ratio'], '.2f')} "
            f"| {_fmt(r['ca_time_ratio'], '.2f')} | {_fmt(r['ca_query_ratio'], '.2f')} "
            f"| {_fmt(r['share_region'], '.2f')} | {_fmt(r['share_polytope'], '.2f')} |"
        )
    parts = [r for r in rows if r["checked_parts"]]
    if parts:
        out += [
            "",
            "Mesh robots (`robot.mesh`): every solved path was also checked without gaps "
            "against the part's own mesh (`kcplan verify --mesh`).",
            "",
            "| scenario | planner | paths checked | part colliding |",
            "|---|---|---|---|",
        ]
        out += [
            f"| {r['scenario']} | {r['planner']} | {r['checked_parts']} | {r['colliding_parts']} |"
            for r in parts
        ]
    anytime = [r for r in rows if not math.isnan(r["median_cost_final"])]
    if anytime:
        out += [
            "",
            "Best cost over time (anytime planners; OMPL's progress property *best cost*, "
            "path length unless the objective says otherwise): median over all runs at 10 %, "
            "50 % and 100 % of the time limit, inf while more than half the runs have no "
            "solution; first solution as median time above.",
            "",
            "| scenario | planner | first solution | cost at 10 % | cost at 50 % | final cost |",
            "|---|---|---|---|---|---|",
        ]
        out += [
            f"| {r['scenario']} | {r['planner']} | {_fmt(r['median_time'], '.3f')} "
            + "".join(f"| {_fmt(r[c], '.2f')} " for c in COST_COLUMNS)
            + "|"
            for r in anytime
        ]
    return "\n".join(out) + "\n"
