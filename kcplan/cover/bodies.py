"""Robot bodies as point sets: conversion from enclosing ellipsoids, membership, volume.

A :class:`kcplan.geometry.robot.Body` (semi-axes and a pose in the robot's frame) is the
ellipsoid ``{x : (x - p)^T M (x - p) <= 1}`` with ``M = R diag(1 / a^2) R^T``;
:func:`body_matrix` computes ``M`` from the very numbers a scenario stores, so a check
with it is a check of the robot the planner uses.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from kcplan.geometry.enclosing import ellipsoid_axes, frame_norm_sq
from kcplan.geometry.pose import quaternion_matrix
from kcplan.geometry.robot import Body
from kcplan.geometry.rotations import exp_rotation

__all__ = [
    "body_bounds",
    "body_from_ellipsoid",
    "body_holds",
    "body_matrix",
    "body_rotation",
    "inside_union",
    "union_volume",
]


def body_from_ellipsoid(center: ArrayLike, M: ArrayLike, sphere: bool = False) -> Body:
    """The body ``{x : (x - c)^T M (x - c) <= 1}``; ``sphere`` stores a ball (``M`` a
    multiple of the identity) with the identity orientation."""
    c = np.asarray(center, dtype=float)
    n = len(c)
    a, R = ellipsoid_axes(M)
    if sphere:
        a, R = np.full(n, a.max()), np.eye(n)
    if n == 2:
        pose = np.append(c, math.atan2(R[1, 0], R[0, 0]))
    else:
        q = Rotation.from_matrix(R).as_quat()  # [x, y, z, w]
        pose = np.concatenate([c, q / np.linalg.norm(q)])
    return Body(a, pose)


def body_matrix(body: Body) -> NDArray[np.float64]:
    """The shape matrix ``M = R diag(1 / a^2) R^T`` of a body, shape ``(n, n)``."""
    R = body_rotation(body)
    return R @ np.diag(1.0 / body.semi_axes**2) @ R.T


def body_rotation(body: Body) -> NDArray[np.float64]:
    """The body's orientation ``R`` in the robot frame, from its stored yaw or quaternion."""
    return (
        exp_rotation([body.pose[2]], 2) if body.dimension == 2 else quaternion_matrix(body.pose[3:])
    )


def body_bounds(body: Body) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The body's axis-aligned bounding box in the robot frame, ``(low, high)``: the half
    side along axis ``i`` is ``|row i of R diag(a)|``."""
    half = np.linalg.norm(body_rotation(body) * body.semi_axes, axis=1)
    return body.position - half, body.position + half


def body_holds(body: Body, points: ArrayLike) -> float:
    """The largest ``|diag(1/a) R^T (x - p)|^2`` of the points, in the body's own frame as
    stored (semi-axes, position, yaw or quaternion): at most 1 when the body holds them
    all."""
    X = np.asarray(points, dtype=float) - body.position
    return float(frame_norm_sq(X, body.semi_axes, body_rotation(body)).max())


def inside_union(points: ArrayLike, bodies: tuple[Body, ...] | list[Body]) -> NDArray[np.bool_]:
    """Whether each point lies in some body, shape ``(m,)``."""
    P = np.asarray(points, dtype=float)
    out = np.zeros(len(P), dtype=bool)
    for body in bodies:
        out |= frame_norm_sq(P - body.position, body.semi_axes, body_rotation(body)) <= 1.0
    return out


def union_volume(
    bodies: tuple[Body, ...] | list[Body], samples: int = 400_000, seed: int = 0
) -> tuple[float, float]:
    """Monte Carlo volume (area in 2D) of the union of bodies and its standard error.

    Uniform samples in the union's bounding box; the standard error is
    ``box * sqrt(f (1 - f) / samples)`` for the fraction ``f`` inside.
    """
    boxes = np.array([body_bounds(body) for body in bodies])  # (k, 2, n)
    low, high = boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)
    box = float(np.prod(high - low))
    rng = np.random.default_rng(seed)
    f = float(inside_union(rng.uniform(low, high, (samples, len(low))), bodies).mean())
    return box * f, box * math.sqrt(f * (1.0 - f) / samples)
