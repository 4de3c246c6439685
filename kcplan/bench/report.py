"""Everything a campaign writes into its output folder, from its run records.

Layout of ``DIR``::

    campaign.json        the run specifications, command, versions and machine
    runs.jsonl           one record per finished run, appended as runs finish
    logs/SCENARIO.log    OMPL benchmark log, one experiment per scenario
    results.db           Planner Arena database (OMPL's ompl_benchmark_statistics.py)
    summary.csv          per scenario and planner (kcplan.bench.summary)
    summary.md           the same as a table, with kc / stock-twin ratios
    plots/SCENARIO.png   time and FCL-query distributions per planner
    plots/success_vs_budget.png
    plots/cost_over_time.png   best cost against time (when anytime planners ran)

Reports are rebuilt from ``runs.jsonl`` by :func:`write_reports`, each file atomically,
so an interrupted campaign still leaves complete files for the runs that finished.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Sequence
from datetime import datetime
from pathlib import Path

from kcplan.bench.ompl_log import build_database, format_log
from kcplan.bench.plots import plot_cost_over_time, plot_distributions, plot_success_vs_budget
from kcplan.bench.summary import summarize, summary_csv, summary_markdown
from kcplan.files import write_text_atomic

__all__ = ["OUTPUTS", "prepare_output", "write_reports"]

OUTPUTS = (
    "campaign.json",
    "runs.jsonl",
    "logs",
    "results.db",
    "summary.csv",
    "summary.md",
    "plots",
)
"""Names kcplan creates in a campaign folder (``--force`` removes only these)."""


def prepare_output(out_dir: str | os.PathLike, force: bool) -> Path:
    """Create the campaign folder, or clear kcplan's earlier results from it with ``force``.

    Raises ``ValueError`` (one line, naming the folder) when the folder holds anything
    and ``force`` is not given, or when it is not a folder. Only the names in
    :data:`OUTPUTS` are removed; other files in the folder are left alone.
    """
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise ValueError(f"{out}: expected an output folder, got an existing file")
    if out.is_dir() and any(out.iterdir()):
        ours = [name for name in OUTPUTS if (out / name).exists()]
        if not force:
            held = f"earlier results ({', '.join(ours)})" if ours else "other files"
            raise ValueError(
                f"{out}: folder already holds {held}; pass --force to replace kcplan's "
                "results, or choose another -o folder"
            )
        for name in ours:
            target = out / name
            shutil.rmtree(target) if target.is_dir() else target.unlink()
    out.mkdir(parents=True, exist_ok=True)
    return out


def write_reports(
    out_dir: str | os.PathLike, records: Sequence[dict], campaign: dict
) -> dict[str, Path]:
    """Write logs, database, summaries and plots for ``records``; return their paths.

    ``campaign`` is the content of ``campaign.json`` (planners with their settings, seed,
    time limit, runs, ``started`` ISO time, OMPL version, scenario properties).
    """
    out = Path(out_dir)
    (out / "logs").mkdir(exist_ok=True)
    (out / "plots").mkdir(exist_ok=True)
    written: dict[str, Path] = {}
    started = datetime.fromisoformat(campaign["started"])
    planners = [(p["name"], p["settings"]) for p in campaign["planners"]]
    logs = []
    for scenario in campaign["scenarios"]:
        name = scenario["name"]
        mine = [r for r in records if r["scenario_name"] == name]
        if not mine:
            continue
        props = {
            "scenario file": ("VARCHAR(1024)", scenario["file"]),
            "dimension": ("INTEGER", scenario["dimension"]),
            "robot": ("VARCHAR(128)", _robot_text(scenario)),
            "kcplan version": ("VARCHAR(32)", campaign["kcplan_version"]),
        }
        text = format_log(
            name,
            mine,
            [p for p in planners if any(r["planner"] == p[0] for r in mine)],
            props,
            setup=f"{scenario['description']}\ncommand: {campaign['command']}\n",
            seed=campaign["seed"],
            time_limit=campaign["time_limit"],
            runs_per_planner=campaign["runs"],
            started=started,
            ompl_version=campaign["ompl_version"],
        )
        log = out / "logs" / f"{name}.log"
        write_text_atomic(log, text)
        logs.append(log)
        written[f"log:{name}"] = log
        plot = out / "plots" / f"{name}.png"
        plot_distributions(mine, name, plot)
        written[f"plot:{name}"] = plot
    if not records:
        return written
    build_database(logs, out / "results.db")
    written["database"] = out / "results.db"
    rows = summarize(records)
    write_text_atomic(out / "summary.csv", summary_csv(rows))
    write_text_atomic(
        out / "summary.md",
        summary_markdown(rows, f"kcplan bench, {started:%Y-%m-%d %H:%M}")
        + f"\nCommand: `{campaign['command']}`\n",
    )
    written["summary.csv"], written["summary.md"] = out / "summary.csv", out / "summary.md"
    plot_success_vs_budget(records, out / "plots" / "success_vs_budget.png")
    written["plot:success"] = out / "plots" / "success_vs_budget.png"
    if any(r.get("progress") for r in records):
        plot_cost_over_time(records, out / "plots" / "cost_over_time.png")
        written["plot:cost"] = out / "plots" / "cost_over_time.png"
    return written


def _robot_text(scenario: dict) -> str:
    """The campaign's robot description (campaigns before multi-body robots stored the
    semi-axes)."""
    if "robot" in scenario:
        return scenario["robot"]
    return "semi axes " + " ".join(map(str, scenario["semi_axes"]))
