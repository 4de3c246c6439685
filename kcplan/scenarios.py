"""Scenario files of every robot kind: the one place that dispatches on the robot's kind.

A rigid robot's scenario (:class:`kcplan.world.Scenario`, format and reader in
:mod:`kcplan.world.scenario`) and an arm's (:class:`kcplan.arm.scenario.ArmScenario`,
:mod:`kcplan.arm.scenario`) share their file's YAML, their error messages and their
obstacles; this module reads either (:func:`load_scenario`, :func:`parse_scenario`),
checks that the start and the goal are free (:func:`check_start_goal`), accepts either
at the public entry points (:func:`as_scenario`) and writes either back
(:func:`dump_scenario`). Dependencies point one way: ``world`` knows no arm, ``arm``
builds on ``world``, this module on both.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from kcplan.arm.scenario import ArmScenario, arm_scenario_to_dict, parse_arm_scenario
from kcplan.world.scenario import (
    Scenario,
    ScenarioError,
    is_arm_data,
    parse_rigid_scenario,
    read_scenario_data,
    scenario_to_dict,
    write_scenario_yaml,
)

__all__ = ["as_scenario", "check_start_goal", "dump_scenario", "load_scenario", "parse_scenario"]


def check_start_goal(scenario: Scenario | ArmScenario) -> None:
    """Raise :class:`ScenarioError` naming what the robot touches at the start or the goal
    (``FILE: start: the robot collides with obstacles[3] (box)``; an arm's names the links,
    or the pair in contact everywhere with the line that allows it)."""
    if isinstance(scenario, ArmScenario):
        _check_arm(scenario)
        return
    from kcplan.world.collision import CollisionWorld

    world = CollisionWorld(scenario)
    for key, pose in (("start", scenario.start), ("goal", scenario.goal)):
        hits = world.colliding_obstacles(pose)
        if hits:
            labels = ", ".join(scenario.obstacles[i].label for i in hits[:3])
            raise ScenarioError(f"{scenario.source}: {key}: the robot collides with {labels}")


def _check_arm(scenario: ArmScenario) -> None:
    from kcplan.arm.verify import ArmMeshChecker
    from kcplan.arm.world import ArmWorld

    arm, obstacles = scenario.arm, scenario.obstacles
    # the compiled twin's query: python-fcl's scene of a point cloud costs seconds to build
    kernel = ArmWorld(arm, obstacles, allowed=scenario.allowed).kernel
    for key, q in (("start", scenario.start), ("goal", scenario.goal)):
        if not kernel.in_collision([float(v) for v in q]):
            continue
        checker = ArmMeshChecker(arm, obstacles, scenario.allowed)
        meshes = checker.check([q, q])
        if meshes.collides and meshes.pair and checker.contact_share(meshes.pair) == 1.0:
            a, b = meshes.pair
            raise ScenarioError(
                f"{scenario.source}: {key}: {a} and {b} touch at every configuration "
                f"tried (32 random ones within the limits): the SRDF does not disable "
                f"the pair; allow it in the scenario with allowed: [[{a}, {b}]]"
            )
        if meshes.collides:
            raise ScenarioError(
                f"{scenario.source}: {key}: the arm's links touch an obstacle or each "
                f"other (on their own collision meshes too): {meshes.what}"
            )
        hulls = any(b.hull is not None for b in arm.bodies)
        hint = (
            "robot.representation: ellipsoids with a small robot.max_offset may free it"
            if hulls
            else "robot.representation: hulls (the default) may free it"
        )
        what = "hulls touch" if hulls else "cover touches"
        raise ScenarioError(
            f"{scenario.source}: {key}: the arm's {what} an obstacle or itself, its "
            f"meshes do not ({hint})"
        )


def parse_scenario(
    data: Any, source: str = "<string>", directory: Path | None = None, check: bool = True
) -> Scenario | ArmScenario:
    """Build the scenario parsed YAML describes: an arm's when its robot names a ``urdf``
    or an ``example`` (:func:`kcplan.arm.scenario.parse_arm_scenario`), else a rigid
    robot's (:func:`kcplan.world.scenario.parse_rigid_scenario`); then (``check``)
    :func:`check_start_goal`.

    Raises
    ------
    ScenarioError
        One line naming the source, the field and what was expected.
    """
    directory = Path.cwd() if directory is None else directory
    if is_arm_data(data):
        scenario = parse_arm_scenario(data, source, directory)
    else:
        scenario = parse_rigid_scenario(data, source, directory)
    if check:
        check_start_goal(scenario)
    return scenario


def load_scenario(path: str | os.PathLike, check: bool = True) -> Scenario | ArmScenario:
    """Read, validate and (``check``) check a scenario file of any robot.

    Raises
    ------
    ScenarioError
        For every problem with the file (unreadable, too large, not YAML, YAML syntax
        errors with line and column, every invalid field) and, with ``check``, a start
        or goal in collision.
    """
    data, source, directory = read_scenario_data(path)
    return parse_scenario(data, source, directory, check)


def as_scenario(
    value: Scenario | ArmScenario | str | os.PathLike, rigid: bool = False
) -> Scenario | ArmScenario:
    """The scenario a public entry point was given: ``value`` itself when it is a
    scenario, the file it names when it is a path (``str`` or ``os.PathLike``, read by
    :func:`load_scenario`). ``rigid``: the caller handles rigid robots only.

    Raises
    ------
    TypeError
        For anything else, saying what is expected, and for an arm when ``rigid``.
    ScenarioError
        For a path whose file is not a valid scenario.
    """
    if isinstance(value, (str, os.PathLike)):
        value = load_scenario(value)
    if isinstance(value, ArmScenario) and rigid:
        raise TypeError(
            f"scenario: {value.source}: expected a rigid robot of ellipsoids, got an "
            f"{value.arm.describe()} (an arm's scene is a kcplan.arm.ArmWorld)"
        )
    if isinstance(value, (Scenario, ArmScenario)):
        return value
    raise TypeError(
        "scenario: expected a kcplan Scenario or the path of a scenario file (str or "
        f"os.PathLike), got {type(value).__name__}"
    )


def dump_scenario(scenario: Scenario | ArmScenario | dict, path: str | os.PathLike) -> None:
    """Write a scenario (or its plain data) as YAML, atomically (temporary file, then
    rename)."""
    if isinstance(scenario, dict):
        data = scenario
    elif isinstance(scenario, ArmScenario):
        data = arm_scenario_to_dict(scenario)
    else:
        data = scenario_to_dict(scenario)
    write_scenario_yaml(data, path)
