"""One benchmark run in a fresh interpreter: ``python -m kcplan.bench.worker < SPEC.json``.

A fresh process per run is what makes runs reproducible (OMPL takes its seed once per
process) and isolated (a segfault in FCL or OMPL ends only this run). The worker reads
one run specification (JSON, see :class:`kcplan.bench.campaign.RunSpec`) from stdin,
plans, verifies the path exactly as ``kcplan verify`` does, and writes one JSON record on
the last line of stdout. Anything else the libraries print goes to stderr.
"""

from __future__ import annotations

import json
import os
import resource
import sys
import time

__all__ = ["execute", "main"]


def execute(spec: dict) -> dict:
    """Plan and verify one run in this process; return the record (plain JSON values).

    The record holds ``status`` ("ok"), ``solved``, ``time`` (seconds in ``solve()``),
    ``simplify_time``, ``length`` and ``raw_length`` (OMPL path lengths after and before
    simplification), ``states`` (the returned path), ``first_solution_time`` and
    ``progress`` (best cost over time of anytime planners, see
    :class:`kcplan.planning.progress.ProgressRecorder`; None and empty otherwise),
    ``counters`` (FCL queries and, for kc planners, the validator's counters),
    ``backend`` (``"kernel"`` or ``"python"``: who checked, see
    :class:`kcplan.planning.problem.PlannerSpec`),
    ``collides`` / ``min_clearance`` / ``verify_queries`` (gap-free verification; None
    when unsolved), ``part_collides`` (the same check of the part's own mesh when the
    robot is the cover of one, ``robot.mesh``; None otherwise), ``memory_mb`` (peak
    resident set of the worker) and ``wall`` (seconds of the whole run).
    """
    t0 = time.perf_counter()
    from kcplan.planning.problem import plan
    from kcplan.planning.verify import verify_path
    from kcplan.scenarios import load_scenario
    from kcplan.world import CollisionWorld

    scenario = load_scenario(spec["scenario"])
    arm = getattr(scenario, "arm", None) is not None
    # plan() resets the world's counters and copies them out
    world = None if arm else CollisionWorld(scenario)
    result = plan(
        scenario,
        spec["planner"],
        float(spec["time_limit"]),
        seed=int(spec["seed"]),
        simplify=bool(spec.get("simplify", True)),
        world=world,
        progress=spec.get("progress"),
    )
    check = None
    if result.solved:  # an arm on its links' meshes (PlanResult.verify)
        check = result.verify() if arm else verify_path(world, result.states)
    part = None
    if check is not None and not arm and scenario.part is not None:
        from kcplan.world.part import PartWorld

        part = verify_path(PartWorld(world, scenario.part), result.states)
    return {
        "status": "ok",
        "reason": "",
        "backend": result.backend,
        "solved": result.solved,
        "time": result.time,
        "simplify_time": result.simplify_time,
        "length": result.length if result.solved else None,
        "raw_length": result.raw_length if result.solved else None,
        "states": result.states,
        "counters": result.counters,
        "first_solution_time": result.first_solution_time,
        "progress": result.progress,
        "collides": None if check is None else check.collides,
        "min_clearance": None if check is None else check.min_clearance,
        "verify_queries": None if check is None else check.queries,
        "part_collides": None if part is None else part.collides,
        "memory_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "wall": time.perf_counter() - t0,
    }


def main() -> None:
    spec = json.loads(sys.stdin.read())
    try:
        record = execute(spec)
    except Exception as exc:  # reported as a failed run by the parent, never a traceback
        record = {"status": "error", "reason": f"{type(exc).__name__}: {exc}"}
    sys.stdout.write("\n" + json.dumps(record) + "\n")
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)  # skip nanobind's shutdown (see ompl-python-notes, section 6)


if __name__ == "__main__":
    main()
