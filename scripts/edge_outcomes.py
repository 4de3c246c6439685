"""Where a kc planner's time goes, by how each edge was decided (issue 26).

Plans one scenario with the given seeds (no simplification) and times every call of the
motion validator and of the state checker, grouped by outcome: certified by the endpoint
guards or after more guards, or rejected at the end state, by the occupancy grid, the
core sweep, a probe, a guard, or "not proven". Prints a Markdown table::

    python scripts/edge_outcomes.py /tmp/hrm/maze_rabbit.yaml kc-rrtconnect 1,2,3 [--probes N]

``--probes`` overrides the planner's collision probes per edge (0: none). Each call is
timed around the kernel call and the counters are read before and after it, which adds
a few microseconds per call outside the timed stretch.
"""

from __future__ import annotations

import argparse
import collections
import dataclasses
import time

from kcplan.planning import problem
from kcplan.planning import validator as V
from kcplan.scenarios import load_scenario

REASONS = (
    "rejected_end_state",
    "rejected_occupancy",
    "rejected_sweep",
    "rejected_probe",
    "rejected_guard",
    "not_proven",
)


def instrument(stats: dict) -> None:
    """Wrap the validator's compiled hot paths so that every call lands in ``stats``."""

    def wrap_check(original):
        def check(self, s1, s2):
            before = self.certifier.counters
            t0 = time.perf_counter()
            ok = original(self, s1, s2)
            seconds = time.perf_counter() - t0
            after = self.certifier.counters
            if ok:
                by_ends = after["certified_by_endpoints"] > before["certified_by_endpoints"]
                key = "certified by the endpoint guards" if by_ends else "certified after guards"
            else:
                key = next((r for r in REASONS if after[r] > before[r]), "rejected (other)")
            row = stats[key]
            row[0] += 1
            row[1] += seconds
            row[2] += after["guards"] - before["guards"]
            row[3] += after["collision_queries"] - before["collision_queries"]
            return ok

        return check

    def wrap_valid(original):
        def valid(self, state):
            before = self.certifier.counters["collision_queries"]
            t0 = time.perf_counter()
            ok = original(self, state)
            queried = self.certifier.counters["collision_queries"] - before
            row = stats["state check, queried" if queried else "state check, known"]
            row[0] += 1
            row[1] += time.perf_counter() - t0
            row[3] += queried
            return ok

        return valid

    for name in ("_check_kernel_se2", "_check_kernel_se3"):
        setattr(V.KCMotionValidator, name, wrap_check(getattr(V.KCMotionValidator, name)))
    for name in ("_valid_kernel_se2", "_valid_kernel_se3"):
        setattr(V.KCMotionValidator, name, wrap_valid(getattr(V.KCMotionValidator, name)))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario")
    parser.add_argument("planner", help="a kc planner on the kernel (kc-rrtconnect, kc-prm, ...)")
    parser.add_argument("seeds", help="comma-separated seeds, e.g. 1,2,3")
    parser.add_argument("--probes", type=int, default=None)
    parser.add_argument("--time", type=float, default=30.0, help="time limit per seed")
    args = parser.parse_args(argv)
    spec = problem.PLANNERS[args.planner]
    if not spec.kc or spec.backend != "kernel":
        parser.error(f"planner: expected a kc planner on the kernel, got {args.planner}")
    if args.probes is not None:
        problem.PLANNERS[args.planner] = dataclasses.replace(spec, probes=args.probes)
    stats: dict = collections.defaultdict(lambda: [0, 0.0, 0, 0])
    instrument(stats)
    scenario = load_scenario(args.scenario)
    total = 0.0
    for seed in (int(s) for s in args.seeds.split(",")):
        result = problem.plan(
            scenario, args.planner, time_limit=args.time, seed=seed, simplify=False
        )
        total += result.time
        print(f"seed {seed}: solved {result.solved} in {result.time:.3f} s, "
              f"{result.counters['kc_edges']} edges")  # fmt: skip
    print(f"\nsolve time, all seeds: {total:.3f} s\n")
    print("| outcome | calls | s | µs per call | guards | collision queries |")
    print("|---|---|---|---|---|---|")
    for key, (calls, seconds, guards, queries) in sorted(stats.items(), key=lambda kv: -kv[1][1]):
        print(f"| {key} | {calls} | {seconds:.3f} | {1e6 * seconds / max(calls, 1):.1f} | "
              f"{guards} | {queries} |")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
