"""A benchmark campaign: a list of independent runs, executed by a pluggable executor.

The campaign is data (:class:`RunSpec` rows), so any engine that can call
:func:`run_isolated` on a row can execute it: :class:`LocalExecutor` (a pool of worker
processes on this machine, the default) and :class:`DaskExecutor` (a ``dask.distributed``
cluster) do. Every run is a fresh ``python -m kcplan.bench.worker`` process, whichever
executor starts it, so the same seeds give the same paths and counters everywhere, and
a crash or hang ends one run, never the campaign.

Records come back as they finish; :func:`run_campaign` appends each to
``DIR/runs.jsonl`` at once (so an interrupted campaign keeps every finished run) and then
writes the reports (:mod:`kcplan.bench.report`).
"""

from __future__ import annotations

import json
import os
import platform
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from contextlib import contextmanager
from dataclasses import asdict, dataclass
from datetime import datetime
from pathlib import Path
from typing import Protocol, TextIO

__all__ = [
    "RunSpec",
    "campaign_specs",
    "campaign_metadata",
    "run_isolated",
    "Executor",
    "LocalExecutor",
    "DaskExecutor",
    "Progress",
    "describe_run",
    "read_records",
    "run_campaign",
    "ordered",
    "WORKER_COMMAND",
]

WORKER_COMMAND = (sys.executable, "-m", "kcplan.bench.worker")
"""The command that runs one :class:`RunSpec` (JSON on stdin, record on stdout)."""

STARTUP_ALLOWANCE = 60.0
"""Seconds a worker may spend beyond its planning budgets (import, building uncached
guard polytopes, verification) before it is considered hung."""


@dataclass(frozen=True)
class RunSpec:
    """One run: a planner on a scenario with a seed and a time budget.

    ``scenario`` is the scenario file (an absolute path, so that any worker can read it),
    ``run`` the index among the runs of this scenario and planner, ``time_limit`` the
    seconds given to ``solve()`` (simplification gets the same again), ``progress`` the
    seconds between best-cost samples of anytime planners (None: none recorded).
    """

    scenario: str
    scenario_name: str
    planner: str
    run: int
    seed: int
    time_limit: float
    simplify: bool = True
    progress: float | None = None

    @property
    def key(self) -> tuple[str, str, int]:
        return (self.scenario_name, self.planner, self.run)


def campaign_specs(
    scenarios: Sequence[tuple[str, str]],
    planners: Sequence[str],
    runs: int,
    seed: int,
    time_limit: float,
    simplify: bool = True,
    progress: float | None = None,
) -> list[RunSpec]:
    """All runs of a campaign, twins next to each other.

    ``scenarios`` are ``(file, name)`` pairs. Run ``i`` of every planner on a scenario
    uses seed ``seed + i``, so kc planners and their stock twins see the same seeds, and
    the runs are ordered scenario, run, planner, so twins run at the same moment.
    """
    return [
        RunSpec(
            str(Path(file).resolve()), name, planner, i, seed + i, time_limit, simplify, progress
        )
        for file, name in scenarios
        for i in range(runs)
        for planner in planners
    ]


def campaign_metadata(
    specs: Sequence[RunSpec],
    scenarios: Sequence,
    planners: Sequence[str],
    runs: int,
    seed: int,
    time_limit: float,
    command: str,
) -> dict:
    """The content of ``campaign.json``: what was run, with which software, where.

    ``scenarios`` are :class:`kcplan.world.Scenario` objects in campaign order."""
    from importlib.metadata import version

    from kcplan.planning.names import PLANNER_NAMES
    from kcplan.planning.problem import PLANNERS

    unknown = sorted(set(planners) - set(PLANNER_NAMES))
    if unknown:
        raise ValueError(f"planners: expected names from {PLANNER_NAMES}, got {unknown}")
    return {
        "started": datetime.now().isoformat(timespec="seconds"),
        "command": command,
        "runs": runs,
        "seed": seed,
        "time_limit": time_limit,
        "kcplan_version": version("kcplan"),
        "ompl_version": version("ompl"),
        "python_fcl_version": version("python-fcl"),
        "python": platform.python_version(),
        "machine": f"{platform.node()} ({platform.machine()}, {os.cpu_count()} CPUs)",
        "scenarios": [
            {
                "name": s.name,
                "file": str(Path(s.source).resolve()),
                "dimension": s.dimension,
                "robot": s.robot.describe(),
                "description": s.description,
            }
            for s in scenarios
        ],
        "planners": [
            {
                "name": name,
                "settings": {
                    "kc validator": PLANNERS[name].kc,
                    "kc fallback": PLANNERS[name].fallback if PLANNERS[name].kc else "",
                    "description": PLANNERS[name].description,
                },
            }
            for name in planners
        ],
        "specs": [asdict(s) for s in specs],
    }


def _signal_name(code: int) -> str:
    try:
        return signal.Signals(code).name
    except ValueError:
        return f"signal {code}"


