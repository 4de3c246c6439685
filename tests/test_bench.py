"""kcplan bench: campaigns, failure isolation, OMPL logs and database, summaries, executors."""

import csv
import json
import math
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from kcplan.bench.campaign import (
    WORKER_COMMAND,
    DaskExecutor,
    LocalExecutor,
    _InterruptGate,
    campaign_specs,
    read_records,
    run_campaign,
    run_isolated,
)
from kcplan.bench.summary import (
    SUMMARY_COLUMNS,
    ca_twin_of,
    summarize,
    summary_markdown,
    twin_of,
)
from kcplan.cli import main

ROOT = Path(__file__).resolve().parents[1]
CORRIDOR = str(ROOT / "scenarios/2d/narrow_corridor.yaml")
OPEN = str(ROOT / "scenarios/2d/open_field.yaml")
PNG = b"\x89PNG\r\n\x1a\n"
VOLATILE = {"time", "simplify_time", "wall", "memory_mb"}  # machine-dependent fields


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    """2 scenarios x 2 planners x 3 runs through the command, in 2 worker processes."""
    out = tmp_path_factory.mktemp("bench") / "results"
    code = main(
        [
            "bench",
            CORRIDOR,
            OPEN,
            "--planners",
            "kc-rrtconnect,rrtconnect",
            "--runs",
            "3",
            "--time",
            "5",
            "--seed",
            "11",
            "--jobs",
            "2",
            "-o",
            str(out),
        ]
    )
    return code, out


def test_campaign_writes_every_output(campaign):
    code, out = campaign
    assert code == 0
    records = read_records(out / "runs.jsonl")
    assert len(records) == 12
    assert all(r["status"] == "ok" for r in records)
    # distinct recorded seeds per run index, shared by the twins
    for r in records:
        assert r["seed"] == 11 + r["run"]
    meta = json.loads((out / "campaign.json").read_text())
    assert len(meta["specs"]) == 12 and meta["command"].startswith("kcplan bench")
    for name in ("narrow_corridor", "open_field"):
        assert (out / "logs" / f"{name}.log").read_text().startswith("OMPL version 2.")
        assert (out / "plots" / f"{name}.png").read_bytes().startswith(PNG)
    assert (out / "plots" / "success_vs_budget.png").read_bytes().startswith(PNG)


def test_database_is_what_ompl_statistics_builds(campaign):
    _, out = campaign
    db = sqlite3.connect(out / "results.db")
    tables = {row[0] for row in db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
    assert {"experiments", "plannerConfigs", "enums", "runs", "progress"} <= tables
    assert db.execute("SELECT COUNT(*) FROM experiments").fetchone()[0] == 2
    assert db.execute("SELECT COUNT(*) FROM plannerConfigs").fetchone()[0] == 2
    assert db.execute("SELECT COUNT(*) FROM runs").fetchone()[0] == 12
    # kcplan's measurements are run columns, equal to the records
    rows = db.execute(
        "SELECT e.name, p.name, r.seed, r.fcl_queries, r.path_collides, r.kc_guards "
        "FROM runs r JOIN experiments e ON r.experimentid = e.id "
        "JOIN plannerConfigs p ON r.plannerid = p.id"
    ).fetchall()
    records = {
        (r["scenario_name"], r["planner"], r["seed"]): r for r in read_records(out / "runs.jsonl")
    }
    assert len(rows) == 12
    for scenario, planner, seed, queries, collides, guards in rows:
        r = records[(scenario, planner, seed)]
        assert queries == r["counters"]["fcl_queries"] > 0
        assert collides == (int(r["collides"]) if r["solved"] else None)
        assert (guards is None) == (planner == "rrtconnect")
    # the log is accepted again by OMPL's own script, run by hand
    again = out / "again.db"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "ompl.ompl_benchmark_statistics",
            *map(str, (out / "logs").iterdir()),
            "-d",
            str(again),
        ],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    assert sqlite3.connect(again).execute("SELECT COUNT(*) FROM runs").fetchone()[0] == 12


