"""``kcplan plan``: plan a path, print its counters, write it and its picture."""

from __future__ import annotations

import argparse
import json
import math

from kcplan.cli.common import (
    InputError,
    duration,
    load_input,
    non_negative_float,
    output_file,
    planner_name,
    positive_float,
)


def _print_counters(counters: dict) -> None:
    keys = [
        "fcl_queries",
        "collision_queries",
        "distance_queries",
        "region_queries",
        "region_pairs",
        "checker_calls",
    ]
    print("fcl queries     : " + ", ".join(f"{k} {counters[k]}" for k in keys if k in counters))
    kc = {k[3:]: v for k, v in counters.items() if k.startswith("kc_")}
    if kc:
        print("kc validator    : " + ", ".join(f"{k} {v}" for k, v in kc.items()))


def run(args: argparse.Namespace) -> int:
    """Plan, print the result and counters, write ``-o``, ``--plot``, ``--animate`` and
    ``--html``; exit 1 when not solved."""
    output_file(args.output, "-o")
    output_file(args.plot, "--plot", (".png",))
    output_file(args.animate, "--animate", (".gif",))
    output_file(args.html, "--html", (".html",))
    output_file(args.trajectory, "--trajectory", (".json", ".csv"))
    output_file(args.velocity_plot, "--velocity-plot", (".png",))
    scenario = load_input(args.scenario)
    arm = getattr(scenario, "arm", None) is not None
    if args.planner is None:
        from kcplan.planning.names import default_planner

        args.planner = default_planner(arm)
    limits = _trajectory_limits(args, scenario, arm)
    if arm and args.guards:
        raise InputError(
            f"{args.scenario}: --guards: not available for arms (their edges are certified "
            "per link)"
        )
    for option in ("show_cover", "meshes"):
        if not arm and getattr(args, option) not in (False, "auto"):
            flag = "--" + option.replace("_", "-")
            raise InputError(f"{args.scenario}: {flag}: only for arms (a URDF robot)")
    if arm and args.meshes == "visual" and (args.plot or args.animate or args.html):
        from kcplan.views.arm import visual_meshes_missing

        reason = visual_meshes_missing(scenario.arm)
        if reason:
            raise InputError(f"{args.scenario}: --meshes visual: {reason}")
    from kcplan.planning.names import check_planner_for
    from kcplan.planning.problem import PLANNERS, plan

    try:  # an arm-only planner on a rigid robot, the paper's on several bodies: one line, exit 2
        check_planner_for(args.planner, scenario)
    except ValueError as err:
        raise InputError(f"{args.scenario}: --planner: {err}") from None
    velocity, acceleration = limits if limits is not None else (None, None)
    if args.padding is not None and args.padding > 0 and not PLANNERS[args.planner].kc:
        raise InputError(f"{args.scenario}: --padding: kept by the kc-* and ca-* planners "
                         f"only (edges certified); {args.planner} checks samples")  # fmt: skip
    try:
        result = plan(scenario, args.planner, args.time, args.seed, args.simplify,
                      trajectory=limits is not None, velocity_limits=velocity,
                      acceleration_limits=acceleration, padding=args.padding)  # fmt: skip
    except ValueError as err:
        if not str(err).startswith("padding:"):
            raise
        raise InputError(f"{args.scenario}: --{err}") from None
    status = "solved" if result.solved else "NOT solved"
    print(
        f"{scenario.name}: {status} by {args.planner} in {duration(result.time)} "
        f"(simplification {duration(result.simplify_time)})"
    )
    if result.solved:
        print(f"path            : {len(result.states)} states, length {result.length:.4g}")
    for ob in scenario.obstacles:
        if getattr(ob, "cloud", None) is not None:
            print(f"{ob.label:<16}: {ob.cloud.summary()}")
    print("time split      : " + ", ".join(f"{k} {duration(v)}" for k, v in result.timing.items()))
    _print_counters(result.counters)
    if args.output:
        from kcplan.files import write_text_atomic

        write_text_atomic(args.output, json.dumps(result.to_json(), indent=1) + "\n")
        print(f"path written to {args.output}")
    timed = result.trajectory
    if timed is not None:
        _write_trajectory(args, timed)
    if args.plot and arm:
        from kcplan.views.plots import plot_arm

        source = plot_arm(scenario, args.plot, result.states if result.solved else None,
                          title=f"{scenario.name}: {args.planner}, {status}",
                          show_cover=args.show_cover, meshes=args.meshes)  # fmt: skip
        print(f"plot written to {args.plot} (links: {source})")
    elif args.plot:
        from kcplan.views.plots import plot_path

        guards = None
        if args.guards and result.solved:
            guards = path_guards(scenario, result.states)
        plot_path(
            scenario,
            result.states,
            args.plot,
            guards=guards,
            title=f"{scenario.name}: {args.planner}, {status}",
        )
        print(f"plot written to {args.plot}")
    if args.animate and result.solved and arm:
        from kcplan.views.animation import animate_arm

        states, fps = result.states, 10
        if timed is not None:  # in real time: one frame every 1 / fps seconds
            states = timed.timed.sample(fps)[2]
        frames = animate_arm(scenario, states, args.animate,
                             title=f"{scenario.name}: {args.planner}",
                             show_cover=args.show_cover, meshes=args.meshes,
                             fps=fps, timed=timed is not None)  # fmt: skip
        print(f"animation written to {args.animate} ({frames} frames)")
    elif args.animate and result.solved:
        from kcplan.views.animation import animate_path

        frames = animate_path(
            scenario, result.states, args.animate, title=f"{scenario.name}: {args.planner}"
        )
        print(f"animation written to {args.animate} ({frames} frames)")
    if args.html:
        from kcplan.views.html import write_scene_html

        states = result.states if result.solved else None
        frame_ms = None
        if timed is not None:  # in real time: 25 frames a second
            states, frame_ms = timed.timed.sample(25.0)[2], 40
        source = write_scene_html(scenario, args.html, states, args.show_cover, args.meshes,
                                  frame_ms=frame_ms)  # fmt: skip
        links = f" (links: {source})" if source else ""
        print(f"interactive view written to {args.html}{links}")
    return 0 if result.solved else 1


