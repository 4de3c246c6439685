"""``kcplan import``: convert HRM and Moving AI maps, and MotionBenchMaker problems,
into scenario files."""

from __future__ import annotations

import argparse
from pathlib import Path

from kcplan.arm.model import REPRESENTATIONS
from kcplan.cli.common import InputError, Parser, output_file, positive_float, positive_int


def run(args: argparse.Namespace) -> int:
    """Convert the map, validate the scenario, then write it."""
    from kcplan.maps import MapImportError
    from kcplan.scenarios import dump_scenario, parse_scenario
    from kcplan.world import ScenarioError

    out = Path(args.output)
    output_file(args.output, "-o", (".yaml", ".yml"))
    if args.source == "mbm":
        return _run_mbm(args, out)
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


def _run_mbm(args: argparse.Namespace, out: Path) -> int:
    """One MotionBenchMaker problem, from its two files or from the archive."""
    from kcplan.arm.mbm import MbmError, mbm_scenario, read_mbm_archive, read_mbm_problem
    from kcplan.scenarios import dump_scenario, parse_scenario
    from kcplan.world import ScenarioError

    files = [args.scene, args.request]
    try:
        if args.archive is not None:
            if any(files) or args.problem is None or args.index is None:
                raise InputError(
                    "kcplan import mbm: --archive: expected --problem and --index, and no "
                    "SCENE.yaml REQUEST.yaml"
                )
            problem = read_mbm_archive(args.archive, args.problem, args.index)
            name = f"{args.problem}_{args.index}"
        else:
            if not all(files):
                raise InputError(
                    "kcplan import mbm: expected SCENE.yaml REQUEST.yaml, or --archive "
                    "with --problem and --index"
                )
            problem = read_mbm_problem(args.scene, args.request)
            name = Path(args.scene).stem
        for option, path in (("--urdf", args.urdf), ("--srdf", args.srdf)):
            if path is not None and not Path(path).is_file():
                raise InputError(f"{path}: {option}: expected an existing file")
        data = mbm_scenario(
            problem, name, args.urdf, args.srdf, out, args.bodies_per_link, args.max_offset,
            args.representation, args.package_dir or (),
        )  # fmt: skip
        scenario = parse_scenario(data, str(out), out.parent, check=True)
    except (MbmError, ScenarioError) as err:
        raise InputError(str(err)) from None
    dump_scenario(data, out)
    print(
        f"{out}: {scenario.name}, arm of {scenario.arm.dof} joints "
        f"({len(scenario.arm.bodies)} bodies), {len(scenario.obstacles)} obstacles, "
        f"{len(scenario.allowed)} allowed link pairs"
    )
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``kcplan import`` on the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "import",
        help="convert public benchmark maps (HRM, Moving AI) and MotionBenchMaker problems "
        "into scenario files",
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
    q = kinds.add_parser(
        "mbm",
        help="a MotionBenchMaker problem (MoveIt scene and request YAML) for a URDF arm",
        description="Convert one MotionBenchMaker problem into an arm scenario: its "
        "obstacles, the request's start and goal for the goal's joints (the planning "
        "group), every other joint fixed at its start value, the scene's allowed collision "
        "matrix. The start and goal must be free for the arm's representation.",
    )
    q.add_argument("scene", nargs="?", metavar="SCENE.yaml")
    q.add_argument("request", nargs="?", metavar="REQUEST.yaml")
    q.add_argument("--archive", metavar="problems.tar.bz2", help="VAMP's problem archive")
    q.add_argument("--problem", help="with --archive: the class, e.g. box or bookshelf_tall")
    q.add_argument("--index", type=positive_int, help="with --archive: the problem, 1 to 100")
    q.add_argument("--urdf", required=True, metavar="ROBOT.urdf")
    q.add_argument("--srdf", metavar="ROBOT.srdf")
    q.add_argument(
        "--package-dir",
        action="append",
        metavar="DIR",
        help="a folder holding the packages of the URDF's package:// mesh URIs (repeatable; "
        "the URDF's folder, ROS_PACKAGE_PATH and example-robot-data's share folder are "
        "searched too)",
    )
    q.add_argument(
        "--representation",
        choices=REPRESENTATIONS,
        help="the links as their own convex hulls (the default: exact for a convex link, "
        "nothing fitted) or as ellipsoid covers (what the KC certificate needs; the default "
        "with --bodies-per-link or --max-offset)",
    )
    q.add_argument(
        "--bodies-per-link",
        type=positive_int,
        help="ellipsoids per link (4: bundled for the Panda); with --max-offset the most "
        "per link (default 32)",
    )
    q.add_argument(
        "--max-offset",
        type=positive_float,
        metavar="METRES",
        help="cut each link's cover until it sticks out of the link's mesh by at most this "
        "(kcplan's default cover is 0.01: 95.7 %% of MBM's Panda goals valid, but a first "
        "fit of about 20 min)",
    )
    q.add_argument("-o", "--output", required=True, metavar="SCENARIO.yaml")
    q.set_defaults(handler=run)
