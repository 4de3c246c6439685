"""Scenario files (YAML) and the FCL collision world.

Independent of OMPL; the only module that imports python-fcl is :mod:`.collision`.
"""

from kcplan.world.collision import CollisionWorld
from kcplan.world.loading import check_start_goal, load_scenario, parse_scenario
from kcplan.world.scenario import (
    DEFAULT_INFLATION,
    Obstacle,
    Scenario,
    ScenarioError,
    dump_scenario,
    scenario_to_dict,
)

__all__ = [
    "DEFAULT_INFLATION",
    "CollisionWorld",
    "Obstacle",
    "Scenario",
    "ScenarioError",
    "check_start_goal",
    "dump_scenario",
    "load_scenario",
    "parse_scenario",
    "scenario_to_dict",
]