def run_isolated(
    spec: RunSpec,
    timeout: float | None = None,
    command: Sequence[str] = WORKER_COMMAND,
    _started: Callable[[subprocess.Popen], None] | None = None,
) -> dict:
    """Run one spec in a fresh worker process and return its record.

    Never raises for a failed run: a worker that dies (``status="crashed"``, with the
    signal or exit code and the end of its stderr), exceeds ``timeout`` seconds
    (``"hung"``, killed) or reports an exception (``"error"``) gives a record with
    ``solved=False`` and the ``reason``. The record always carries the spec's fields.
    """
    if timeout is None:
        timeout = 2.0 * spec.time_limit + STARTUP_ALLOWANCE
    base = asdict(spec)
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        list(command),
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # Ctrl-C reaches the parent only; it stops the workers
    )
    if _started is not None:
        _started(proc)
    try:
        out, err = proc.communicate(json.dumps(base), timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        return _failed(base, "hung", f"no result after {timeout:.0f} s; worker killed", t0)
    lines = out.strip().splitlines()
    try:
        record = json.loads(lines[-1]) if lines else None
    except json.JSONDecodeError:
        record = None
    if proc.returncode != 0 or not isinstance(record, dict):
        if proc.returncode < 0:
            why = f"worker killed by {_signal_name(-proc.returncode)}"
        else:
            why = f"worker exited with code {proc.returncode} and no result"
        tail = " | ".join(err.strip().splitlines()[-3:])
        return _failed(base, "crashed", why + (f" ({tail})" if tail else ""), t0)
    if record.get("status") != "ok":
        return _failed(base, "error", str(record.get("reason", "unknown error")), t0)
    return {**base, **record}


def _failed(base: dict, status: str, reason: str, t0: float) -> dict:
    return {
        **base,
        "status": status,
        "reason": reason,
        "solved": False,
        "time": None,
        "counters": {},
        "progress": {},  # no samples: the spec's sampling interval is not a run's progress
        "wall": time.perf_counter() - t0,
    }


class Executor(Protocol):
    """Runs specs and yields their records in completion order."""

    def map(self, specs: Sequence[RunSpec]) -> Iterator[dict]: ...

    def shutdown(self) -> None: ...


class LocalExecutor:
    """``jobs`` worker processes at a time on this machine (threads wait on them)."""

    def __init__(
        self,
        jobs: int = 1,
        timeout: float | None = None,
        command: Sequence[str] = WORKER_COMMAND,
    ):
        if jobs < 1:
            raise ValueError(f"jobs: expected an integer >= 1, got {jobs}")
        self.jobs, self.timeout, self.command = jobs, timeout, tuple(command)
        self._procs: set[subprocess.Popen] = set()
        self._lock = threading.Lock()
        self._stopping = False
        self._pool: ThreadPoolExecutor | None = None

    def _run(self, spec: RunSpec) -> dict:
        def started(proc: subprocess.Popen) -> None:
            with self._lock:
                self._procs.add(proc)
                if self._stopping:  # started while shutdown() was killing the others
                    proc.kill()

        return run_isolated(spec, self.timeout, self.command, started)

    def map(self, specs: Sequence[RunSpec]) -> Iterator[dict]:
        self._pool = ThreadPoolExecutor(self.jobs)
        pending = {self._pool.submit(self._run, s) for s in specs}
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                yield future.result()

    def shutdown(self) -> None:
        """Cancel queued runs and kill running workers (used on Ctrl-C)."""
        if self._pool is not None:
            self._pool.shutdown(wait=False, cancel_futures=True)
        with self._lock:
            self._stopping = True
            for proc in self._procs:
                if proc.poll() is None:
                    proc.kill()


class DaskExecutor:
    """Runs specs on a ``dask.distributed`` cluster (``pip install "kcplan[dask]"``).

    ``address`` is the scheduler's address (``tcp://host:8786``) or an existing
    ``Client``. Each task starts the same worker process as :class:`LocalExecutor`, so
    the workers need kcplan installed and the scenario files at the same paths.
    """

    def __init__(self, address, timeout: float | None = None):
        try:
            from dask.distributed import Client
        except ImportError as exc:  # pragma: no cover - depends on the extra
            raise RuntimeError(
                'the Dask executor needs dask.distributed: pip install "kcplan[dask]"'
            ) from exc
        self._own = not isinstance(address, Client)
        self.client = Client(address) if self._own else address
        self.timeout = timeout
        self._futures: list = []

    def map(self, specs: Sequence[RunSpec]) -> Iterator[dict]:
        from dask.distributed import as_completed

        self._futures = self.client.map(run_isolated, list(specs), timeout=self.timeout, pure=False)
        for future in as_completed(self._futures):
            yield future.result()

    def shutdown(self) -> None:
        if self._futures:
            self.client.cancel(self._futures)
        if self._own:
            self.client.close()


class Progress:
    """Campaign progress: a live line on a terminal, one log line per run otherwise."""

    def __init__(self, total: int, stream: TextIO | None = None):
        self.total, self.done = total, 0
        self.stream = stream or sys.stderr
        self.live = self.stream.isatty()
        self.t0 = time.perf_counter()

    def update(self, record: dict) -> None:
        self.done += 1
        elapsed = time.perf_counter() - self.t0
        left = elapsed / self.done * (self.total - self.done)
        what = describe_run(record)
        if self.live:
            line = (
                f"\r[{self.done}/{self.total}] {_clock(elapsed)} elapsed, ~{_clock(left)} left"
                f" | {what}"
            )
            width = shutil.get_terminal_size((120, 24)).columns - 1
            self.stream.write(line[: width + 1].ljust(width + 1))
            if self.done == self.total:
                self.stream.write("\n")
        else:
            self.stream.write(f"[{self.done}/{self.total}] {what}\n")
        self.stream.flush()

    def close(self) -> None:
        if self.live and self.done != self.total:
            self.stream.write("\n")
            self.stream.flush()


def _clock(seconds: float) -> str:
    m, s = divmod(int(seconds), 60)
    h, m = divmod(m, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


def describe_run(record: dict) -> str:
    """One line about a finished run, e.g. ``maze kc-prm #3 (seed 4): solved in 0.21 s``."""
    head = f"{record['scenario_name']} {record['planner']} #{record['run']} (seed {record['seed']})"
    if record["status"] != "ok":
        return f"{head}: {record['status']}: {record['reason']}"
    queries = record["counters"].get("fcl_queries", 0)
    if not record["solved"]:
        return f"{head}: unsolved in {record['time']:.2f} s, {queries} FCL queries"
    path = "PATH COLLIDES" if record["collides"] else "path clean"
    if record.get("part_collides") is not None:  # a mesh robot: its part checked too
        path += ", PART COLLIDES" if record["part_collides"] else ", part clean"
    found = f"solved in {record['time']:.3f} s"
    if record.get("first_solution_time") is not None:
        found = f"first solution at {record['first_solution_time']:.3f} s"
    return f"{head}: {found}, {queries} FCL queries, {path}"


def read_records(path: str | os.PathLike) -> list[dict]:
    """Records of ``runs.jsonl``; a last line cut short by a kill is ignored."""
    records = []
    with open(path) as fh:
        for line in fh:
            try:
                records.append(json.loads(line))
            except json.JSONDecodeError:
                continue
    return records


def run_campaign(
    specs: Sequence[RunSpec],
    out_dir: str | os.PathLike,
    executor: Executor,
    progress: Progress | None = None,
    on_record: Callable[[dict], None] | None = None,
) -> tuple[list[dict], bool]:
    """Execute ``specs``, appending each record to ``out_dir/runs.jsonl`` as it arrives.

    Returns ``(records, complete)``; ``complete`` is False after a ``KeyboardInterrupt``,
    in which case the workers are stopped and the records of the finished runs returned.
    """
    out = Path(out_dir)
    records: list[dict] = []
    complete = True
    with open(out / "runs.jsonl", "a") as log, _InterruptGate() as gate:
        try:
            for record in executor.map(specs):
                with gate.held():  # the line and the list agree, even under Ctrl-C
                    log.write(json.dumps(record) + "\n")
                    log.flush()
                    records.append(record)
                if progress is not None:
                    progress.update(record)
                if on_record is not None:
                    on_record(record)
        except KeyboardInterrupt:
            complete = False
            executor.shutdown()
        finally:
            if progress is not None:
                progress.close()
    return records, complete


class _InterruptGate:
    """Defers ``KeyboardInterrupt`` out of the sections it holds.

    Python raises ``KeyboardInterrupt`` between any two bytecodes, so a Ctrl-C between a
    record's line in ``runs.jsonl`` and its entry in the returned list would report one
    run fewer than the file holds. While the gate is entered, every signal whose handler
    is :func:`signal.default_int_handler` (SIGINT, and SIGTERM when ``kcplan bench`` maps
    it so) is caught here; inside :meth:`held` it is remembered and raised when the
    section ends, elsewhere at once. Off the main thread, where handlers cannot be set,
    the gate does nothing.
    """

    def __init__(self) -> None:
        self._holding = False
        self._pending = False
        self._previous: dict[int, object] = {}

    def __enter__(self) -> _InterruptGate:
        if threading.current_thread() is threading.main_thread():
            for signum in (signal.SIGINT, signal.SIGTERM):
                if signal.getsignal(signum) is signal.default_int_handler:
                    self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)

    def _handle(self, signum: int, frame: object) -> None:
        if self._holding:
            self._pending = True
        else:
            raise KeyboardInterrupt

    @contextmanager
    def held(self) -> Iterator[None]:
        """A section no interrupt enters; one that arrives meanwhile is raised after it."""
        self._holding = True
        try:
            yield
        finally:
            self._holding = False
            if self._pending:
                self._pending = False
                raise KeyboardInterrupt


def ordered(records: Iterable[dict], specs: Sequence[RunSpec]) -> list[dict]:
    """Records in campaign order (completion order depends on the executor)."""
    rank = {s.key: i for i, s in enumerate(specs)}
    return sorted(
        records,
        key=lambda r: rank.get((r["scenario_name"], r["planner"], r["run"]), len(rank)),
    )