def test_summary_csv_has_the_exact_header_and_true_values(campaign):
    _, out = campaign
    with open(out / "summary.csv") as fh:
        rows = list(csv.reader(fh))
    assert tuple(rows[0][: len(SUMMARY_COLUMNS)]) == SUMMARY_COLUMNS
    assert len(rows) == 5
    table = [dict(zip(rows[0], row, strict=True)) for row in rows[1:]]
    records = read_records(out / "runs.jsonl")
    for row in table:
        mine = [
            r
            for r in records
            if (r["scenario_name"], r["planner"]) == (row["scenario"], row["planner"])
        ]
        assert int(row["runs"]) == 3
        assert int(row["solved"]) == sum(r["solved"] for r in mine)
        assert float(row["median_fcl_queries"]) == np.median(
            [r["counters"]["fcl_queries"] for r in mine]
        )
        if row["planner"].startswith("kc-"):
            assert int(row["colliding_paths"]) == 0
            assert row["twin"] == row["planner"][3:]
    md = (out / "summary.md").read_text()
    assert "| narrow_corridor | kc-rrtconnect |" in md and "twin/kc" in md


def test_existing_folder_is_refused_without_force(campaign, tmp_path, capsys):
    _, out = campaign
    before = (out / "runs.jsonl").read_text()
    args = ["bench", OPEN, "--planners", "rrtconnect", "--runs", "1", "--time", "2", "-o"]
    assert main([*args, str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert str(out) in err and "--force" in err and "runs.jsonl" in err
    assert (out / "runs.jsonl").read_text() == before
    # a folder of the user's own files is never cleared, even with --force
    other = tmp_path / "mine"
    other.mkdir()
    (other / "notes.txt").write_text("keep")
    assert main([*args, str(other), "--force"]) == 0
    assert (other / "notes.txt").read_text() == "keep"
    assert len(read_records(other / "runs.jsonl")) == 1
    # --force replaces kcplan's results only
    assert main([*args, str(other), "--force"]) == 0
    assert len(read_records(other / "runs.jsonl")) == 1


@pytest.mark.parametrize(
    "argv, field",
    [
        (["--planners", "kc-rrtconnect,rrtfast"], "--planners"),
        (["--runs", "0"], "--runs"),
        (["--time", "-1"], "--time"),
        (["--jobs", "two"], "--jobs"),
    ],
)
def test_bad_arguments_exit_2_with_one_line(argv, field, tmp_path, capsys):
    assert main(["bench", OPEN, *argv, "-o", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and field in err
    assert not (tmp_path / "x").exists()


def test_bad_scenario_exits_2_naming_the_file(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: x\n")
    assert main(["bench", str(bad), "-o", str(tmp_path / "x")]) == 2
    assert str(bad) in capsys.readouterr().err


# a worker that fails in the way the spec's run index asks, otherwise the real one
FAULTY_WORKER = (
    sys.executable,
    "-c",
    "import json, os, signal, sys, time\n"
    "spec = json.loads(sys.stdin.read())\n"
    "if spec['run'] == 1: os.kill(os.getpid(), signal.SIGSEGV)\n"
    "if spec['run'] == 2: time.sleep(600)\n"
    "if spec['run'] == 3: sys.exit(3)\n"
    "from kcplan.bench.worker import execute\n"
    "print(json.dumps(execute(spec)))\n",
)


def test_crashed_hung_and_failing_workers_are_recorded_not_fatal(tmp_path):
    specs = campaign_specs([(OPEN, "open_field")], ["rrtconnect"], 4, 1, 2.0)
    t0 = time.perf_counter()
    records, complete = run_campaign(specs, tmp_path, LocalExecutor(2, 8.0, FAULTY_WORKER))
    assert complete and time.perf_counter() - t0 < 120
    by_run = {r["run"]: r for r in records}
    assert by_run[0]["status"] == "ok" and by_run[0]["solved"]
    assert by_run[1]["status"] == "crashed" and "SIGSEGV" in by_run[1]["reason"]
    assert by_run[2]["status"] == "hung" and "killed" in by_run[2]["reason"]
    assert by_run[3]["status"] == "crashed" and "code 3" in by_run[3]["reason"]
    assert not any(r["solved"] for r in records if r["run"] > 0)
    # the reports treat failed runs as unsolved, with their reasons in the log
    from kcplan.bench.report import write_reports

    meta = {
        "started": "2026-01-01T00:00:00",
        "command": "test",
        "runs": 4,
        "seed": 1,
        "time_limit": 2.0,
        "kcplan_version": "0",
        "ompl_version": "2.0.1",
        "scenarios": [
            {
                "name": "open_field",
                "file": OPEN,
                "dimension": 2,
                "semi_axes": [1, 0.5],
                "description": "d",
            }
        ],
        "planners": [{"name": "rrtconnect", "settings": {}}],
    }
    write_reports(tmp_path, records, meta)
    row = summarize(records)[0]
    assert row["failed_runs"] == 3 and row["solved"] == 1
    assert row["median_time"] == 2.0  # three of four runs charged at the limit
    db = sqlite3.connect(tmp_path / "results.db")
    status = dict(db.execute("SELECT seed, status FROM runs").fetchall())
    assert status == {1: 6, 2: 7, 3: 7, 4: 7}  # Exact solution, then Crash
    assert "SIGSEGV" in db.execute("SELECT failure FROM runs WHERE seed = 2").fetchone()[0]


def test_worker_error_is_a_failed_run(tmp_path):
    from kcplan.bench.ompl_log import _progress_lines

    spec = campaign_specs([(OPEN, "open_field")], ["rrtconnect"], 1, 1, 1.0, progress=0.1)[0]
    broken = spec.__class__(**{**spec.__dict__, "scenario": str(tmp_path / "missing.yaml")})
    record = run_isolated(broken, 60.0, WORKER_COMMAND)
    assert record["status"] == "error" and "missing.yaml" in record["reason"]
    assert record["solved"] is False
    # no progress samples, not the spec's interval (which crashed the reports once)
    assert record["progress"] == {} and _progress_lines([record]) == []


def test_an_interrupt_waits_until_the_record_is_kept():
    # CI once saw runs.jsonl hold 2 records and summary.csv 1: the Ctrl-C fell between them
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    kept = []
    try:
        with pytest.raises(KeyboardInterrupt), _InterruptGate() as gate:
            with gate.held():
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.05)  # the handler runs here, and must not raise
                kept.append("line")
                kept.append("list entry")
        assert kept == ["line", "list entry"]
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
        with pytest.raises(KeyboardInterrupt), _InterruptGate():
            os.kill(os.getpid(), signal.SIGINT)  # outside a held section: at once
            time.sleep(5)
            kept.append("never")
        assert "never" not in kept
    finally:
        signal.signal(signal.SIGINT, previous)


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_ctrl_c_leaves_complete_results_for_finished_runs(signum, tmp_path):
    out = tmp_path / "r"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "kcplan.cli",
            "bench",
            OPEN,
            "--planners",
            "rrtconnect",
            "--runs",
            "40",
            "--time",
            "2",
            "-o",
            str(out),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # a shell starts background jobs with SIGINT ignored, and Python keeps that
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    deadline = time.time() + 120
    while time.time() < deadline:
        if (out / "runs.jsonl").exists() and len(read_records(out / "runs.jsonl")) >= 2:
            break
        time.sleep(0.2)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "interrupted" in err and "Traceback" not in err
    records = read_records(out / "runs.jsonl")
    assert 2 <= len(records) < 40
    with open(out / "summary.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert int(rows[0]["runs"]) == len(records)
    db = sqlite3.connect(out / "results.db")
    assert db.execute("SELECT COUNT(*) FROM runs").fetchone()[0] == len(records)
    assert not [p for p in out.rglob(".*") if p.is_file()]  # no temporary files left


def _content(records):
    return sorted(
        ({k: v for k, v in r.items() if k not in VOLATILE} for r in records),
        key=lambda r: (r["scenario_name"], r["planner"], r["run"]),
    )


@pytest.mark.study  # a Dask cluster's start-up: .ci/run runs it (pytest -m study)
def test_dask_executor_gives_the_same_results_as_local(tmp_path):
    distributed = pytest.importorskip("dask.distributed", reason="dask[distributed] not installed")
    specs = campaign_specs(
        [(CORRIDOR, "narrow_corridor")], ["kc-rrtconnect", "rrtconnect"], 2, 5, 10.0
    )
    local, _ = run_campaign(specs, tmp_path, LocalExecutor(2))
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        (tmp_path / "dask").mkdir()
        remote, complete = run_campaign(specs, tmp_path / "dask", DaskExecutor(client))
    assert complete
    assert all(r["solved"] for r in local)
    assert _content(local) == _content(remote)


def test_summary_statistics_by_hand():
    def rec(planner, run, solved, t, q, collides=False, status="ok", covered=None):
        return {
            "scenario_name": "s",
            "planner": planner,
            "run": run,
            "seed": run + 1,
            "time_limit": 10.0,
            "status": status,
            "solved": solved,
            "time": t,
            "simplify_time": 0.1,
            "length": 5.0 + run,
            "collides": collides,
            "counters": {"fcl_queries": q, **(covered or {})},
        }

    records = [
        rec("rrtconnect", 0, True, 1.0, 1000, collides=True),
        rec("rrtconnect", 1, True, 3.0, 3000),
        rec("rrtconnect", 2, False, 10.0, 9000),
        rec("kc-rrtconnect", 0, True, 0.5, 100, covered={"kc_covered_region": 3.0}),
        rec("kc-rrtconnect", 1, True, 1.5, 300),
        rec(
            "kc-rrtconnect",
            2,
            True,
            2.5,
            500,
            covered={"kc_covered_region": 1.0, "kc_covered_polytope": 1.0},
        ),
        rec("ca-rrtconnect", 0, True, 3.0, 600),
        rec("ca-rrtconnect", 1, True, 3.0, 600),
        rec("ca-rrtconnect", 2, True, 3.0, 600),
    ]
    rows = {r["planner"]: r for r in summarize(records)}
    stock, kc = rows["rrtconnect"], rows["kc-rrtconnect"]
    assert stock["solved"] == 2 and math.isclose(stock["success_rate"], 2 / 3)
    assert stock["median_time"] == 3.0 and stock["median_fcl_queries"] == 3000
    assert math.isclose(stock["p90_time"], 8.6)  # 3 + 0.8 * (10 - 3)
    assert stock["median_length"] == 5.5 and stock["colliding_paths"] == 1
    assert kc["time_ratio"] == 2.0 and kc["query_ratio"] == 10.0
    assert math.isnan(stock["time_ratio"])
    # the clearance-ball ablation is kc's second twin; its own twin is the stock planner
    assert kc["ca_twin"] == "ca-rrtconnect" and rows["ca-rrtconnect"]["twin"] == "rrtconnect"
    assert kc["ca_time_ratio"] == 2.0 and kc["ca_query_ratio"] == 2.0
    assert math.isnan(rows["ca-rrtconnect"]["ca_time_ratio"])
    # certificate shares: medians over the runs that covered something (1.0 and 0.5)
    assert kc["share_region"] == 0.75 and kc["share_polytope"] == 0.25
    assert twin_of("kc-prm") == "prm" and twin_of("kc-rrtconnect-discrete") == "rrtconnect"
    assert twin_of("kc-prm-paper") == "prm" and ca_twin_of("kc-prm-paper") == "ca-prm"
    assert ca_twin_of("ca-prm") is None and ca_twin_of("prm") is None
    assert twin_of("prm") is None
    # with only the fine-resolution stock planner in the campaign, it is the twin
    fine = [
        dict(r, planner="rrtconnect-fine") if r["planner"] == "rrtconnect" else r for r in records
    ]
    rows = {r["planner"]: r for r in summarize(fine)}
    assert rows["kc-rrtconnect"]["twin"] == "rrtconnect-fine"
    assert rows["kc-rrtconnect"]["time_ratio"] == 2.0


def test_polytope_cache_round_trip_and_repair(tmp_path, monkeypatch):
    from kcplan.certification import ladder as certificate
    from kcplan.kc.convex import ConvexLowerBound

    monkeypatch.setenv("KCPLAN_CACHE_DIR", str(tmp_path))
    certificate._halfspaces.cache_clear()
    A, c = certificate._halfspaces((1.0, 0.4), 0.05)
    files = list(tmp_path.glob("polytope-*.npz"))
    assert len(files) == 1
    built = ConvexLowerBound([1.0, 0.4], 0.05).halfspaces
    certificate._halfspaces.cache_clear()
    A2, c2 = certificate._halfspaces((1.0, 0.4), 0.05)  # from disk
    assert np.array_equal(A2, built[0]) and np.array_equal(c2, built[1])
    files[0].write_bytes(b"garbage")
    certificate._halfspaces.cache_clear()
    A3, _ = certificate._halfspaces((1.0, 0.4), 0.05)  # rebuilt, file repaired
    assert np.array_equal(A3, built[0])
    with np.load(files[0]) as data:
        assert np.array_equal(data["A"], built[0])
    certificate._halfspaces.cache_clear()
    monkeypatch.setenv("KCPLAN_CACHE_DIR", "off")
    assert certificate.polytope_cache_dir() is None


def test_progress_is_live_on_a_terminal_and_logged_otherwise():
    import io

    from kcplan.bench.campaign import Progress

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    record = {
        "scenario_name": "s",
        "planner": "prm",
        "run": 0,
        "seed": 1,
        "status": "ok",
        "solved": True,
        "time": 0.5,
        "collides": False,
        "counters": {"fcl_queries": 7},
    }
    tty = Terminal()
    progress = Progress(2, tty)
    progress.update(record)
    progress.close()
    text = tty.getvalue()
    assert text.startswith("\r[1/2] 0:00 elapsed, ~0:00 left | s prm #0 (seed 1): solved")
    assert text.endswith("\n") and text.count("\n") == 1  # one live line, ended on close
    log = io.StringIO()
    progress = Progress(2, log)
    progress.update(dict(record, status="hung", reason="no result after 80 s; worker killed"))
    progress.update(dict(record, run=1, solved=False, time=2.0))
    assert log.getvalue().splitlines() == [
        "[1/2] s prm #0 (seed 1): hung: no result after 80 s; worker killed",
        "[2/2] s prm #1 (seed 1): unsolved in 2.00 s, 7 FCL queries",
    ]


def test_distribution_plot_of_a_scenario_nobody_solved(tmp_path):
    """Found by the CLI fuzz test: a bench whose runs all fail drew a log axis of nothing."""
    from kcplan.bench.plots import plot_distributions

    records = [
        {
            "scenario_name": "s",
            "planner": "rrtconnect",
            "solved": False,
            "time": 0.01,
            "counters": {"fcl_queries": 3},
        }
    ]
    out = tmp_path / "s.png"
    plot_distributions(records, "s", out)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_mesh_robots_paths_are_checked_on_its_part_too(tmp_path):
    """hand_through_slot's robot is the cover of the hand's mesh: the worker verifies each
    path on the cover and on the mesh, and the summary says so."""
    hand = str(ROOT / "scenarios/3d/hand_through_slot.yaml")
    spec = campaign_specs([(hand, "hand_through_slot")], ["kc-rrtconnect"], 1, 1, 10.0)[0]
    record = run_isolated(spec, 120.0, WORKER_COMMAND)
    assert record["status"] == "ok" and record["solved"], record.get("reason")
    assert record["collides"] is False and record["part_collides"] is False
    (row,) = summarize([{**spec.__dict__, **record, "scenario_name": "hand_through_slot"}])
    assert (row["checked_parts"], row["colliding_parts"]) == (1, 0)
    assert "| hand_through_slot | kc-rrtconnect | 1 | 0 |" in summary_markdown([row])
    plain = run_isolated(campaign_specs([(OPEN, "open_field")], ["rrtconnect"], 1, 1, 2.0)[0],
                         60.0, WORKER_COMMAND)  # fmt: skip
    assert plain["part_collides"] is None


def test_bench_outputs_follow_the_umask(tmp_path):
    """Logs, results.db, summaries and plots are readable by the group and others under
    umask 022, as any file written with open() would be (mkstemp alone gave 0600)."""
    import os
    import stat

    out = tmp_path / "b"
    old = os.umask(0o022)
    try:
        argv = ["bench", OPEN, "--planners", "rrtconnect", "--runs", "1", "--time", "1"]
        assert main([*argv, "-o", str(out)]) == 0
    finally:
        os.umask(old)
    files = [p for p in out.rglob("*") if p.is_file()]
    assert {p.name for p in files} >= {"results.db", "summary.csv", "summary.md"}
    modes = {p.relative_to(out).as_posix(): stat.S_IMODE(p.stat().st_mode) for p in files}
    assert set(modes.values()) == {0o644}, modes
