"""One row per planner over every scenario of a ``kcplan bench`` campaign (its summary.csv).

``kcplan bench`` writes a row per scenario and planner; a campaign over many problems
(issue 57's whole-body problems, ``make_whole_body_problems.py``) is read per planner:
the problems, the runs solved, the median over the problems of each problem's median
solve time, and the returned paths that the gap-free verification found colliding::

    python scripts/bench_totals.py benchmarks/whole-body/pr2-bench/summary.csv
"""

from __future__ import annotations

import argparse
import csv
import statistics
import sys
from pathlib import Path


def totals(path: Path) -> list[dict]:
    """Per planner, in the campaign's order: problems, solved, runs, the median of the
    problems' median times (seconds), colliding paths."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    out = []
    for planner in dict.fromkeys(r["planner"] for r in rows):
        mine = [r for r in rows if r["planner"] == planner]
        out.append({
            "planner": planner,
            "problems": len(mine),
            "solved": sum(int(r["solved"]) for r in mine),
            "runs": sum(int(r["runs"]) for r in mine),
            "median_time": statistics.median(float(r["median_time"]) for r in mine),
            "colliding": sum(int(r["colliding_paths"]) for r in mine),
        })  # fmt: skip
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("summary", type=Path, help="a campaign's summary.csv")
    args = parser.parse_args(argv)
    try:
        rows = totals(args.summary)
    except (OSError, KeyError, ValueError) as err:
        print(f"{args.summary}: expected a kcplan bench summary.csv: {err}", file=sys.stderr)
        return 2
    print("| planner | problems | solved | median of the problems' median times (ms) | "
          "colliding paths |")  # fmt: skip
    print("|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['planner']} | {r['problems']} | {r['solved']} / {r['runs']} | "
              f"{1e3 * r['median_time']:.1f} | {r['colliding']} |")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
