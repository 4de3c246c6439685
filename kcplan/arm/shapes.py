"""coal shapes of scenario obstacles, for Pinocchio geometry models (the hand-written
checker of :mod:`kcplan.planning.pin_checker`, attached objects of :mod:`kcplan.arm.attach`).

Obstacles become the same solids as in :func:`kcplan.world.collision.fcl_obstacle_parts`:
a box a coal ``Box`` at its pose, a sphere a ``Sphere``, a cylinder a ``Cylinder`` (axis
along its local z), an ellipsoid an ``Ellipsoid``, a convex obstacle the coal ``Convex``
hull of its vertices, a mesh a ``BVHModelOBBRSS`` of its triangles. :func:`bvh_mesh`
reads such a model (or one Pinocchio loaded from a URDF) back as arrays.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from kcplan.world.obstacles import Obstacle

__all__ = ["bvh_mesh", "coal_obstacle"]


def coal_obstacle(ob: Obstacle):
    """The coal geometry of a 3D obstacle and its pose, ``(geometry, pinocchio.SE3)``.

    Parameters
    ----------
    ob : Obstacle
        A 3D obstacle of a scenario (kinds ``box``, ``sphere``, ``cylinder``,
        ``ellipsoid``, ``convex``, ``mesh``), metres, in the arm's base frame.

    Raises
    ------
    ValueError
        For a planar obstacle or an unknown kind.
    """
    import coal
    import pinocchio as pin

    if len(ob.center) != 3:
        raise ValueError(f"{ob.label}: expected a 3D obstacle for an arm")
    pose = pin.SE3(np.asarray(ob.rotation, dtype=float), np.asarray(ob.center, dtype=float))
    if ob.kind == "box":
        return coal.Box(*(2.0 * np.asarray(ob.extents, dtype=float)).tolist()), pose
    if ob.kind == "sphere":
        return coal.Sphere(float(ob.extents[0])), pose
    if ob.kind == "cylinder":  # extents (r, r, h / 2), axis along the local z
        return coal.Cylinder(float(ob.extents[0]), 2.0 * float(ob.extents[2])), pose
    if ob.kind == "ellipsoid":
        return coal.Ellipsoid(*np.asarray(ob.extents, dtype=float).tolist()), pose
    if ob.kind in ("convex", "mesh"):
        model = coal.BVHModelOBBRSS()
        model.beginModel(len(ob.triangles), len(ob.vertices))
        for v in np.asarray(ob.vertices, dtype=float):
            model.addVertex(v)
        for a, b, c in np.asarray(ob.triangles, dtype=int).tolist():
            model.addTriangle(ob.vertices[a], ob.vertices[b], ob.vertices[c])
        model.endModel()
        if ob.kind == "convex":  # a solid: the hull of the (world-frame) vertices
            model.buildConvexHull(True, "")
            return model.convex, pin.SE3.Identity()
        return model, pin.SE3.Identity()
    raise ValueError(f"{ob.label}: expected a 3D obstacle kind, got {ob.kind!r}")


def bvh_mesh(bvh) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The vertices ``(v, 3)`` (as stored: scaled, in the model's frame) and triangles
    ``(t, 3)`` of a coal BVH model."""
    V = np.asarray(bvh.vertices(), dtype=float).reshape(-1, 3)
    F = np.array([[t[0], t[1], t[2]] for t in map(bvh.tri_indices, range(bvh.num_tris))],
                 dtype=np.int64).reshape(-1, 3)  # fmt: skip
    return V, F
