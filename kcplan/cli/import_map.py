"""``kcplan import``: convert HRM and Moving AI maps into scenario files."""

from __future__ import annotations

import argparse
from pathlib import Path

from kcplan.cli.common import InputError, Parser, output_file, positive_float


def run(args: argparse.Namespace) -> int:
    """Convert the map, validate the scenario, then write it."""
    from kcplan.maps import MapImportError
    from kcplan.world import ScenarioError, dump_scenario, parse_scenario

    out = Path(args.output)
    output_file(args.output, "-o", (".yaml", ".yml"))
    try:
        if args.source == "hrm":
            from kcplan.maps.hrm import import_hrm

            if not Path(args.resources).is_dir():
                raise MapImportError(f"{args.resources}: expected HRM's resources folder")
            data = import_hrm(
                args.resources, args.map, args.dimension, out, args.inflation, args.robot
            )
        else:
            from kcplan.maps.movingai import import_movingai

            if args.index is not None and args.scen is None:
                raise MapImportError("--index: expected --scen FILE.scen as well")
            data = import_movingai(
                args.map_file, args.scen, args.index or 0, args.cell, args.robot, args.inflation
            )
        scenario = parse_scenario(data, str(out), out.parent, check=True)
    except (MapImportError, ScenarioError) as err:
        raise InputError(str(err)) from None
    dump_scenario(data, out)
    print(
        f"{out}: {scenario.name}, {scenario.dimension}D, {len(data['obstacles'])} obstacles, "
        f"robot {scenario.robot.describe()}"
    )
    print(data["description"])
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``kcplan import`` on the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "import",
        help="convert public benchmark maps (HRM, Moving AI) into scenario files",
        description="Convert a public benchmark map into a kcplan scenario YAML; the "
        "result is validated (start and goal free) before it is written.",
    )
    kinds = p.add_subparsers(dest="source", required=True, parser_class=Parser)
    q = kinds.add_parser(
        "hrm",
        help="a Highway RoadMap map (CSV, github.com/ChirikjianLab/hrm)",
        description="Convert an HRM map with one of HRM's robots (every body kept, rigid). "
        "Superellipses become circumscribed polygons, superquadrics circumscribed convex "
        "polytopes (outer approximations); the arena is kept by walls outside its inscribed "
        "polygon (3D: a mesh surface and an inscribed box for the robot's origin); the "
        "bound on the geometric error is in the scenario's description.",
    )
    q.add_argument("resources", metavar="RESOURCES_DIR", help="HRM's resources folder")
    q.add_argument("--map", required=True, help="map name, e.g. ellipse_maze or maze")
    q.add_argument("--dimension", type=int, choices=(2, 3), default=2, help="2 (default) or 3")
    q.add_argument(
        "--robot",
        help="HRM robot: 2D NAO_silhouette, S_shape, rabbit, single_body (default); "
        "3D chair, rabbit (default), rabbit2, snake, tree",
    )
    q.add_argument("--inflation", type=positive_float, default=0.1, help="guard inflation")
    q.add_argument("-o", "--output", required=True, metavar="SCENARIO.yaml")
    q.set_defaults(handler=run)
    q = kinds.add_parser(
        "movingai",
        help="a Moving AI grid map (.map, optional .scen row)",
        description="Convert a Moving AI grid map: blocked cells become boxes merged into "
        "rectangles, walls keep the robot on the map, start and goal from a .scen row.",
    )
    q.add_argument("map_file", metavar="MAP.map")
    q.add_argument("--scen", metavar="FILE.scen", help="scenario file with start/goal rows")
    q.add_argument("--index", type=int, help="0-based row of --scen (default 0)")
    q.add_argument("--cell", type=positive_float, default=1.0, help="cell size (default 1)")
    q.add_argument(
        "--robot",
        nargs=2,
        type=positive_float,
        metavar=("A1", "A2"),
        help="robot semi-axes (default 0.7 and 0.4 times the narrowest corridor)",
    )
    q.add_argument("--inflation", type=positive_float, default=0.1, help="guard inflation")
    q.add_argument("-o", "--output", required=True, metavar="SCENARIO.yaml")
    q.set_defaults(handler=run)
