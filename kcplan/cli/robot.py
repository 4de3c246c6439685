"""``kcplan robot fit``: a robot of ellipsoids that provably contains a mesh or outline."""

from __future__ import annotations

import argparse
import math
import sys

import yaml

from kcplan.cli.common import InputError, output_file, positive_float, positive_int

TIGHTNESS_SAMPLES = 400_000
"""Monte Carlo samples of the reported volume ratio."""


def _robot_yaml(cover, ratio: float, error: float) -> str:
    solid = cover.solid
    header = (
        f"# kcplan robot fit: {len(cover.bodies)} {cover.shape}s covering {solid.describe()}\n"
        f"# sha256 {solid.digest}\n"
        f"# union volume / part volume {ratio:.4f} +- {error:.4f} (95 %, Monte Carlo)\n"
    )
    if not math.isnan(cover.offset):
        header += f"# sticks out of the part by at most {cover.offset:.6g}\n"
    if cover.note:
        header += f"# note: {cover.note}\n"
    body = yaml.safe_dump({"robot": cover.to_spec()}, sort_keys=False, default_flow_style=None)
    return header + body


def run_fit(args: argparse.Namespace) -> int:
    """Fit, report the tightness, write the robot block, the picture and the view."""
    output_file(args.output, "-o", (".yaml", ".yml"))
    output_file(args.plot, "--plot", (".png", ".svg", ".pdf"))
    output_file(args.html, "--html", (".html",))
    from kcplan.cover import SolidError, fit_cover, read_solid, union_volume
    from kcplan.geometry.robot import MAX_BODIES

    if args.bodies is not None and args.bodies > MAX_BODIES:
        raise InputError(f"--bodies: expected 1 to {MAX_BODIES}, got {args.bodies}")
    if args.max_offset is not None and args.max_excess is not None:
        raise InputError("--max-offset: expected --bodies (the most) or nothing beside it, "
                         "got --max-excess too")  # fmt: skip
    try:
        solid = read_solid(args.mesh, args.scale, args.hull)
    except SolidError as err:
        raise InputError(str(err)) from None
    report = sys.stdout if args.output else sys.stderr  # without -o the YAML goes to stdout
    shape = "sphere" if args.spheres else "ellipsoid"
    bodies = None if args.max_excess is not None else (args.bodies or 4)
    if args.max_offset is not None:
        bodies = args.bodies  # the most; fit_cover's default when not given

    def progress(line: str) -> None:
        print(f"  {line}", file=sys.stderr, flush=True)

    if args.max_offset is not None and solid.dimension != 3:
        raise InputError("--max-offset: expected a 3D part (a mesh), got a 2D outline")
    cover = fit_cover(solid, bodies, args.max_excess, shape, progress, args.max_offset)
    volume, error = union_volume(cover.bodies, TIGHTNESS_SAMPLES)
    ratio, error95 = volume / solid.volume, 1.96 * error / solid.volume
    unit = "area" if solid.dimension == 2 else "volume"
    print(
        f"{solid.describe()}, {unit} {solid.volume:.6g}: {len(cover.bodies)} {shape}s in "
        f"{cover.seconds:.1f} s",
        file=report,
    )
    print(
        f"  union {unit} / part {unit}: {ratio:.4f} +- {error95:.4f} (95 %, Monte Carlo, "
        f"{TIGHTNESS_SAMPLES} samples); the bodies' total: {cover.volume_bound:.4f}",
        file=report,
    )
    print(
        f"  sound: every hull point of every piece inside its body "
        f"(largest (x-p)^T M (x-p) = {cover.worst:.10f})",
        file=report,
    )
    if not math.isnan(cover.offset):
        print(
            f"  sticks out of the part by at most {cover.offset:.6g} (a proved bound: every "
            "point of every body within it of the part)",
            file=report,
        )
    if cover.note:
        print(f"  note: {cover.note}", file=report)
    text = _robot_yaml(cover, ratio, error95)
    if args.output:
        from kcplan.files import write_text_atomic

        write_text_atomic(args.output, text)
        print(f"robot written to {args.output}")
    else:
        sys.stdout.write(text)
    tightness = f"union / part {ratio:.3f}"
    if args.plot:
        from kcplan.views.plots import plot_cover

        plot_cover(cover, args.plot, tightness)
        print(f"picture written to {args.plot}", file=report)
    if args.html:
        from kcplan.views.html import write_cover_html

        write_cover_html(cover, args.html)
        print(f"interactive view written to {args.html}", file=report)
    return 0


