"""``kcplan validate``: check scenario files, one line each."""

from __future__ import annotations

import argparse
import sys


def run(args: argparse.Namespace) -> int:
    """Check each scenario file; exit 2 when any is invalid."""
    from kcplan.scenarios import load_scenario
    from kcplan.world import ScenarioError

    failed = 0
    for path in args.scenarios:
        try:
            s = load_scenario(path)
        except ScenarioError as err:
            failed += 1
            print(f"INVALID {err}")
            continue
        print(
            f"ok      {path}: {s.name}, {s.dimension}D, {len(s.obstacles)} obstacles, "
            f"robot {s.robot.describe()}"
        )
    if failed:
        print(f"{failed} of {len(args.scenarios)} scenario files are invalid", file=sys.stderr)
    return 2 if failed else 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``kcplan validate`` on the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "validate",
        help="check scenario files",
        description="Check scenario files: format, values, start and goal inside the bounds and "
        "free of obstacles. One line per file; exit 0 when all are valid, 2 otherwise.",
    )
    p.add_argument("scenarios", nargs="+", metavar="SCENARIO", help="YAML scenario files")
    p.set_defaults(handler=run)
