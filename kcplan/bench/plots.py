"""Benchmark figures: per-scenario distributions and success rate against time budget."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

import numpy as np
from matplotlib import colors as mcolors

from kcplan.bench.summary import cost_at, solution_time
from kcplan.views.plots import plt, save_figure  # pyplot on the Agg backend views.plots chose

__all__ = ["plot_distributions", "plot_success_vs_budget", "plot_cost_over_time"]

_COLORS = {
    "kc-rrtconnect": "#1f77b4",
    "rrtconnect": "#aec7e8",
    "kc-prm": "#d62728",
    "prm": "#ff9896",
    "kc-rrtconnect-discrete": "#2ca02c",
    "ca-rrtconnect": "#17becf",
    "ca-prm": "#e377c2",
    "kc-rrtconnect-paper": "#8c564b",
    "kc-prm-paper": "#bcbd22",
    "rrtconnect-fine": "#ff7f0e",
    "prm-fine": "#9467bd",
    "kc-rrtconnect-py": "#393b79",
    "kc-prm-py": "#843c39",
    "rrtconnect-fcl": "#7f7f7f",
    "prm-fcl": "#c7c7c7",
}


def _color(planner: str, i: int) -> str:
    # planners without a colour of their own: matplotlib's qualitative cycle, less the
    # colours the named planners have (else e.g. a fourth planner drew kc-prm's red)
    if planner in _COLORS:
        return _COLORS[planner]
    free = [c for c in map(mcolors.to_hex, plt.cm.tab20.colors) if c not in _COLORS.values()]
    return free[i % len(free)]


def _planners(records: Sequence[dict]) -> list[str]:
    return list(dict.fromkeys(r["planner"] for r in records))


def plot_distributions(records: Sequence[dict], scenario: str, path: str | os.PathLike) -> None:
    """Box plots of solve time and FCL queries per planner, over the solved runs of one
    scenario (log scales; each box labelled with its solved count and, when stock
    returned some, how many of those paths collide)."""
    runs = [r for r in records if r["scenario_name"] == scenario]
    planners = _planners(runs)
    fig, axes = plt.subplots(1, 2, figsize=(4 + 1.4 * len(planners), 4.2))
    for ax, (label, get) in zip(
        axes,
        (
            ("time to first solution [s]", solution_time),
            ("FCL queries (collision, distance, region)", lambda r: r["counters"]["fcl_queries"]),
        ),
        strict=True,
    ):
        data, names = [], []
        for planner in planners:
            mine = [r for r in runs if r["planner"] == planner]
            solved = [r for r in mine if r["solved"]]
            data.append([max(get(r), 1e-4) for r in solved] or [math.nan])
            colliding = sum(bool(r.get("collides")) for r in solved)
            name = f"{planner}\n{len(solved)}/{len(mine)} solved"
            names.append(name + (f"\n{colliding} colliding" if colliding else ""))
        box = ax.boxplot(data, patch_artist=True, widths=0.6)
        for i, (patch, planner) in enumerate(zip(box["boxes"], planners, strict=True)):
            patch.set_facecolor(_color(planner, i))
        for i, values in enumerate(data, start=1):
            ax.plot(np.full(len(values), i), values, ".", color="k", ms=3, alpha=0.5)
        ax.set_xticks(range(1, len(names) + 1), names, fontsize=8, rotation=30, ha="right")
        if any(np.isfinite(v).any() for v in data):  # log of nothing fails in matplotlib
            ax.set_yscale("log")
        else:
            ax.text(0.5, 0.5, "no solved runs", ha="center", transform=ax.transAxes)
        ax.set_ylabel(label)
        ax.grid(axis="y", alpha=0.3)
    fig.suptitle(f"{scenario}: solved runs")
    fig.tight_layout()
    save_figure(fig, path)


def plot_success_vs_budget(records: Sequence[dict], path: str | os.PathLike) -> None:
    """Fraction of runs solved within each time budget, one panel per scenario; a
    returned path that collides counts as a failure."""
    scenarios = list(dict.fromkeys(r["scenario_name"] for r in records))
    fig, axes = _panels(len(scenarios))
    limit = max(r["time_limit"] for r in records)
    budgets = np.geomspace(1e-3, limit, 200)
    for ax, scenario in zip(axes.flat, scenarios, strict=False):
        runs = [r for r in records if r["scenario_name"] == scenario]
        for i, planner in enumerate(_planners(runs)):
            mine = [r for r in runs if r["planner"] == planner]
            times = np.array([solution_time(r) for r in mine if r["solved"] and not r["collides"]])
            rate = (times[None, :] <= budgets[:, None]).sum(axis=1) / len(mine)
            ax.step(budgets, rate, where="post", label=planner, color=_color(planner, i))
        ax.set_xscale("log")
        ax.set_ylim(-0.03, 1.03)
        ax.set_title(scenario, fontsize=10)
        ax.set_xlabel("time budget [s]")
        ax.set_ylabel("success rate")
        ax.grid(alpha=0.3)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), frameon=False)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    save_figure(fig, path)


def _panels(n: int, width: float = 3.6, height: float = 3.0):
    cols = min(4, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, height * rows), squeeze=False)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    return fig, axes


def plot_cost_over_time(records: Sequence[dict], path: str | os.PathLike) -> None:
    """Best cost against time (log scale) of the planners that record progress, one
    panel per scenario: the median over all runs (drawn once more than half the runs
    have a solution) and the band between the 25th and 75th percentiles. A certified
    planner and its twins share a colour: ``kc-*`` solid, ``ca-*`` dotted, stock dashed."""
    runs = [r for r in records if r.get("progress")]
    scenarios = list(dict.fromkeys(r["scenario_name"] for r in runs))
    planners = _planners(runs)
    bases = list(dict.fromkeys(p.removeprefix("kc-").removeprefix("ca-") for p in planners))
    fig, axes = _panels(len(scenarios), 4.4, 3.4)
    for ax, scenario in zip(axes.flat, scenarios, strict=False):
        mine = [r for r in runs if r["scenario_name"] == scenario]
        start = min(r["progress"]["time REAL"][0] for r in mine)
        grid = np.geomspace(start, max(r["time_limit"] for r in mine), 300)
        for planner in planners:
            theirs = [
                r for r in records if r["scenario_name"] == scenario and r["planner"] == planner
            ]
            if not any(r.get("progress") for r in theirs):
                continue
            cost = np.array([[cost_at(r, t) for t in grid] for r in theirs])
            with np.errstate(invalid="ignore"):  # inf - inf between unsolved runs
                low, mid, high = np.percentile(cost, [25, 50, 75], axis=0)
            base = planner.removeprefix("kc-").removeprefix("ca-")
            color = plt.cm.tab10(bases.index(base) % 10)
            style = "-" if planner.startswith("kc-") else ":" if planner.startswith("ca-") else "--"
            ax.step(grid, mid, style, where="post", color=color, label=planner)
            high = np.where(np.isfinite(high), high, np.nan)
            ax.fill_between(grid, low, high, step="post", color=color, alpha=0.15, lw=0)
        ax.set_xscale("log")
        ax.set_title(scenario, fontsize=10)
        ax.set_xlabel("time into solve() [s]")
        ax.set_ylabel("best cost (path length)")
        ax.grid(alpha=0.3)
    axes.flat[0].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    save_figure(fig, path)
