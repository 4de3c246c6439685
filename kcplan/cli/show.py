"""``kcplan show``: draw a scenario."""

from __future__ import annotations

import argparse
from pathlib import Path

from kcplan.cli.common import InputError, load_input, output_file


def run(args: argparse.Namespace) -> int:
    """Draw the scenario into ``-o`` (default beside it) and ``--html``."""
    output_file(args.output, "-o", (".png",))
    output_file(args.html, "--html", (".html",))
    scenario = load_input(args.scenario)
    arm = getattr(scenario, "arm", None) is not None
    for option in ("show_cover", "meshes"):
        if not arm and getattr(args, option) not in (False, "auto"):
            flag = "--" + option.replace("_", "-")
            raise InputError(f"{args.scenario}: {flag}: only for arms (a URDF robot)")
    if arm and args.meshes == "visual":
        from kcplan.views.arm import visual_meshes_missing

        reason = visual_meshes_missing(scenario.arm)
        if reason:
            raise InputError(f"{args.scenario}: --meshes visual: {reason}")
    if args.html:
        from kcplan.views.html import write_scene_html

        source = write_scene_html(scenario, args.html, None, args.show_cover, args.meshes)
        links = f" (links: {source})" if source else ""
        print(f"interactive view written to {args.html}{links}")
        if not args.output:
            return 0
    out = args.output or str(Path(args.scenario).with_suffix(".png"))
    if arm:
        from kcplan.views.plots import plot_arm

        source = plot_arm(scenario, out, show_cover=args.show_cover, meshes=args.meshes)
        print(f"picture written to {out} (links: {source})")
        return 0
    from kcplan.views.plots import plot_scenario

    plot_scenario(scenario, out, guards=scenario.inflation)
    print(f"picture written to {out}")
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``kcplan show`` on the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "show",
        help="draw a scenario",
        description="Draw a scenario: obstacles, bounds, start (green) and goal (red) robots "
        "with their guards (dotted). 2D top view, 3D perspective; an arm at its start and goal "
        "from two viewpoints.",
    )
    p.add_argument("scenario", metavar="SCENARIO", help="YAML scenario file")
    p.add_argument(
        "-o",
        "--output",
        metavar="FILE.png",
        help="image file (default: beside the scenario, same name, .png; with --html, only "
        "when given)",
    )
    p.add_argument("--html", metavar="FILE.html", help="write an interactive 3D view")
    from kcplan.cli.plan import add_arm_view_options

    add_arm_view_options(p)
    p.set_defaults(handler=run)
