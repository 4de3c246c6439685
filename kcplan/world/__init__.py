"""Rigid robots' scenario files (YAML) and the FCL collision world.

Independent of OMPL and of arms; the only module that imports python-fcl is
:mod:`.collision`. Scenario files of every robot kind are read by :mod:`kcplan.scenarios`.
"""

from kcplan.world.collision import CollisionWorld
from kcplan.world.scenario import (
    DEFAULT_INFLATION,
    Obstacle,
    Scenario,
    ScenarioError,
    scenario_to_dict,
)

__all__ = [
    "DEFAULT_INFLATION",
    "CollisionWorld",
    "Obstacle",
    "Scenario",
    "ScenarioError",
    "scenario_to_dict",
]
