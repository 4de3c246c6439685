"""Kinematics of Containment: convex and geometric lower bounds, KC volumes.

Pure numpy/scipy; never imports ompl or fcl.
"""

from kcplan.kc.convex import ConvexLowerBound
from kcplan.kc.geometric import GeometricLowerBound
from kcplan.kc.volume import kc_volume

__all__ = ["ConvexLowerBound", "GeometricLowerBound", "kc_volume"]
