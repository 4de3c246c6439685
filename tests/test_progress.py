"""Best cost over time of anytime planners (kcplan.planning.progress) and in kcplan bench."""

import math
import sqlite3
from pathlib import Path

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from kcplan import load_scenario, plan
from kcplan.bench.campaign import read_records
from kcplan.bench.summary import cost_at, solution_time, summarize
from kcplan.cli import main
from kcplan.planning.progress import ProgressRecorder, reports_progress

ROOT = Path(__file__).resolve().parents[1]
OPEN = str(ROOT / "scenarios/2d/open_field.yaml")


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(OPEN)


@pytest.mark.parametrize("planner", ["kc-rrtstar", "kc-bitstar", "kc-aorrtc", "rrtstar"])
def test_samples_are_timed_and_the_cost_only_falls(scenario, planner):
    result = plan(scenario, planner, time_limit=1.0, seed=3, progress=0.1, simplify=False)
    assert result.solved
    progress = result.progress
    assert list(progress)[:2] == ["time REAL", "best cost REAL"]
    times, cost = np.array(progress["time REAL"]), np.array(progress["best cost REAL"])
    assert len(times) >= 5 and len(set(map(len, progress.values()))) == 1
    assert np.all(np.diff(times) > 0) and np.all(np.diff(times)[:-1] >= 0.1)
    assert times[-1] <= 1.0 + 0.5  # the termination condition keeps the time limit
    finite = cost[np.isfinite(cost)]
    assert np.all(np.diff(finite) <= 1e-12)
    # the last sample is the path solve() returned; the first solution came before it
    assert math.isclose(cost[-1], result.raw_length, rel_tol=1e-9)
    assert 0 < result.first_solution_time < times[np.isfinite(cost)][0] + 1e-9
    if "iterations INTEGER" in progress:
        assert np.all(np.diff(progress["iterations INTEGER"]) >= 0)
    assert result.to_json()["progress"] is progress


@pytest.mark.parametrize("planner", ["kc-prmstar", "kc-rrtconnect", "fmt"])
def test_planners_without_progress_record_none_and_do_not_hang(scenario, planner):
    result = plan(scenario, planner, time_limit=0.5, seed=3, progress=0.1, simplify=False)
    assert result.progress == {} and result.first_solution_time is None


def test_recorder_refuses_what_it_cannot_follow():
    space = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0)
    bounds.setHigh(1)
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    # PRM polls its termination condition from a thread of its own (GIL deadlock)
    assert not reports_progress(og.PRMstar(si)) and not reports_progress(og.RRTConnect(si))
    assert reports_progress(og.RRTstar(si)) and reports_progress(og.BITstar(si))
    with pytest.raises(ValueError, match="PRMstar reports no progress"):
        ProgressRecorder(og.PRMstar(si), 0.1)
    with pytest.raises(ValueError, match="interval: expected seconds > 0, got 0"):
        ProgressRecorder(og.RRTstar(si), 0.0)


def test_cost_at_and_summary_costs_by_hand():
    def rec(run, times, costs, solved=True):
        return {
            "scenario_name": "s",
            "planner": "kc-rrtstar",
            "run": run,
            "time_limit": 10.0,
            "status": "ok",
            "solved": solved,
            "time": 10.0,
            "first_solution_time": next(
                (t for t, c in zip(times, costs, strict=True) if c < 1e9), None
            ),
            "simplify_time": 0.1,
            "length": 1.0,
            "collides": False,
            "counters": {"fcl_queries": 1},
            "progress": {"time REAL": times, "best cost REAL": costs},
        }

    inf = math.inf
    records = [
        rec(0, [1.0, 5.0, 10.0], [9.0, 7.0, 6.0]),
        rec(1, [1.0, 5.0, 10.0], [inf, 8.0, 5.0]),
        rec(2, [1.0, 5.0, 10.0], [inf, inf, inf], solved=False),
    ]
    assert cost_at(records[0], 0.5) == inf and cost_at(records[0], 1.0) == 9.0
    assert cost_at(records[0], 4.9) == 9.0 and cost_at(records[1], 5.0) == 8.0
    assert solution_time(records[1]) == 5.0 and solution_time(records[2]) is None
    row = summarize(records)[0]
    assert row["median_time"] == 5.0  # 1, 5 and the unsolved run at the limit
    assert row["median_cost_10pct"] == inf  # two of three runs unsolved at 1 s
    assert row["median_cost_50pct"] == 8.0 and row["median_cost_final"] == 6.0


def test_bench_writes_progress_to_log_database_summary_and_plot(tmp_path):
    out = tmp_path / "results"
    argv = ["bench", OPEN, "--planners", "kc-rrtstar,kc-prmstar", "--runs", "2", "--time", "1"]
    assert main([*argv, "--jobs", "2", "--progress-interval", "0.2", "-o", str(out)]) == 0
    records = read_records(out / "runs.jsonl")
    star = [r for r in records if r["planner"] == "kc-rrtstar"]
    assert all(len(r["progress"]["time REAL"]) >= 3 for r in star)
    assert all(r["progress"] == {} for r in records if r["planner"] == "kc-prmstar")
    log = (out / "logs" / "open_field.log").read_text()
    assert log.count("3 progress properties for each run") == 1  # kc-rrtstar only
    db = sqlite3.connect(out / "results.db")
    rows = db.execute(
        "SELECT r.seed, g.time, g.best_cost, g.iterations FROM progress g "
        "JOIN runs r ON g.runid = r.id JOIN plannerConfigs p ON r.plannerid = p.id "
        "WHERE p.name = 'kc-rrtstar' ORDER BY r.seed, g.time"
    ).fetchall()
    expected = [
        (r["seed"], t, c, i)
        for r in sorted(star, key=lambda r: r["seed"])
        for t, c, i in zip(*r["progress"].values(), strict=True)
    ]
    assert len(rows) == len(expected)
    for got, want in zip(rows, expected, strict=True):
        assert got[0] == want[0] and got[3] == want[3]
        assert math.isclose(got[1], want[1], rel_tol=1e-8)
        if math.isinf(want[2]):  # inf before the first solution is NULL in the database
            assert got[2] is None
        else:
            assert math.isclose(got[2], want[2], rel_tol=1e-8)
    first = db.execute(
        "SELECT time_to_first_solution FROM runs r JOIN plannerConfigs p "
        "ON r.plannerid = p.id WHERE p.name = 'kc-rrtstar'"
    ).fetchall()
    want = sorted(r["first_solution_time"] for r in star)
    assert np.allclose(sorted(f for (f,) in first), want, rtol=1e-8)
    summary = (out / "summary.md").read_text()
    assert "| open_field | kc-rrtstar |" in summary.split("Best cost over time")[1]
    assert (out / "plots" / "cost_over_time.png").read_bytes().startswith(b"\x89PNG")
    # --progress-interval 0 switches sampling off
    off = tmp_path / "off"
    assert (
        main(
            [
                *argv[:3],
                "kc-rrtstar",
                "--runs",
                "1",
                "--time",
                "0.5",
                "--progress-interval",
                "0",
                "-o",
                str(off),
            ]
        )
        == 0
    )
    (record,) = read_records(off / "runs.jsonl")
    assert record["progress"] == {} and record["first_solution_time"] is None
    assert not (off / "plots" / "cost_over_time.png").exists()
