"""Gap-free verification of an arm's path on the links' own collision meshes.

Independent of the covers and of any certifier: the links are the URDF's collision
geometry itself (python-fcl BVH meshes, or the primitives), placed by Pinocchio's
``updateGeometryPlacements``. Along each segment ``q(s)`` of the path, at a sample ``s``
every link ``g`` is ``D_g`` from the obstacles and ``D_gh`` from each link ``h`` it may
collide with; its points move at most ``V_g`` per unit of ``s`` (the chain's bound of
:func:`kcplan.arm.bounds.chain_speeds`, with the mesh's own farthest vertex as the reach),
so link ``g`` is measured against the scene again at ``s + D_g / V_g`` and against ``h`` at
``s + D_gh / V_gh`` (:class:`ArmMeshChecker`): no stretch is skipped that could hide a
contact. A distance at or below ``tolerance`` is a collision.
"""

from __future__ import annotations

import functools
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

__all__ = ["ArmMeshChecker", "ArmPathCheck", "verify_arm_path"]


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
        Distance queries made (a link against the scene, or two links).
    """

    collides: bool
    min_clearance: float
    where: tuple = ()
    queries: int = 0


@functools.lru_cache(maxsize=256)
def _mesh(path: str, scale: tuple[float, float, float]) -> tuple[fcl.BVHModel, float]:
    """A collision mesh file as an FCL BVH model (scaled), and its farthest vertex's
    distance from the mesh's origin; loaded once per process (the model is shared by the
    collision objects that place it)."""
    mesh = trimesh.load(path, force="mesh", process=False)
    V = np.asarray(mesh.vertices, dtype=float) * np.asarray(scale, dtype=float)
    F = np.asarray(mesh.faces, dtype=np.int32)
    model = fcl.BVHModel()
    model.beginModel(len(V), len(F))
    model.addSubModel(V, F)
    model.endModel()
    return model, float(np.linalg.norm(V, axis=1).max())


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
    return _mesh(str(obj.meshPath), tuple(float(x) for x in obj.meshScale))


class ArmMeshChecker:
    """The links' own collision meshes of an arm in a scene, built once to check many
    paths (see the module docstring).

    Parameters
    ----------
    arm : ArmModel
    obstacles : sequence of Obstacle
    allowed : collection of frozenset
        Link pairs (names) never checked against each other (the scene's allowed
        collision matrix), beside the SRDF's disabled pairs.
    tolerance : float
        A distance at or below this (metres) is a collision.

    Notes
    -----
    Each link against the scene and each self pair is an *item* with its own horizon:
    measured at ``s`` with distance ``D`` and speed bound ``V`` (per unit of the
    segment's parameter, for the whole segment), it cannot touch anything before
    ``s + D / V``. The check samples the smallest horizon and measures again only the
    items whose horizon it has reached, so a pair of links far apart is measured once
    per segment, not at every sample; each item's horizons still cover the whole
    segment without gaps.
    """

    def __init__(
        self,
        arm: ArmModel,
        obstacles: Sequence[Obstacle],
        allowed: Collection[frozenset] = (),
        tolerance: float = 1e-6,
    ) -> None:
        geometry = arm.geometry
        self.arm, self.tolerance = arm, float(tolerance)
        self._links, reaches, joints = [], [], []
        for obj in geometry.geometryObjects:
            shape, reach = _link_geometry(obj)
            self._links.append(fcl.CollisionObject(shape, fcl.Transform()))
            # the geometry's points lie within its placement's length plus its own reach
            reaches.append(float(np.linalg.norm(obj.placement.translation)) + reach)
            joints.append(int(obj.parentJoint))
        link = [arm.model.frames[obj.parentFrame].name for obj in geometry.geometryObjects]
        self._pairs = np.array(
            [
                (p.first, p.second)
                for p in geometry.collisionPairs
                if frozenset((link[p.first], link[p.second])) not in allowed
            ],
            dtype=int,
        ).reshape(-1, 2)
        self._rho = chain_speeds(arm, joints, reaches)
        self._rho_pairs = relative_speeds(self._rho, carries(arm, joints), self._pairs)
        scene = []
        for ob in obstacles:
            for shape, tf in fcl_obstacle_parts(ob, 3):
                scene.append(fcl.CollisionObject(shape, tf))
        self._scene = scene  # the manager keeps pointers to these objects
        self._manager = fcl.DynamicAABBTreeCollisionManager()
        if scene:
            self._manager.registerObjects(scene)
            self._manager.setup()
        self._data, self._gdata = arm.model.createData(), geometry.createData()

    def _place(self, q: np.ndarray) -> None:
        import pinocchio as pin

        geometry = self.arm.geometry
        pin.forwardKinematics(self.arm.model, self._data, self.arm.configuration(q))
        pin.updateGeometryPlacements(self.arm.model, self._data, geometry, self._gdata)
        for obj, placement in zip(self._links, self._gdata.oMg, strict=True):
            obj.setTransform(fcl.Transform(placement.rotation, placement.translation))

    def _distance(self, item: int) -> float:
        """Item ``item``'s distance as placed: link ``item`` against the scene, or self
        pair ``item - links``."""
        links = len(self._links)
        if item < links:
            if not self._scene:
                return math.inf
            result = fcl.DistanceData()
            self._manager.distance(self._links[item], result, fcl.defaultDistanceCallback)
            return float(result.result.min_distance)
        a, b = self._pairs[item - links]
        return float(
            fcl.distance(
                self._links[a], self._links[b], fcl.DistanceRequest(), fcl.DistanceResult()
            )
        )

    def check(self, states: Sequence[ArrayLike], max_queries: int = 1_000_000) -> ArmPathCheck:
        """Check the path through ``states`` (joint vectors, :attr:`ArmModel.joints`
        order) without gaps; ``max_queries`` distance queries per segment at most
        (RuntimeError beyond)."""
        queries, lowest = 0, math.inf
        states = [np.asarray(q, dtype=float) for q in states]
        for index, (q1, q2) in enumerate(zip(states[:-1], states[1:], strict=True)):
            dq = np.abs(q2 - q1)
            speeds = np.concatenate([self._rho @ dq, self._rho_pairs @ dq])
            horizon = np.zeros(len(speeds))
            budget = queries + max_queries
            while horizon.size:
                s = float(horizon.min())
                if s > 1.0:
                    break
                self._place(q1 + s * (q2 - q1))
                for item in np.flatnonzero(horizon <= s):
                    d = self._distance(int(item))
                    queries += 1
                    lowest = min(lowest, d)
                    if d <= self.tolerance:
                        return ArmPathCheck(True, max(lowest, 0.0), (index, s), queries)
                    # free on [s, s + d / v): this item's next sample is there
                    v = speeds[item]
                    step = d / v if v > 0 else math.inf
                    horizon[item] = s + max(step * (1.0 - 1e-6), 1e-9)
                if queries >= budget:
                    raise RuntimeError(
                        f"verify: more than {max_queries} queries on segment {index}"
                    )
        return ArmPathCheck(False, lowest, (), queries)


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
    docstring. To check many paths in one scene, build an :class:`ArmMeshChecker` once."""
    return ArmMeshChecker(arm, obstacles, allowed, tolerance).check(states, max_queries)
