"""kcplan: motion planning for ellipsoidal robots with edges certified by the
Kinematics of Containment (Ruan, Ding, Ma, Chirikjian).

KC coordinates are ``xi = [theta, x, y]`` (2D) and ``xi = [w1, w2, w3, x, y, z]`` (3D):
the robot's pose relative to its guard, rotation as exponential coordinates.
"""

from kcplan.geometry import containment_margin, first_order_margin
from kcplan.kc import ConvexLowerBound, GeometricLowerBound, kc_volume

__version__ = "0.1.0"

__all__ = [
    "ConvexLowerBound",
    "GeometricLowerBound",
    "containment_margin",
    "first_order_margin",
    "kc_volume",
]