def run_info(args: argparse.Namespace) -> int:
    """``kcplan robot info``: what kcplan makes of a URDF arm (module docstring)."""
    import time
    from pathlib import Path

    import numpy as np

    from kcplan.arm import ArmError, load_arm
    from kcplan.arm.model import movable_joints, urdf_model
    from kcplan.arm.pairs import prove_pairs
    from kcplan.arm.srdf import read_srdf

    for key, path in (("urdf", args.urdf), ("srdf", args.srdf)):
        if path is not None and not Path(path).is_file():
            raise InputError(f"{path}: {key}: expected an existing {key.upper()} file")
    if args.group is not None and args.srdf is None:
        raise InputError("--group: expected --srdf (the SRDF that defines the group)")
    t0 = time.perf_counter()
    try:
        srdf = None if args.srdf is None else read_srdf(args.srdf)
        base = None if args.base is None else _base(args.base, srdf)
        full = None if srdf is None else urdf_model(args.urdf, base)  # the groups' joint tree
        if args.group is not None:
            joints = srdf.group_joints(args.group, full)
        else:  # every movable joint, in order (the base's first)
            joints = args.joints or movable_joints(args.urdf, base)
        arm = load_arm(args.urdf, joints, srdf=args.srdf, package_dirs=args.package_dir,
                       base=base)  # fmt: skip
    except ArmError as err:
        raise InputError(str(err)) from None
    took = time.perf_counter() - t0
    print(f"{args.urdf}: {arm.dof} joints in the group, {len(arm.bodies)} bodies "
          f"(links as their convex hulls), read in {took:.1f} s")  # fmt: skip
    if srdf is not None:
        _print_srdf(srdf, full, base)
    if base is not None:
        (xmin, xmax), (ymin, ymax) = base.bounds
        print(f"base {base.name}: planar, x in [{xmin:g}, {xmax:g}] m, y in [{ymin:g}, "
              f"{ymax:g}] m, at most {base.velocity[0]:g} m/s and {base.velocity[1]:g} rad/s; "
              f"joints {', '.join(base.joints)} (the yaw wraps)")  # fmt: skip
    print("joints (state order): name, kind, limits")
    wraps = [False] * arm.dof if arm.wraps is None else arm.wraps.tolist()
    for name, kind, lo, hi, wrap in zip(arm.joints, arm.kinds, arm.lower, arm.upper, wraps,
                                        strict=True):  # fmt: skip
        turn = " (an angle that wraps: any angle, edges the shorter way)" if wrap else ""
        print(f"  {name}: {kind} [{float(lo)!r}, {float(hi)!r}]{turn}")
    print("bodies: link, shape, bounding radius (m)")
    for body in arm.bodies:
        shape = "sphere" if body.hull is None else f"hull of {len(body.hull.vertices)} vertices"
        if body.hull is not None and body.hull.offset > 0:
            shape += f" (grown {body.hull.offset:.1e} m to hold every vertex)"
        print(f"  {body.link}: {shape}, {float(np.max(body.semi_axes)):.4f}")
    t0 = time.perf_counter()
    proofs = prove_pairs(arm)
    took = time.perf_counter() - t0
    source = "the SRDF leaves" if args.srdf else "not joined by a joint (no SRDF)"
    counts = {v: sum(p.verdict == v for p in proofs) for v in ("apart", "touches", "unknown")}
    print(f"self pairs {source}: {len(proofs)}; proven apart {counts['apart']} (never "
          f"checked), can touch {counts['touches']}, not decided {counts['unknown']} "
          f"(both checked); proofs in {took:.2f} s")  # fmt: skip
    for p in proofs:
        print(f"  {p.links[0]} / {p.links[1]}: {p.verdict}")
    from kcplan.arm.verify import ArmMeshChecker

    checker = ArmMeshChecker(arm, [])
    touching = list(dict.fromkeys(p.links for p in proofs if p.verdict == "touches"))
    always = checker.touching_everywhere(touching)  # a pair of several geometries: once
    if always:  # no plan can separate them: the SRDF misses them
        pairs = ", ".join(f"[{a}, {b}]" for a, b in always)
        print(f"in contact at every configuration tried (32 random ones within the limits): "
              f"{pairs}; a scenario must allow them: allowed: [{pairs}]")  # fmt: skip
    return 0


def _base(bounds: list[float], srdf):
    """``--base XMIN XMAX YMIN YMAX``: the planar base, named after the SRDF's planar
    virtual joint (else ``base``)."""
    from kcplan.arm.description import PlanarBase

    xmin, xmax, ymin, ymax = bounds
    if not (xmin < xmax and ymin < ymax) or not all(map(math.isfinite, bounds)):
        raise InputError(f"--base: expected XMIN < XMAX and YMIN < YMAX (metres), got {bounds}")
    planar = [] if srdf is None else [v.name for v in srdf.virtual_joints if v.kind == "planar"]
    return PlanarBase(planar[0] if planar else "base", ((xmin, xmax), (ymin, ymax)))


