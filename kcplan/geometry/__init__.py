"""Ellipsoid geometry: rotations, exact containment margin, Minkowski differences.

Pure numpy/scipy; never imports ompl or fcl.
"""

from kcplan.geometry.containment import (
    containment_margin,
    first_order_margin,
    linearised_margin,
    max_affine_norm,
    ray_extent,
)
from kcplan.geometry.ellipsoid import as_inflation, as_semi_axes, guard_semi_axes
from kcplan.geometry.minkowski import centred_margin, radial_extent, sphere_frames
from kcplan.geometry.robot import Body, Robot
from kcplan.geometry.rotations import exp_rotation, hat, kc_dimension, log_rotation

__all__ = [
    "Body",
    "Robot",
    "as_inflation",
    "as_semi_axes",
    "centred_margin",
    "containment_margin",
    "exp_rotation",
    "first_order_margin",
    "guard_semi_axes",
    "hat",
    "kc_dimension",
    "linearised_margin",
    "log_rotation",
    "max_affine_norm",
    "radial_extent",
    "ray_extent",
    "sphere_frames",
]