def _trajectory_limits(args: argparse.Namespace, scenario, arm: bool):
    """``(velocity limits, acceleration limits)`` for ``--trajectory``, checked before
    planning (None without it)."""
    wants = args.trajectory or args.velocity_plot
    if not wants:
        for flag in ("acceleration_limit", "speed_limit"):
            if getattr(args, flag) is not None:
                name = "--" + flag.replace("_", "-")
                raise InputError(f"{args.scenario}: {name}: only with --trajectory")
        return None
    if not args.planner.startswith(("kc-", "ca-")):
        raise InputError(f"{args.scenario}: --trajectory: expected a kc-* or ca-* planner, "
                         f"whose edges are certified, got {args.planner}")  # fmt: skip
    if arm and args.speed_limit is not None:
        raise InputError(f"{args.scenario}: --speed-limit: a rigid robot's; an arm's joint "
                         "velocity limits are its URDF's")  # fmt: skip
    from kcplan.trajectory.certified import joint_limits, rigid_limits

    given = {}
    for flag in ("speed_limit", "acceleration_limit"):
        value = getattr(args, flag)
        if value is not None:
            try:
                numbers = [float(x) for x in value.split(",")]
            except ValueError:
                numbers = [math.nan]
            given[flag] = numbers[0] if len(numbers) == 1 and arm else numbers
    try:
        if arm:
            return joint_limits(scenario.arm, None, given.get("acceleration_limit"))
        return rigid_limits(given.get("speed_limit"), given.get("acceleration_limit"))
    except ValueError as err:
        flag = ("--acceleration-limit" if "acceleration" in str(err) else
                "--speed-limit" if not arm else "robot.urdf")  # fmt: skip
        raise InputError(f"{args.scenario}: {flag}: {err}") from None


def _write_trajectory(args: argparse.Namespace, timed) -> None:
    """``--trajectory`` (JSON or CSV) and ``--velocity-plot``, and a line about each."""
    from kcplan.files import write_text_atomic

    t = timed.timed
    rv, ra = t.peak_ratios()
    certificate = getattr(timed, "certificate", None)
    how = (f"{certificate.summary()['blends']} certified blends" if certificate is not None
           else "stopping at every corner (rigid robot: no blends)")  # fmt: skip
    print(f"trajectory      : {t.duration:.3f} s ({timed.stop_duration:.3f} s stopping at "
          f"every corner), {how}, peak {rv:.3f} of the velocity and {ra:.3f} of the "
          f"acceleration limits, ready in {timed.seconds:.3f} s")  # fmt: skip
    if args.trajectory:
        if args.trajectory.lower().endswith(".csv"):
            write_text_atomic(args.trajectory, timed.csv(args.rate))
        else:
            write_text_atomic(args.trajectory, json.dumps(timed.document(args.rate)) + "\n")
        print(f"trajectory written to {args.trajectory} ({args.rate:g} samples a second)")
    if args.velocity_plot:
        from kcplan.views.plots import plot_joint_velocities

        plot_joint_velocities(timed, args.velocity_plot)
        print(f"velocities plotted in {args.velocity_plot}")