def _print_srdf(srdf, model, base=None) -> None:
    """The SRDF's planning groups (their joints, or why kcplan cannot plan one), named
    states and virtual joints, for ``kcplan robot info``."""
    from kcplan.arm import ArmError

    print(f"groups ({srdf.source}): name: joints, in state order")
    for name in srdf.groups:
        try:
            print(f"  {name}: {', '.join(srdf.group_joints(name, model))}")
        except ArmError as err:  # said, not fatal: another group may be the one asked
            # the message less its "SRDF: group 'NAME': " prefix, said on the line already
            reason = str(err).removeprefix(f"{srdf.source}: ").removeprefix(f"group {name!r}: ")
            print(f"  {name}: not plannable: {reason}")
    if srdf.states:
        states = ", ".join(f"{state} ({group})" for group, state in srdf.states)
        print(f"named states (group): {states}")
    for v in srdf.virtual_joints:
        print(
            f"virtual joint {v.name}: {v.kind}, {v.parent_frame} to {v.child_link}"
            + ("" if v.kind == "fixed" else " (planned: its joints "
               f"{', '.join(base.joints)})" if base is not None and base.name == v.name
               else " (kcplan plans the base fixed; --base, a scenario's robot.base, moves it)")
        )


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``kcplan robot`` (with its actions ``fit`` and ``info``) on the subcommand
    parsers."""
    p = sub.add_parser(
        "robot",
        help="make robots: fit ellipsoids that contain a mesh or outline; describe a URDF arm",
        description="Robots for kcplan scenarios.",
    )
    actions = p.add_subparsers(dest="action", required=True, parser_class=type(p))
    fit = actions.add_parser(
        "fit",
        help="cover a mesh (3D) or a polygon (2D) by ellipsoids that provably contain it",
        description="Cover a closed mesh (STL, OBJ, PLY, OFF, glTF) or a simple polygon (YAML "
        "list of [x, y], or CSV x,y rows) by K ellipsoids (ellipses) whose union provably "
        "contains it, and write them as a scenario's robot block (in the mesh's frame and "
        "unit times --scale). Exit 0 done, 2 bad input.",
    )
    fit.add_argument("mesh", metavar="MESH", help="mesh or outline file")
    count = fit.add_mutually_exclusive_group()
    count.add_argument(
        "--bodies", type=positive_int, metavar="K", help="number of bodies (default 4)"
    )
    count.add_argument(
        "--max-excess",
        type=positive_float,
        metavar="X",
        help="instead of --bodies: the fewest bodies whose total volume is at most (1 + X) "
        "times the part's",
    )
    fit.add_argument(
        "--max-offset",
        type=positive_float,
        metavar="D",
        help="cut until no body sticks out of the part by more than D (the part's unit "
        "times --scale; a proved bound), with --bodies as the most bodies (default "
        "32); 3D parts only",
    )
    fit.add_argument(
        "--scale", type=positive_float, default=1.0, help="multiply coordinates (default 1)"
    )
    fit.add_argument(
        "--hull",
        action="store_true",
        help="cover the mesh's convex hull (for meshes that are not closed)",
    )
    fit.add_argument("--spheres", action="store_true", help="fit spheres instead (for comparison)")
    fit.add_argument("-o", "--output", metavar="ROBOT.yaml", help="write the robot block here")
    fit.add_argument("--plot", metavar="FILE.png", help="draw the part and its cover")
    fit.add_argument("--html", metavar="FILE.html", help="write an interactive 3D view")
    fit.set_defaults(handler=run_fit)
    info = actions.add_parser(
        "info",
        help="what kcplan makes of a URDF arm: groups, joints, limits, bodies, self pairs",
        description="Read a URDF arm (Pinocchio) as kcplan plans it: the SRDF's groups, named "
        "states and virtual joints, the planning group's "
        "joints and limits, each link's body (its convex hull), and the self pairs: those "
        "proven apart over the joint box (never checked), those that can touch and those "
        "not decided (checked). Exit 0 done, 2 bad input.",
    )
    info.add_argument("urdf", metavar="URDF")
    info.add_argument("--srdf", metavar="SRDF",
                      help="its disabled pairs are never checked; its groups, named states "
                      "and virtual joints are listed")  # fmt: skip
    chosen = info.add_mutually_exclusive_group()
    chosen.add_argument("--joints", nargs="+", metavar="JOINT",
                        help="the planning group (default: every movable joint)")  # fmt: skip
    chosen.add_argument("--group", metavar="NAME", help="the planning group: a group of --srdf")
    info.add_argument("--package-dir", action="append", metavar="DIR",
                      help="a folder of packages of package:// mesh URIs (repeatable)")  # fmt: skip
    info.add_argument("--base", nargs=4, type=float, metavar=("XMIN", "XMAX", "YMIN", "YMAX"),
                      help="a planar base that drives within these bounds (metres), named "
                      "after the SRDF's planar virtual joint (else base): its joints NAME/x, "
                      "NAME/y, NAME/theta join the group")  # fmt: skip
    info.set_defaults(handler=run_info)
