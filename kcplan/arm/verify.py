"""Gap-free verification of an arm's path on the links' own collision meshes.

Independent of the covers and of any certifier: the links are the URDF's collision
geometry itself (python-fcl BVH meshes, or the primitives), placed by Pinocchio's
``updateGeometryPlacements``. Along each segment ``q(s)`` of the path, at a sample ``s``
every link ``g`` is ``D_g`` from the obstacles and ``D_gh`` from each link ``h`` it may
collide with; its points move at most ``V_g`` per unit of ``s`` (the chain's bound of
:func:`kcplan.arm.bounds.chain_speeds`, with the mesh's own farthest vertex as the reach),
so the next sample is ``s + min(D_g / V_g, D_gh / V_gh)``: no stretch is skipped that
could hide a contact. A distance at or below ``tolerance`` is a collision.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass

import fcl
import numpy as np
import trimesh
from numpy.typing import ArrayLike

from kcplan.arm.bounds import carries, chain_speeds, relative_speeds
from kcplan.arm.model import ArmModel
from kcplan.world.collision import fcl_obstacle_parts
from kcplan.world.scenario import Obstacle

__all__ = ["ArmPathCheck", "verify_arm_path"]


@dataclass(frozen=True)
class ArmPathCheck:
    """The result of :func:`verify_arm_path`.

    Attributes
    ----------
    collides : bool
    min_clearance : float
        Smallest link distance seen (to an obstacle or another link), metres.
    where : tuple
        ``(segment, s)`` of the first contact, or ``()``.
    queries : int
        Distance queries (one per sample).
    """

    collides: bool
    min_clearance: float
    where: tuple = ()
    queries: int = 0


def _link_geometry(obj) -> tuple[fcl.CollisionGeometry, float]:
    """The FCL geometry of one collision object of Pinocchio and the farthest any point of
    it lies from its own frame's origin."""
    shape, kind = obj.geometry, type(obj.geometry).__name__
    if kind == "Sphere":
        return fcl.Sphere(float(shape.radius)), float(shape.radius)
    if kind == "Box":
        h = np.asarray(shape.halfSide, dtype=float)
        return fcl.Box(*(2 * h).tolist()), float(np.linalg.norm(h))
    if kind == "Cylinder":
        r, c = float(shape.radius), float(shape.halfLength)
        return fcl.Cylinder(r, 2 * c), math.hypot(r, c)
    mesh = trimesh.load(obj.meshPath, force="mesh", process=False)
    V = np.asarray(mesh.vertices, dtype=float) * np.asarray(obj.meshScale, dtype=float)
    F = np.asarray(mesh.faces, dtype=np.int32)
    model = fcl.BVHModel()
    model.beginModel(len(V), len(F))
    model.addSubModel(V, F)
    model.endModel()
    return model, float(np.linalg.norm(V, axis=1).max())


def verify_arm_path(
    arm: ArmModel,
    obstacles: Sequence[Obstacle],
    states: Sequence[ArrayLike],
    tolerance: float = 1e-6,
    max_queries: int = 1_000_000,
    allowed: Collection[frozenset] = (),
) -> ArmPathCheck:
    """Check the path through ``states`` (joint vectors, :attr:`ArmModel.joints` order)
    without gaps against ``obstacles`` and self-collision (the pairs of
    :attr:`ArmModel.geometry` whose links are not an ``allowed`` pair); see the module
    docstring."""
    import pinocchio as pin

    geometry = arm.geometry
    links, reaches, joints = [], [], []
    for obj in geometry.geometryObjects:
        shape, reach = _link_geometry(obj)
        links.append(fcl.CollisionObject(shape, fcl.Transform()))
        # the geometry's points lie within its placement's length plus its own reach
        reaches.append(float(np.linalg.norm(obj.placement.translation)) + reach)
        joints.append(int(obj.parentJoint))
    link = [arm.model.frames[obj.parentFrame].name for obj in geometry.geometryObjects]
    pairs = np.array(
        [
            (p.first, p.second)
            for p in geometry.collisionPairs
            if frozenset((link[p.first], link[p.second])) not in allowed
        ],
        dtype=int,
    ).reshape(-1, 2)
    rho = chain_speeds(arm, joints, reaches)
    rho_pairs = relative_speeds(rho, carries(arm, joints), pairs)
    scene = []
    for ob in obstacles:
        for shape, tf in fcl_obstacle_parts(ob, 3):
            scene.append(fcl.CollisionObject(shape, tf))
    manager = fcl.DynamicAABBTreeCollisionManager()
    if scene:
        manager.registerObjects(scene)
        manager.setup()
    data, gdata = arm.model.createData(), geometry.createData()
    request = fcl.DistanceRequest()

    def distances(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        pin.forwardKinematics(arm.model, data, arm.configuration(q))
        pin.updateGeometryPlacements(arm.model, data, geometry, gdata)
        for obj, placement in zip(links, gdata.oMg, strict=True):
            obj.setTransform(fcl.Transform(placement.rotation, placement.translation))
        d_scene = np.full(len(links), math.inf)
        if scene:
            for g, obj in enumerate(links):
                result = fcl.DistanceData()
                manager.distance(obj, result, fcl.defaultDistanceCallback)
                d_scene[g] = float(result.result.min_distance)
        d_pairs = np.array(
            [fcl.distance(links[a], links[b], request, fcl.DistanceResult()) for a, b in pairs]
        )
        return d_scene, d_pairs

    queries, lowest = 0, math.inf
    states = [np.asarray(q, dtype=float) for q in states]
    for index, (q1, q2) in enumerate(zip(states[:-1], states[1:], strict=True)):
        dq = np.abs(q2 - q1)
        v_scene = rho @ dq
        v_pairs = rho_pairs @ dq
        s = 0.0
        while True:
            d_scene, d_pairs = distances(q1 + s * (q2 - q1))
            queries += 1
            lowest = min(
                lowest, float(d_scene.min(initial=math.inf)), float(d_pairs.min(initial=math.inf))
            )
            if (d_scene <= tolerance).any() or (d_pairs <= tolerance).any():
                return ArmPathCheck(True, max(lowest, 0.0), (index, s), queries)
            if s >= 1.0 or queries >= max_queries:
                break
            with np.errstate(divide="ignore"):
                step = min(
                    float(
                        np.min(np.where(v_scene > 0, d_scene / v_scene, math.inf), initial=math.inf)
                    ),
                    float(
                        np.min(np.where(v_pairs > 0, d_pairs / v_pairs, math.inf), initial=math.inf)
                    ),
                )
            s = min(1.0, s + max(step * (1.0 - 1e-6), 1e-9))
        if queries >= max_queries:
            raise RuntimeError(f"verify: more than {max_queries} queries on segment {index}")
    return ArmPathCheck(False, lowest, (), queries)
