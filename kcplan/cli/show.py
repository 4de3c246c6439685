"""``kcplan show``: draw a scenario."""

from __future__ import annotations

import argparse
from pathlib import Path

from kcplan.cli.common import load_input, output_file


def run(args: argparse.Namespace) -> int:
    """Draw the scenario into ``-o`` (default beside it)."""
    output_file(args.output, "-o", (".png",))
    scenario = load_input(args.scenario)
    out = args.output or str(Path(args.scenario).with_suffix(".png"))
    from kcplan.viz import plot_scenario

    plot_scenario(scenario, out, guards=scenario.inflation)
    print(f"picture written to {out}")
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``kcplan show`` on the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "show",
        help="draw a scenario",
        description="Draw a scenario: obstacles, bounds, start (green) and goal (red) robots "
        "with their guards (dotted). 2D top view, 3D perspective.",
    )
    p.add_argument("scenario", metavar="SCENARIO", help="YAML scenario file")
    p.add_argument(
        "-o",
        "--output",
        metavar="FILE.png",
        help="image file (default: beside the scenario, same name, .png)",
    )
    p.set_defaults(handler=run)
