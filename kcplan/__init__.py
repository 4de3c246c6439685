"""kcplan: motion planning for robots made of ellipsoids, with edges certified by the
Kinematics of Containment (Ruan, Ding, Ma, Chirikjian).

>>> from kcplan import load_scenario, plan
>>> result = plan(load_scenario("scenarios/2d/l_turn.yaml"), time_limit=5, seed=1)
>>> result.solved, result.verify().collides
(True, False)

KC coordinates are ``xi = [theta, x, y]`` (2D) and ``xi = [w1, w2, w3, x, y, z]`` (3D):
the robot's pose relative to its guard, rotation as exponential coordinates.
"""

from kcplan.geometry import Robot, containment_margin, first_order_margin
from kcplan.kc import ConvexLowerBound, GeometricLowerBound, kc_volume

__version__ = "0.1.0"

__all__ = [
    "CollisionWorld",
    "ConvexLowerBound",
    "KCMotionValidator",
    "PlanResult",
    "Robot",
    "load_scenario",
    "plan",
    "GeometricLowerBound",
    "containment_margin",
    "first_order_margin",
    "kc_volume",
]


def __getattr__(name: str):
    # OMPL and FCL load only when their parts are used, so the mathematics stays light.
    if name == "KCMotionValidator":
        from kcplan.planning.validator import KCMotionValidator

        return KCMotionValidator
    if name in ("plan", "PlanResult"):
        import kcplan.planning.problem

        return getattr(kcplan.planning.problem, name)
    if name == "CollisionWorld":
        from kcplan.world import CollisionWorld

        return CollisionWorld
    if name == "load_scenario":
        from kcplan.scenarios import load_scenario

        return load_scenario
    raise AttributeError(f"module 'kcplan' has no attribute {name!r}")
