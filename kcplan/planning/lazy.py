"""Lazy certification: screen a tree's edges, certify only the path it returns.

A certified edge costs a few guards; most edges a tree planner checks never reach its
solution path. Lazy collision checking (Bohlin and Kavraki 2000, OMPL's LazyRRT and
LazyPRM, which the OMPL 2.0 wheel does not expose) pays the full price only for a
candidate path's edges. :func:`solve_lazily` does that around any single-query planner:

1. the motion validator only *screens* edges (:attr:`KCMotionValidator.screen_step`):
   the end state and collision probes every ``screen_step`` (radians of joint-space
   distance for an arm, length units of motion for a rigid robot), no proof;
2. when the planner returns a path, every edge of it is certified as an eager planner's
   would be (the certifier's ``check``: guards, certificates, no gap);
3. if an edge is rejected (it touches between the probes, or its proof needs more
   guards than allowed), the planner starts again with the probes twice as dense, within
   the same time limit.

So a returned path is certified edge by edge exactly like an eager planner's: laziness
changes which edges are paid for, never what a returned path is. What it costs: a path
the certificate rejects throws away the trees grown so far.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

from ompl import base as ob

from kcplan.planning.arm_certifier import PROBE_STEP

__all__ = ["LAZY_SCREEN_STEP", "RIGID_SCREEN_STEP", "LazyOutcome", "solve_lazily"]

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
        Paths returned by the planner that had an edge the certificate rejected.
    screen_step : float
        The last attempt's screening step.
    """

    solved: bool
    time: float
    attempts: int
    rejected_paths: int
    screen_step: float


def solve_lazily(
    ss,
    validator,
    read: Callable,
    time_limit: float,
    screen_step: float = LAZY_SCREEN_STEP,
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

    Returns
    -------
    LazyOutcome
        When ``solved``, ``ss``'s solution path is certified edge by edge; otherwise it
        has none. The validator certifies again on return.
    """
    if not screen_step > 0.0:
        raise ValueError(f"screen_step: expected a step > 0, got {screen_step}")
    start = time.perf_counter()
    attempts = rejected = 0
    step = screen_step
    certify = validator.certifier.check
    while True:
        remaining = time_limit - (time.perf_counter() - start)
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
        path = [read(s) for s in ss.getSolutionPath().getStates()]
        if all(certify(a, b) for a, b in zip(path, path[1:], strict=False)):
            return LazyOutcome(True, time.perf_counter() - start, attempts, rejected, step)
        rejected += 1
        step *= 0.5
        ss.clear()  # the trees hold screened edges only: start again, probing denser
    ss.clear()
    return LazyOutcome(False, time.perf_counter() - start, attempts, rejected, step)