def path_guards(scenario, states) -> list:
    """The guards (pose, inflation) that certify each edge of a path, for plotting."""
    from kcplan.certification.certifier import EdgeCertifier
    from kcplan.world import CollisionWorld

    certifier = EdgeCertifier(CollisionWorld(scenario))
    certifier.guard_log = []
    for p, q in zip(states[:-1], states[1:], strict=True):
        certifier.check(p, q)
    return certifier.guard_log


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``kcplan plan`` on the subcommand parsers ``sub``."""
    from kcplan.planning.names import DEFAULT_ARM_PLANNER, DEFAULT_PLANNER, PLANNER_NAMES

    p = sub.add_parser(
        "plan",
        help="plan a path with a stock OMPL planner, with or without KC certificates",
        description="Plan from start to goal. Exit 0 solved, 1 not solved in time, 2 bad input.",
    )
    p.add_argument("scenario", metavar="SCENARIO", help="YAML scenario file")
    p.add_argument(
        "--planner",
        default=None,
        type=planner_name,
        metavar="PLANNER",
        help=f"planner (default {DEFAULT_PLANNER}, for an arm {DEFAULT_ARM_PLANNER}): "
        f"{', '.join(PLANNER_NAMES)}",
    )
    p.add_argument(
        "--time",
        type=positive_float,
        default=10.0,
        metavar="SECONDS",
        help="planning time limit (default 10)",
    )
    p.add_argument("--seed", type=int, help="OMPL random seed, for reproducible runs")
    p.add_argument(
        "--padding",
        type=non_negative_float,
        metavar="P",
        help="clearance every certified edge keeps from every obstacle and point, in the "
        "scenario's unit (default: the scenario's robot.padding, else 0)",
    )
    p.add_argument(
        "--simplify",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="simplify the path (every new edge is validated again; default on)",
    )
    p.add_argument("-o", "--output", metavar="PATH.json", help="write the path as JSON")
    p.add_argument("--plot", metavar="FILE.png", help="draw the map and the path")
    p.add_argument("--guards", action="store_true", help="also draw the guards certifying the path")
    p.add_argument(
        "--animate", metavar="FILE.gif", help="write a GIF of the robot moving along the path"
    )
    p.add_argument(
        "--html",
        metavar="FILE.html",
        help="write an interactive 3D view (one self-contained HTML file, works offline)",
    )
    p.add_argument(
        "--trajectory",
        metavar="TRAJ.json",
        help="kc-*/ca-* planners: an arm's path smoothed with certified blends and timed "
        "within its joint limits (TOPP-RA), a rigid robot's timed edge by edge within "
        "--speed-limit and --acceleration-limit; written sampled (.json, or .csv); "
        "--animate and --html then play an arm's in real time",
    )
    p.add_argument(
        "--rate",
        type=positive_float,
        default=100.0,
        metavar="HZ",
        help="samples per second of --trajectory (default 100)",
    )
    p.add_argument(
        "--acceleration-limit",
        metavar="A[,A...]",
        help="acceleration limits of --trajectory: an arm's, rad/s^2, one for every joint or "
        "one per joint (default: twice each joint's URDF velocity limit per second); a "
        "rigid robot's, translational and angular (default 2,2)",
    )
    p.add_argument(
        "--speed-limit",
        metavar="V[,W]",
        help="a rigid robot's translational (length unit/s) and angular (rad/s) speed "
        "limits for --trajectory (default 1,1)",
    )
    p.add_argument(
        "--velocity-plot",
        metavar="FILE.png",
        help="plot the trajectory's joint velocities and accelerations against their limits",
    )
    add_arm_view_options(p)
    p.set_defaults(handler=run)


def add_arm_view_options(p: argparse.ArgumentParser) -> None:
    """``--show-cover`` and ``--meshes``, the options of an arm's pictures."""
    p.add_argument(
        "--show-cover",
        action="store_true",
        help="arms: also draw the ellipsoids covering the links (in the HTML view: shown at "
        "first; a switch in the page shows or hides them)",
    )
    p.add_argument(
        "--meshes",
        choices=("auto", "visual", "collision"),
        default="auto",
        help="arms: draw the links from the URDF's visual meshes or its collision meshes "
        "(default auto: visual when every visual mesh can be read)",
    )
