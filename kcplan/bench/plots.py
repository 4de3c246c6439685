"""Benchmark figures: per-scenario distributions and success rate against time budget."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

import numpy as np

from kcplan.viz import plt, save_figure  # pyplot with the Agg backend kcplan.viz chose

__all__ = ["plot_distributions", "plot_success_vs_budget"]

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
}


def _color(planner: str, i: int) -> str:
    # planners without a colour of their own: grey shades
    return _COLORS.get(planner, plt.cm.Greys(0.4 + 0.15 * (i % 4)))


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
            ("time to solution [s]", lambda r: r["time"]),
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
    cols = min(4, len(scenarios))
    rows = math.ceil(len(scenarios) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.0 * rows), squeeze=False)
    limit = max(r["time_limit"] for r in records)
    budgets = np.geomspace(1e-3, limit, 200)
    for ax, scenario in zip(axes.flat, scenarios, strict=False):
        runs = [r for r in records if r["scenario_name"] == scenario]
        for i, planner in enumerate(_planners(runs)):
            mine = [r for r in runs if r["planner"] == planner]
            times = np.array([r["time"] for r in mine if r["solved"] and not r["collides"]])
            rate = (times[None, :] <= budgets[:, None]).sum(axis=1) / len(mine)
            ax.step(budgets, rate, where="post", label=planner, color=_color(planner, i))
        ax.set_xscale("log")
        ax.set_ylim(-0.03, 1.03)
        ax.set_title(scenario, fontsize=10)
        ax.set_xlabel("time budget [s]")
        ax.set_ylabel("success rate")
        ax.grid(alpha=0.3)
    for ax in list(axes.flat)[len(scenarios) :]:
        ax.axis("off")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), frameon=False)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    save_figure(fig, path)
