"""Lazy certification: screen a tree's edges, certify only the path it returns.

A certified edge costs a few guards; most edges a tree planner checks never reach its
solution path. Lazy collision checking (Bohlin and Kavraki 2000, OMPL's LazyRRT and
LazyPRM, which the OMPL 2.0 wheel does not expose) pays the full price only for a
candidate path's edges. :func:`solve_lazily` does that around any single-query planner:

1. the motion validator only *screens* edges (:attr:`KCMotionValidator.screen_step`):
   the end state and collision probes every ``screen_step`` (radians of joint-space
   distance for an arm, length units of motion for a rigid robot), no proof;
2. when the planner returns a path, every edge of it is certified as an eager planner's
   would be (the certifier's ``check``: guards, certificates, no gap), without the
   probes ``check`` begins with (they only reject early, and the edge was screened);
3. an edge the certificate rejects (it touches between the probes, or its proof needs
   more guards than allowed) is *repaired*: RRT-Connect at the planner's range, every
   edge certified (eager), plans from the edge's start to its end, and its path takes the
   edge's place. Repairs get as long as the attempt that found the path took
   (:data:`REPAIR_SHARE`); if one fails, the planner starts again with the probes twice as
   dense, within the same time limit (so did every rejection before repairs: the
   ablation ``kc-rrtconnect-lazy-restart``).

So a returned path is certified edge by edge exactly like an eager planner's: laziness
changes which edges are paid for, never what a returned path is. What it costs: the
screening, and for a rejected edge a short certified plan around it (or, when that fails,
the trees grown so far).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

from ompl import base as ob
from ompl import geometric as og

from kcplan.certification.arm_certifier import PROBE_STEP

__all__ = ["LAZY_SCREEN_STEP", "REPAIR_SHARE", "RIGID_SCREEN_STEP", "LazyOutcome", "solve_lazily"]

LAZY_SCREEN_STEP = PROBE_STEP
"""An arm's first screening step, radians of joint-space distance (L2) per probe: the
eager certifier's probe step (0.1), between VAMP's 1/32 rad and the 0.134 rad
of OMPL's default resolution on the Panda. On 35 MBM Panda problems 0.2 screened for
less but a quarter more paths were rejected, each throwing its trees away: the sum of
times 0.425 s against 0.321 s at 0.1 (RESULTS 17)."""

RIGID_SCREEN_STEP = 0.5
"""A rigid robot's first screening step, as a multiple of its thinnest semi-axis: probes at
most that far apart in the motion of the robot's farthest point, so that the robot's
placements at two probes overlap well. Against 1.0, on HRM's maze and cluttered map,
slanted_gap and Moving AI's maze-32 (10 runs each): 0.122, 0.051, 0.010, 0.165 s against
0.109, 0.054, 0.011, 0.218 s; a rejected path costs a restart (RESULTS 17.3)."""


REPAIR_SHARE = 1.0
"""Seconds the repairs of one path may take, as a multiple of the seconds the attempt
that returned it took (its ``solve()`` and certification): a failed repair so costs at
most what a restart's first attempt would have."""


@dataclass(frozen=True)
class LazyOutcome:
    """What :func:`solve_lazily` did.

    Attributes
    ----------
    solved : bool
        A path was found and every edge of it certified.
    time : float
        Seconds, every attempt's ``solve()`` and the paths' certification.
    attempts : int
        ``solve()`` calls.
    rejected_paths : int
        Paths thrown away: a rejected edge that could not be repaired (or repairs off).
    screen_step : float
        The last attempt's screening step.
    repaired_edges : int
        Rejected edges replaced by a certified sub-plan, in every attempt.
    """

    solved: bool
    time: float
    attempts: int
    rejected_paths: int
    screen_step: float
    repaired_edges: int = 0


