"""The world a robot moves in: obstacles, sensed clouds, meshes, the scenario reader every
format shares, rigid robots' scenario files (YAML) and the FCL collision world.

:mod:`.fields` (a file's YAML, one-line field errors) and :mod:`.obstacles` (obstacles,
clouds and depth images, the self filter) lie below both scenario formats, the rigid
robots' (:mod:`.scenario`) and the arms' (:mod:`kcplan.arm.scenario`). Independent of
OMPL and of arms; the only modules that import python-fcl are :mod:`.collision` and its
helpers. Scenario files of every robot kind are read by :mod:`kcplan.scenarios`.
"""

from kcplan.world.collision import CollisionWorld
from kcplan.world.fields import ScenarioError
from kcplan.world.obstacles import Obstacle
from kcplan.world.scenario import DEFAULT_INFLATION, Scenario, scenario_to_dict

__all__ = [
    "DEFAULT_INFLATION",
    "CollisionWorld",
    "Obstacle",
    "Scenario",
    "ScenarioError",
    "scenario_to_dict",
]
