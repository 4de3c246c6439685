"""What one call costs on an arm: certified edges, rejected edges and state checks (issue 25).

Plans an arm scenario with a kc planner on the compiled kernel (one seed, no
simplification), timing every ``checkMotion`` and state check the planner makes, and
prints a Markdown table by outcome: calls, median and mean microseconds per call, and
the share of the solve time; then the counters that explain them (guards and probes per
edge). A lazy planner's (``kc-rrtconnect-lazy``) tree edges are counted as *screened*;
the certification of its path is part of its solve time but not of the table::

    python scripts/arm_edge_cost.py scenarios/arm/box_1.yaml [--planner kc-rrtconnect]
        [--seed 1] [--time 10]

Each call is timed around the validator's one call into the kernel (reading the OMPL
states included), as :mod:`scripts.edge_cost` times rigid robots. The rest of the solve
time is OMPL's own work (sampling, nearest neighbours, the calls' way in and out of
Python).
"""

from __future__ import annotations

import argparse
import statistics
import time

from kcplan.planning.problem import plan
from kcplan.planning.validator import KCMotionValidator
from kcplan.scenarios import load_scenario


class ArmCallTimer:
    """Every kernel-backed arm call of :class:`KCMotionValidator`, timed and sorted by
    its outcome (the class's methods are wrapped; restored on exit)."""

    def __init__(self):
        self.times: dict[str, list[float]] = {
            "certified": [], "rejected": [], "screened": [], "state": []
        }  # fmt: skip
        self._saved = []

    def __enter__(self) -> ArmCallTimer:
        edge, state = KCMotionValidator._check_kernel_arm, KCMotionValidator._valid_kernel_arm
        self._saved = [("_check_kernel_arm", edge), ("_valid_kernel_arm", state)]

        def timed_edge(validator, s1, s2) -> bool:
            t0 = time.perf_counter()
            ok = edge(validator, s1, s2)
            # a lazy planner's tree edges are screened, not certified (kcplan.planning.lazy)
            if validator.screen_step is not None:
                kind = "screened"
            else:
                kind = "certified" if ok else "rejected"
            self.times[kind].append(time.perf_counter() - t0)
            return ok

        def timed_state(validator, s) -> bool:
            t0 = time.perf_counter()
            ok = state(validator, s)
            self.times["state"].append(time.perf_counter() - t0)
            return ok

        KCMotionValidator._check_kernel_arm = timed_edge
        KCMotionValidator._valid_kernel_arm = timed_state
        return self

    def __exit__(self, *exc) -> None:
        for name, value in self._saved:
            setattr(KCMotionValidator, name, value)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario")
    parser.add_argument("--planner", default="kc-rrtconnect")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--time", type=float, default=10.0, help="solve time limit [s]")
    args = parser.parse_args(argv)
    scenario = load_scenario(args.scenario)
    if getattr(scenario, "arm", None) is None:
        parser.error(f"{args.scenario}: expected an arm scenario")
    with ArmCallTimer() as timer:
        r = plan(scenario, args.planner, args.time, args.seed, simplify=False)
    if r.backend != "kernel" or not r.counters.get("kc_edges"):
        parser.error(f"--planner: expected a kc planner on the kernel, got {args.planner}")
    solved = "solved" if r.solved else "not solved"
    print(f"{scenario.name}, {args.planner}, seed {args.seed}: {solved} in {r.time:.3f} s")
    print("| calls | count | median µs | mean µs | share of solve |")
    print("|---|---|---|---|---|")
    for name, times in timer.times.items():
        if times:
            median, mean = statistics.median(times), statistics.fmean(times)
            share = sum(times) / r.time if r.time > 0 else 0.0
            print(f"| {name} | {len(times)} | {1e6 * median:.1f} | {1e6 * mean:.1f} "
                  f"| {share:.0%} |")  # fmt: skip
    c = r.counters
    edges = max(c["kc_edges"], 1)
    print(
        f"guards per edge {c['kc_guards'] / edges:.2f}, probes per edge "
        f"{c['kc_probes'] / edges:.2f}, edges rejected by a probe {c['kc_rejected_probe']}, "
        f"certified {c['kc_edges'] - c['kc_rejected']} of {c['kc_edges']}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
