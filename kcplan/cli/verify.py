"""``kcplan verify``: gap-free check of a path file."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from kcplan.cli.common import InputError, load_input, non_negative_float, positive_float


def _read_json(path: str) -> dict:
    try:
        data = json.loads(Path(path).read_text())
    except OSError as err:
        raise InputError(f"{path}: cannot read the file: {err.strerror or err}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise InputError(f"{path}: expected a JSON path file, got invalid JSON ({err})") from None
    return data


def _read_path(path: str, scenario, data: dict) -> np.ndarray:
    """The path file's states, checked against the scenario (poses, or an arm's joint
    vectors in its ``joints`` order)."""
    if not isinstance(data, dict) or "states" not in data:
        raise InputError(f"{path}: states: expected a JSON object with a 'states' list")
    arm = getattr(scenario, "arm", None)
    if arm is not None and data.get("joints") != list(arm.joints):
        raise InputError(
            f"{path}: joints: expected the scenario's planning group {list(arm.joints)}, "
            f"got {data.get('joints')!r}"
        )
    width = arm.dof if arm is not None else 3 if scenario.dimension == 2 else 7
    try:
        states = np.array(data["states"], dtype=float)
    except (TypeError, ValueError):
        states = np.zeros((0, 0))
    if states.ndim != 2 or states.shape[1] != width or len(states) < 1:
        what = "joint vectors" if arm is not None else "poses"
        raise InputError(
            f"{path}: states: expected a non-empty list of {what} with {width} numbers each "
            f"(scenario {scenario.source})"
        )
    if not np.isfinite(states).all():
        raise InputError(f"{path}: states: expected finite numbers")
    if scenario.dimension == 2:  # yaw in [-pi, pi), as OMPL and the scenario loader keep it
        from kcplan.geometry.pose import wrap_angle

        states[:, 2] = wrap_angle(states[:, 2])
    if data.get("dimension", scenario.dimension) != scenario.dimension:
        raise InputError(
            f"{path}: dimension: expected {scenario.dimension}, got {data['dimension']}"
        )
    return states


def run(args: argparse.Namespace) -> int:
    """Verify the path file against the scenario; exit 1 on a collision."""
    scenario = load_input(args.scenario)
    data = _read_json(args.path)
    if isinstance(data, dict) and "curve" in data and "states" not in data:
        return _verify_trajectory(args, scenario, data)
    states = _read_path(args.path, scenario, data)
    if getattr(scenario, "arm", None) is not None:
        return _verify_arm(args, scenario, states)
    from kcplan.planning.verify import verify_path
    from kcplan.world import CollisionWorld

    world = CollisionWorld(scenario)
    part = ""  # names the part in the report when --mesh checks it
    if args.mesh is not None:
        world, part = _part_world(args, scenario, world)
    check = verify_path(world, states, tolerance=args.tolerance, padding=_padding(args, scenario))
    edges = max(len(states) - 1, 1)
    if check.collides:
        pose = ", ".join(f"{v:.6g}" for v in check.first_collision)
        print(
            f"{_closer(args, scenario)}{f' of {part}' if part else ''} on edge "
            f"{check.edge_index} at "
            f"s = {check.s:.6f}: pose "
            f"[{pose}] ({check.queries} clearance queries)"
        )
        return 1
    print(
        f"clean: {f'{part}, ' if part else ''}{edges} edges checked without gaps, minimum "
        "clearance "
        f"{check.min_clearance:.6g}, {check.queries} clearance queries"
    )
    return 0


def _verify_arm(args: argparse.Namespace, scenario, states: np.ndarray) -> int:
    """An arm's path, on the links' own collision meshes (:mod:`kcplan.arm.verify`)."""
    from kcplan.arm.verify import verify_arm_path

    if args.mesh is not None:
        raise InputError(f"{args.scenario}: --mesh: an arm is checked on its own meshes")
    _within_limits(args.path, "states", scenario.arm, states)
    check = verify_arm_path(
        scenario.arm, scenario.obstacles, states, args.tolerance, allowed=scenario.allowed,
        padding=_padding(args, scenario), link_padding=scenario.link_padding,
    )  # fmt: skip
    if check.collides:
        edge, s = check.where
        print(f"{_closer(args, scenario)} of the links' meshes on edge {edge} at s = {s:.6f} "
              f"({check.queries} distance queries)")  # fmt: skip
        return 1
    edges = max(len(states) - 1, 1)
    print(f"clean: the links' meshes, {edges} edges checked without gaps, minimum "
          f"clearance {check.min_clearance:.6g}, {check.queries} distance queries")  # fmt: skip
    return 0


def _padding(args: argparse.Namespace, scenario) -> float:
    """``--padding``, else the scenario's ``robot.padding`` (an arm's links named in its
    ``robot.link_padding`` keep their own either way)."""
    return scenario.padding if args.padding is None else args.padding


def _closer(args: argparse.Namespace, scenario) -> str:
    """How a verdict names a pose nearer than the tolerance: a collision, or nearer than
    the padding when there is one."""
    padding = _padding(args, scenario)
    own = {k: v for k, v in getattr(scenario, "link_padding", {}).items() if v > 0}
    if own:
        links = ", ".join(f"{name} {value:g}" for name, value in sorted(own.items()))
        return f"CLOSER THAN THE PADDING {padding:g} ({links})"
    return f"CLOSER THAN THE PADDING {padding:g}" if padding > 0 else "COLLISION"


LIMIT_TOLERANCE = 1e-6
"""Relative: a sample's speed or acceleration up to this much above its limit passes."""
CURVE_TOLERANCE = 1e-9
"""Radians: a sample this far from the curve at its ``s`` is still on it."""


