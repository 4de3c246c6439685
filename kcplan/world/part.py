"""Clearance of a robot's own part (its mesh or outline), not of the ellipsoids covering it.

A robot fitted to a mesh (``robot: {mesh: ...}``, :mod:`kcplan.cover`) plans with its
cover; :class:`PartWorld` measures the part itself with python-fcl, so that
``kcplan verify --mesh`` shows the part, not only its cover, free along a path. The part
moves rigidly with the robot frame (the mesh's frame is the robot's).

* 3D: the part's triangles as one ``fcl.BVHModel``. A surface can be at a positive
  distance from an obstacle that lies wholly *inside* the part, so
  :meth:`PartWorld.encloses_obstacle` tests one point of every obstacle against the part
  (winding number); along a path no obstacle can enter without the surface touching it,
  so the first pose suffices.
* 2D: the polygon's convex pieces as prisms, like planar obstacles
  (:mod:`kcplan.world.collision`); solid, so nothing can hide inside.
"""

from __future__ import annotations

import math

import fcl
import numpy as np
from numpy.typing import ArrayLike

from kcplan.geometry.polygon import convex_pieces
from kcplan.geometry.pose import pose_frame, pose_size
from kcplan.geometry.winding import winding_numbers
from kcplan.world.collision import CollisionWorld, polygon_prism

__all__ = ["PartWorld"]


class PartWorld:
    """Safe clearances of a part (:class:`kcplan.cover.Solid`) at robot poses.

    Parameters
    ----------
    world : CollisionWorld
        The scenario's obstacles (its robot is not used).
    part : Solid
        In the robot's frame, same dimension as the world.

    Attributes
    ----------
    reach : float
        The largest distance of a point of the part from the robot's origin (a vertex).
    """

    def __init__(self, world: CollisionWorld, part):
        if part.dimension != world.dimension:
            raise ValueError(f"part: expected a {world.dimension}D part, got {part.dimension}D")
        self.world = world
        self.part = part
        self.dimension = part.dimension
        self.reach = float(np.linalg.norm(part.vertices, axis=1).max())
        if self.dimension == 3:
            model = fcl.BVHModel()
            model.beginModel(len(part.vertices), len(part.faces))
            model.addSubModel(part.vertices, part.faces.astype(np.int32))
            model.endModel()
            self._objects = [fcl.CollisionObject(model, fcl.Transform())]
        else:
            self._objects = [
                fcl.CollisionObject(polygon_prism(p, world.half_height), fcl.Transform())
                for p in convex_pieces(part.vertices)
            ]

    def _place(self, pose: ArrayLike) -> None:
        p = np.asarray(pose, dtype=float)
        if p.shape != (pose_size(self.dimension),) or not np.isfinite(p).all():
            raise ValueError(f"pose: expected {pose_size(self.dimension)} finite numbers")
        R, t = pose_frame(p, self.dimension)
        R3, t3 = np.eye(3), np.zeros(3)
        R3[: self.dimension, : self.dimension], t3[: self.dimension] = R, t
        for obj in self._objects:
            obj.setTransform(fcl.Transform(R3, t3))

    def safe_clearance(self, pose: ArrayLike) -> float:
        """Distance from the part at ``pose`` to the nearest obstacle, less FCL's error
        allowance (:meth:`CollisionWorld.object_clearance`); one query per object."""
        self._place(pose)
        return min((self.world.object_clearance(obj) for obj in self._objects), default=math.inf)

    def encloses_obstacle(self, pose: ArrayLike) -> bool:
        """Whether some obstacle has a point inside the part at ``pose`` (3D; always
        False in 2D, where the part is solid to FCL)."""
        if self.dimension == 2 or not self.world.scenario.obstacles:
            return False
        R, t = pose_frame(np.asarray(pose, dtype=float), 3)
        anchors = np.array(
            [ob.vertices[0] if ob.vertices is not None else ob.center
             for ob in self.world.scenario.obstacles]
        )  # fmt: skip
        local = (anchors - t) @ R  # into the part's frame
        return bool((np.abs(winding_numbers(local, self.part.boundary)) > 0.5).any())
