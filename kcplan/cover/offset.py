"""How far a cover sticks out of its part: the largest distance from a point of the
cover to the part.

A cover that holds a gripper's finger may still stick out of it by centimetres, and a
grasp that leaves the finger a few millimetres from an object is then invalid for the
covered robot (issue 25: MotionBenchMaker's goals leave the Panda's hand and fingers
9-32 mm from the objects). Volume does not see this; the offset does.

The offset is *estimated* from samples (it is an objective for choosing covers, not a
bound any certificate relies on): points on every body's surface, those outside the part
(winding number below 1/2, :func:`kcplan.geometry.winding.winding_numbers`), and their
distance to the part's boundary triangles (``trimesh.triangles.closest_point``). The
true offset is at least the estimate; with ``samples`` points per body the gap shrinks
like the spacing of the samples on the body.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from trimesh.triangles import closest_point

from kcplan.cover.bodies import body_rotation
from kcplan.cover.solid import Solid
from kcplan.geometry.robot import Body
from kcplan.geometry.winding import winding_numbers

__all__ = ["cover_offsets"]

_PAIRS = 2**20
"""Point-triangle pairs measured at once (bounds the temporary arrays)."""


def _surface(body: Body, samples: int, rng: np.random.Generator) -> NDArray[np.float64]:
    u = rng.normal(size=(samples, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return (u * body.semi_axes) @ body_rotation(body).T + body.position


def _distances(points: NDArray[np.float64], triangles: NDArray[np.float64]) -> NDArray:
    """Distance from each point to the nearest of the triangles, shape ``(len(points),)``."""
    out = np.full(len(points), np.inf)
    per = max(1, _PAIRS // len(triangles))
    for start in range(0, len(points), per):
        P = points[start : start + per]
        pairs_t = np.repeat(triangles[None], len(P), axis=0).reshape(-1, 3, 3)
        pairs_p = np.repeat(P, len(triangles), axis=0)
        d = np.linalg.norm(closest_point(pairs_t, pairs_p) - pairs_p, axis=1)
        out[start : start + per] = d.reshape(len(P), len(triangles)).min(axis=1)
    return out


def cover_offsets(
    solid: Solid, bodies: tuple[Body, ...] | list[Body], samples: int = 400, seed: int = 0
) -> NDArray[np.float64]:
    """How far each body sticks out of the part (3D), estimated from ``samples`` points
    on its surface: shape ``(len(bodies),)``, in the part's unit (0 for a body inside).

    Raises
    ------
    ValueError
        For a 2D part (outlines are not measured).
    """
    if solid.dimension != 3:
        raise ValueError(f"solid: expected a 3D part, got {solid.dimension}D")
    rng = np.random.default_rng(seed)
    triangles = np.asarray(solid.boundary, dtype=float)
    out = np.zeros(len(bodies))
    for k, body in enumerate(bodies):
        points = _surface(body, samples, rng)
        outside = points[winding_numbers(points, triangles) < 0.5]
        if len(outside):
            out[k] = float(_distances(outside, triangles).max())
    return out
