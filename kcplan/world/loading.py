"""Loading a scenario for planning: parse it, then check its start and goal in the world.

:mod:`kcplan.world.scenario` reads and validates the file alone (it never needs FCL);
this module adds the one check that does, that the robot at the start and at the goal
touches no obstacle, so that the format and the collision world depend on each other in
one direction only (scenario <- collision <- loading).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from kcplan.world import scenario as scenario_format
from kcplan.world.collision import CollisionWorld
from kcplan.world.scenario import Scenario, ScenarioError

__all__ = ["check_start_goal", "load_scenario", "parse_scenario"]


def check_start_goal(scenario: Scenario) -> None:
    """Raise :class:`ScenarioError` naming the obstacles the robot touches at the start or
    the goal (``FILE: start: the robot collides with obstacles[3] (box)``)."""
    if not isinstance(scenario, Scenario):  # an arm
        from kcplan.arm.verify import ArmMeshChecker
        from kcplan.arm.world import ArmWorld

        arm, obstacles = scenario.arm, scenario.obstacles
        arm_world = ArmWorld(arm, obstacles, allowed=scenario.allowed)
        for key, q in (("start", scenario.start), ("goal", scenario.goal)):
            if not arm_world.in_collision(q):
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
        return
    world = CollisionWorld(scenario)
    for key, pose in (("start", scenario.start), ("goal", scenario.goal)):
        hits = world.colliding_obstacles(pose)
        if hits:
            labels = ", ".join(scenario.obstacles[i].label for i in hits[:3])
            raise ScenarioError(f"{scenario.source}: {key}: the robot collides with {labels}")


def parse_scenario(
    data: Any, source: str = "<string>", directory: Path | None = None, check: bool = True
) -> Scenario:
    """:func:`kcplan.world.scenario.parse_scenario`, then (``check``)
    :func:`check_start_goal`."""
    scenario = scenario_format.parse_scenario(data, source, directory)
    if check:
        check_start_goal(scenario)
    return scenario


def load_scenario(path: str | os.PathLike, check: bool = True) -> Scenario:
    """:func:`kcplan.world.scenario.load_scenario`, then (``check``)
    :func:`check_start_goal`.

    Raises
    ------
    ScenarioError
        For every problem with the file (see :func:`kcplan.world.scenario.load_scenario`)
        and, with ``check``, a start or goal in collision.
    """
    scenario = scenario_format.load_scenario(path)
    if check:
        check_start_goal(scenario)
    return scenario
