"""Path cost over time of anytime planners: OMPL's planner progress properties.

OMPL's ``tools::Benchmark`` samples a planner's progress properties ("best cost REAL",
"iterations INTEGER", ...) from a second thread while ``solve()`` runs; Planner Arena
draws them as progress plots. The OMPL 2 wheel cannot hand those properties to Python
(``Planner.getPlannerProgressProperties()`` fails to convert its ``std::function``
values), so :class:`ProgressRecorder` reads the same quantities through the bound
accessors (``bestCost()``, ``numIterations()``, ``numBatches()``) and stores them under
OMPL's property names, so the log's progress section and the database's ``progress``
table look as OMPL's own benchmark would make them.

The samples are taken *inside the planning thread*, by the Python termination condition
the planner polls once per iteration: no second thread reads the planner while it
changes. That needs a planner that polls its termination condition from the thread that
called ``solve()``. PRM and PRM* do not (the wheel's PRM checks for a solution in a
thread of its own, which then waits for the GIL the calling thread holds: a deadlock),
and they bind no ``bestCost()`` either, so they report no progress;
:func:`reports_progress` says which planners do.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from ompl import base as ob
from ompl import geometric as og

__all__ = ["PROPERTIES", "ProgressRecorder", "reports_progress"]

PROPERTIES: tuple[tuple[str, str, Callable[[object], float]], ...] = (
    ("best cost REAL", "bestCost", lambda p: float(p.bestCost().value())),
    ("iterations INTEGER", "numIterations", lambda p: int(p.numIterations())),
    ("batches INTEGER", "numBatches", lambda p: int(p.numBatches())),
)
"""``(OMPL progress property name, bound accessor, reader)``; a planner reports those
whose accessor it binds. The sample time is the extra property ``"time REAL"``."""

_THREADED = (og.PRM, og.PRMstar)  # see the module docstring


def reports_progress(planner: object) -> bool:
    """Whether :class:`ProgressRecorder` can follow ``planner`` (an OMPL planner object):
    it binds ``bestCost()`` and polls its termination condition in the calling thread."""
    return hasattr(planner, "bestCost") and not isinstance(planner, _THREADED)


class ProgressRecorder:
    """Samples a planner's best cost (and iteration counts) while it solves.

    Parameters
    ----------
    planner : ompl.base.Planner
        A planner for which :func:`reports_progress` holds.
    interval : float
        Seconds between samples (OMPL's ``timeBetweenUpdates``; its default is 0.05).

    Notes
    -----
    Times are seconds since :meth:`termination_condition` was made (just before
    ``solve()``). A cost is the planner's best cost in the optimization objective's unit
    (path length by default), ``inf`` before the first solution. Sampling costs one
    Python call per planner iteration; ``first_solution_time`` is exact to one iteration.
    """

    def __init__(self, planner: object, interval: float):
        if not reports_progress(planner):
            raise ValueError(f"{type(planner).__name__} reports no progress properties")
        if not interval > 0:
            raise ValueError(f"interval: expected seconds > 0, got {interval}")
        self.planner, self.interval = planner, float(interval)
        self.properties = [(n, get) for n, attr, get in PROPERTIES if hasattr(planner, attr)]
        self.samples: list[list[float]] = []
        self.first_solution_time: float | None = None
        self._t0 = 0.0

    @property
    def names(self) -> list[str]:
        """Property names in sample order, ``"time REAL"`` first."""
        return ["time REAL", *(n for n, _ in self.properties)]

    def termination_condition(self, time_limit: float) -> ob.PlannerTerminationCondition:
        """A condition that stops the planner after ``time_limit`` seconds and samples
        its progress every ``interval`` seconds until then."""
        self._t0 = time.perf_counter()
        deadline, next_sample = self._t0 + time_limit, [self._t0 + self.interval]
        best_cost = self.properties[0][1]

        def done() -> bool:
            now = time.perf_counter()
            if self.first_solution_time is None and math.isfinite(best_cost(self.planner)):
                self.first_solution_time = now - self._t0
            if now >= next_sample[0]:
                self._sample(now)
                next_sample[0] = now + self.interval
            return now >= deadline

        return ob.PlannerTerminationCondition(done)

    def _sample(self, now: float) -> None:
        self.samples.append([now - self._t0, *(get(self.planner) for _, get in self.properties)])

    def finish(self) -> None:
        """Take the last sample, at the end of ``solve()``, and let go of the planner.

        Some planners (AORRTC) keep the termination condition, whose Python callable
        holds this recorder: holding the planner after ``solve()`` would make a cycle
        through C++ that Python's collector cannot see, so nothing of it would be freed.
        """
        now = time.perf_counter()
        if not self.samples or now - self._t0 > self.samples[-1][0]:
            self._sample(now)
        # a solution found in the very last iteration was never seen by the condition
        if self.first_solution_time is None and math.isfinite(self.samples[-1][1]):
            self.first_solution_time = self.samples[-1][0]
        self.planner = None

    def to_json(self) -> dict[str, list[float]]:
        """The samples as columns, ``{property name: values}`` (``inf`` stays ``inf``)."""
        return {name: [s[i] for s in self.samples] for i, name in enumerate(self.names)}