def _verify_trajectory(args: argparse.Namespace, scenario, data: dict) -> int:
    """A trajectory file of ``kcplan plan --trajectory``: its continuous curve on the
    links' own meshes (every piece, without gaps, :meth:`kcplan.arm.verify.ArmMeshChecker.
    check_pieces`), every sample on that curve and within the limits it states."""
    arm = getattr(scenario, "arm", None)
    if arm is None:
        return _verify_rigid_trajectory(args, scenario, data)
    if args.mesh is not None:
        raise InputError(f"{args.scenario}: --mesh: an arm is checked on its own meshes")
    from kcplan.arm.verify import ArmMeshChecker
    from kcplan.trajectory.certified import read_trajectory

    if data.get("joints") != list(arm.joints):
        raise InputError(f"{args.path}: joints: expected the scenario's planning group "
                         f"{list(arm.joints)}, got {data.get('joints')!r}")  # fmt: skip
    try:
        file = read_trajectory(data, arm.dof)
    except ValueError as err:
        raise InputError(f"{args.path}: {err}") from None
    _within_limits(args.path, "curve.waypoints", arm, file.path.waypoints)
    off = file.deviations()
    problems = _sample_problems(off)
    checker = ArmMeshChecker(
        arm, scenario.obstacles, scenario.allowed, args.tolerance, _padding(args, scenario)
    )
    check = checker.check_pieces(file.path.pieces())
    pieces = len(file.path.breakpoints) - 1
    if check.collides:
        piece, s = check.where
        problems.append(f"{_closer(args, scenario)} of the links' meshes ({check.what}) on "
                        f"piece {piece} of "
                        f"the curve at {s:.6f} of it")  # fmt: skip
    checked = (f"the links' meshes along the whole curve ({pieces} pieces, "
               f"{int((file.path.blends > 0).sum())} blends)")  # fmt: skip
    return _report(problems, checked, check, "distance", len(file.t), off)


def _within_limits(path: str, field: str, arm, states) -> None:
    """One line naming the first of an arm's ``states`` outside its joint limits."""
    outside = [k for k, q in enumerate(states) if not arm.within_limits(q)]
    if outside:
        raise InputError(f"{path}: {field}[{outside[0]}]: expected joint values within the "
                         "limits")  # fmt: skip


def _sample_problems(off: dict) -> list[str]:
    """What is wrong with a trajectory's samples (:meth:`TrajectoryFile.deviations`)."""
    problems = []
    if off["curve"] > CURVE_TOLERANCE:
        problems.append(f"a sample is {off['curve']:.3g} off the curve")
    if off["velocity"] > 1 + LIMIT_TOLERANCE:
        problems.append(f"a speed reaches {off['velocity']:.6f} of its limit")
    if off["acceleration"] > 1 + LIMIT_TOLERANCE:
        problems.append(f"an acceleration reaches {off['acceleration']:.6f} of its limit")
    if off["time"] <= 0 or off["parameter"] < 0:
        problems.append("the samples do not move forward in time and along the curve")
    return problems