def solve_lazily(
    ss,
    validator,
    read: Callable,
    time_limit: float,
    screen_step: float = LAZY_SCREEN_STEP,
    repair: bool = True,
    probe_path: bool = False,
) -> LazyOutcome:
    """Solve ``ss`` screening edges, certifying only the returned path (module docstring).

    Parameters
    ----------
    ss : ompl.geometric.SimpleSetup
        Set up, with ``validator`` installed as its motion validator.
    validator : KCMotionValidator
        Certifying ``ss``'s edges (kernel or Python, any robot).
    read : callable
        An OMPL state to the certifier's numpy state (``ProblemSetup.read``).
    time_limit : float
        Seconds for everything.
    screen_step : float
        The first attempt's screening step (> 0): radians for an arm
        (:data:`LAZY_SCREEN_STEP`), length units for a rigid robot
        (:data:`RIGID_SCREEN_STEP` times its thinnest semi-axis).
    repair : bool
        Replace a rejected edge by a certified sub-plan before throwing the trees away;
        False: restart at once (the ablation).
    probe_path : bool
        Probe the path's edges again before their guards, as an eager certifier does (the
        ablation): they were screened at ``screen_step`` already, and probes prove nothing.

    Returns
    -------
    LazyOutcome
        When ``solved``, ``ss``'s solution path is certified edge by edge; otherwise it
        has none. The validator certifies again on return.
    """
    if not screen_step > 0.0:
        raise ValueError(f"screen_step: expected a step > 0, got {screen_step}")
    start = time.perf_counter()
    attempts = rejected = repaired = 0
    step = screen_step
    certifier = validator.certifier

    def certify(q1, q2) -> bool:  # screened already: its probes would be asked again
        return certifier.check(q1, q2, probe=probe_path)

    while True:
        began = time.perf_counter()
        remaining = time_limit - (began - start)
        if remaining <= 0.0:
            break
        attempts += 1
        validator.screen_step = step
        try:  # not solve(seconds): from 1 s on, OMPL then polls the clock from a thread
            ss.solve(ob.timedPlannerTerminationCondition(remaining))
        finally:
            validator.screen_step = None
        validator.raise_error()
        if not ss.haveExactSolutionPath():
            break
        path = ss.getSolutionPath()
        q = [read(s) for s in path.getStates()]
        bad = []
        for i in range(len(q) - 1):
            if not certify(q[i], q[i + 1]):
                bad.append(i)
                if not repair:  # the first rejected edge condemns the path
                    break
        if bad and repair:
            now = time.perf_counter()
            budget = min(REPAIR_SHARE * (now - began), time_limit - (now - start))
            fixed = _repaired(ss, path, bad, budget)
            validator.raise_error()
            if fixed is not None:
                # its states copied into the solution ss holds: a path made in Python and
                # handed to OMPL (addSolutionPath, assign) keeps Python's wrapper of si,
                # and so ss, alive from inside ss (a cycle the collector cannot see)
                path.clear()
                for state in fixed.getStates():
                    path.append(state)
                repaired += len(bad)
                bad = []
        if not bad:
            elapsed = time.perf_counter() - start
            return LazyOutcome(True, elapsed, attempts, rejected, step, repaired)
        rejected += 1
        step *= 0.5
        ss.clear()  # the trees hold screened edges only: start again, probing denser
    ss.clear()
    return LazyOutcome(False, time.perf_counter() - start, attempts, rejected, step, repaired)


def _repaired(ss, path, bad: list[int], budget: float) -> og.PathGeometric | None:
    """``path`` with each edge ``i`` of ``bad`` (states i to i + 1) replaced by a path
    of RRT-Connect at ``ss``'s planner's range whose edges the validator certified, all
    within ``budget`` seconds; None if one of them is not found in time."""
    si = ss.getSpaceInformation()
    planner = ss.getPlanner()
    reach = planner.getRange() if hasattr(planner, "getRange") else None
    deadline = time.perf_counter() + budget
    rejected = set(bad)
    states = path.getStates()
    out = og.PathGeometric(si)
    out.append(states[0])
    for i in range(len(states) - 1):
        if i in rejected:
            left = deadline - time.perf_counter()
            if left <= 0.0:
                return None
            pdef = ob.ProblemDefinition(si)
            pdef.setStartAndGoalStates(states[i], states[i + 1])
            sub = og.RRTConnect(si)
            if reach:
                sub.setRange(reach)
            sub.setProblemDefinition(pdef)
            sub.setup()
            sub.solve(ob.timedPlannerTerminationCondition(left))
            if not pdef.hasExactSolution():
                return None
            between = pdef.getSolutionPath().getStates()
            for s in between[1:-1]:  # the sub-plan's ends are the edge's
                out.append(s)
        out.append(states[i + 1])
    return out