def _verify_rigid_trajectory(args: argparse.Namespace, scenario, data: dict) -> int:
    """A rigid robot's trajectory file: its path gap-free (as a path file's), every sample
    on it and within its translational and angular limits."""
    from kcplan.planning.verify import verify_path
    from kcplan.trajectory.certified import POSE_NAMES, read_rigid_trajectory
    from kcplan.world import CollisionWorld

    n = scenario.dimension
    if data.get("joints") != list(POSE_NAMES[n]):
        raise InputError(f"{args.path}: joints: expected the pose of a {n}D rigid robot "
                         f"{list(POSE_NAMES[n])}, got {data.get('joints')!r}")  # fmt: skip
    try:
        file = read_rigid_trajectory(data, n)
    except ValueError as err:
        raise InputError(f"{args.path}: {err}") from None
    world = CollisionWorld(scenario)
    part = ""
    if args.mesh is not None:
        world, part = _part_world(args, scenario, world)
    off = file.deviations()
    problems = _sample_problems(off)
    check = verify_path(
        world, file.waypoints, tolerance=args.tolerance, padding=_padding(args, scenario)
    )
    if check.collides:
        problems.append(f"{_closer(args, scenario)}{f' of {part}' if part else ''} on edge "
                        f"{check.edge_index} "
                        f"at s = {check.s:.6f}")  # fmt: skip
    checked = f"{f'{part}, ' if part else ''}{len(file.waypoints) - 1} edges"
    return _report(problems, checked, check, "clearance", len(file.t), off)


def _report(problems: list[str], checked: str, check, kind: str, samples: int, off: dict) -> int:
    """Print a trajectory's verdict in one line; exit 1 with its problems, else 0."""
    if problems:
        print("; ".join(problems) + f" ({check.queries} {kind} queries)")
        return 1
    print(f"clean: {checked} checked without gaps, minimum clearance "
          f"{check.min_clearance:.6g}, {check.queries} {kind} queries; {samples} samples on "
          f"the curve (within {off['curve']:.1g}), peaks {off['velocity']:.6f} of the "
          f"velocity and {off['acceleration']:.6f} of the acceleration limits")  # fmt: skip
    return 0


def _part_world(args: argparse.Namespace, scenario, world):
    """The part of ``--mesh`` (the scenario's own mesh when given without a file)."""
    from kcplan.world.part import PartWorld

    if args.mesh == "":
        if scenario.part is None:
            raise InputError(
                f"{args.scenario}: --mesh: expected a mesh file, or a scenario whose robot "
                "is a mesh (robot.mesh); this robot is given as ellipsoids"
            )
        part = scenario.part
    else:
        from kcplan.cover import SolidError, read_solid

        try:
            part = read_solid(args.mesh, args.scale)
        except SolidError as err:
            raise InputError(str(err)) from None
        if part.dimension != scenario.dimension:
            raise InputError(
                f"{args.mesh}: --mesh: expected a {scenario.dimension}D part like "
                f"{args.scenario}, got {part.dimension}D"
            )
    return PartWorld(world, part), f"the part {part.describe()}"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``kcplan verify`` on the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "verify",
        help="check a path for collisions without gaps (conservative advancement)",
        description="Check every edge of a path, interpolated as OMPL does, with FCL "
        "clearances and conservative advancement (independent of the KC bounds). Exit 0 "
        "clean, 1 collision, 2 bad input.",
    )
    p.add_argument("scenario", metavar="SCENARIO", help="YAML scenario file")
    p.add_argument(
        "path",
        metavar="PATH.json",
        help="path file written by kcplan plan (-o), or a trajectory file (--trajectory): "
        "then its continuous curve, and its samples against the curve and the limits",
    )
    p.add_argument(
        "--tolerance",
        type=positive_float,
        default=1e-6,
        help="clearance below which a pose counts as colliding (default 1e-6)",
    )
    p.add_argument(
        "--padding",
        type=non_negative_float,
        metavar="P",
        help="clearance the path must keep from the obstacles, checked without gaps "
        "(default: the scenario's robot.padding, else 0)",
    )
    p.add_argument(
        "--mesh",
        nargs="?",
        const="",
        metavar="MESH",
        help="check the part's own mesh (or outline) instead of the robot's ellipsoids: "
        "the scenario's robot.mesh, or the file given (in the robot's frame)",
    )
    p.add_argument(
        "--scale",
        type=positive_float,
        default=1.0,
        help="with --mesh MESH: multiply its coordinates (default 1)",
    )
    p.set_defaults(handler=run)
