"""Gap-free verification of an arm's path on the links' own collision meshes.

Independent of the covers and of any certifier: the links are the URDF's collision
geometry itself (python-fcl BVH meshes, or the primitives), placed by Pinocchio's
``updateGeometryPlacements``. Along each segment ``q(s)`` of the path, at a sample ``s``
every link ``g`` is ``D_g`` from the obstacles and ``D_gh`` from each link ``h`` it may
collide with; its points move at most ``V_g`` per unit of ``s`` (the chain's bound of
:func:`kcplan.arm.bounds.chain_speeds`, with the mesh's own farthest vertex as the reach),
so link ``g`` is measured against the scene again at ``s + D_g / V_g`` and against ``h`` at
``s + D_gh / V_gh`` (:class:`ArmMeshChecker`): no stretch is skipped that could hide a
contact. A distance at or below ``tolerance`` is a collision. Where a link's convex hull
(qhull's, of the mesh file's vertices) is farther than :data:`HULL_NEAR`, the hull's
distance serves as ``D``: a lower bound, since the hull holds the mesh, and one query of a
few hundred vertices instead of a BVH of tens of thousands of triangles.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass

import fcl
import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.arm.bounds import carries, chain_speeds, relative_speeds
from kcplan.arm.model import ArmModel
from kcplan.arm.shapes import bvh_mesh
from kcplan.world.collision import fcl_obstacle_parts
from kcplan.world.obstacles import Obstacle
from kcplan.world.pointcloud import CLOUD_KINDS

__all__ = ["ArmMeshChecker", "ArmPathCheck", "verify_arm_path"]

HULL_NEAR = 0.02
"""Metres: a link whose convex hull is farther than this from what it is measured against
is measured by its hull (a lower bound of its mesh's distance), nearer by its mesh."""
HULL_MARGIN = 1e-5
"""Metres taken off a hull's distance: well above FCL's GJK tolerance (1e-6)."""


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
    what : str
        What touches there: ``LINK and an obstacle`` or ``LINK and LINK`` (a held
        object counts as a link, by its name), or ``""``.
    pair : tuple of str
        The two links' names when two links touch there, else ``()``.
    queries : int
        Distance queries made (a link against the scene, or two links).
    """

    collides: bool
    min_clearance: float
    where: tuple = ()
    queries: int = 0
    what: str = ""
    pair: tuple = ()


@functools.lru_cache(maxsize=256)
def _file_mesh(path: str, scale: tuple[float, float, float]):
    """A collision mesh file as trimesh reads it (scaled): its FCL BVH model, its farthest
    vertex's distance from the mesh's origin and its convex hull (:func:`_convex_hull`);
    ``None`` for a format trimesh cannot read here (Collada without pycollada). Loaded
    once per process (the model is shared by the collision objects that place it)."""
    import trimesh  # here: a plan that verifies no mesh never pays its 1.5 s import

    try:
        mesh = trimesh.load(path, force="mesh", process=False)
    except (ImportError, ValueError, OSError):  # as the views (kcplan.views.arm) fall back
        return None
    V = np.asarray(mesh.vertices, dtype=float) * np.asarray(scale, dtype=float)
    return (*_bvh_model(V, np.asarray(mesh.faces)), _convex_hull(V))


def _bvh_model(V: NDArray[np.float64], F: NDArray) -> tuple[fcl.BVHModel, float]:
    """Triangles as an FCL BVH model, and the farthest vertex's distance from the origin."""
    model = fcl.BVHModel()
    model.beginModel(len(V), len(F))
    model.addSubModel(V, F.astype(np.int32))
    model.endModel()
    return model, float(np.linalg.norm(V, axis=1).max())


def _convex_hull(V: NDArray[np.float64]) -> fcl.Convex | None:
    """The convex hull of points as an FCL solid, ``None`` when qhull cannot build one (a
    flat mesh)."""
    import trimesh

    try:
        hull = trimesh.convex.convex_hull(V)
    except Exception:  # qhull's errors on flat input are of several kinds
        return None
    faces = np.hstack([np.full((len(hull.faces), 1), 3), hull.faces]).astype(np.int32).ravel()
    return fcl.Convex(np.asarray(hull.vertices, dtype=float), len(hull.faces), faces)


def _link_geometry(obj) -> tuple[fcl.CollisionGeometry, float, fcl.Convex | None]:
    """The FCL geometry of one collision object of Pinocchio, the farthest any point of it
    lies from its own frame's origin, and a mesh file's convex hull (else None).

    A mesh file is read by trimesh, independently of the loader the hulls were made
    from; a format it cannot read here is taken as Pinocchio read it (assimp)."""
    shape, kind = obj.geometry, type(obj.geometry).__name__
    if kind == "Sphere":
        return fcl.Sphere(float(shape.radius)), float(shape.radius), None
    if kind == "Box":
        h = np.asarray(shape.halfSide, dtype=float)
        return fcl.Box(*(2 * h).tolist()), float(np.linalg.norm(h)), None
    if kind == "Cylinder":
        r, c = float(shape.radius), float(shape.halfLength)
        return fcl.Cylinder(r, 2 * c), math.hypot(r, c), None
    if not obj.meshPath:  # a mesh given by its triangles (an attached object's)
        return (*_bvh(shape), None)
    read = _file_mesh(str(obj.meshPath), tuple(float(x) for x in obj.meshScale))
    if read is None:
        V, F = bvh_mesh(shape)
        return (*_bvh_model(V, F), _convex_hull(V))
    return read


def _bvh(shape) -> tuple[fcl.BVHModel, float]:
    """A coal BVH model's triangles as an FCL BVH model, and its farthest vertex's
    distance from its origin."""
    return _bvh_model(*bvh_mesh(shape))


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
    padding : float
        Metres each link must keep from the obstacles (not from other links): a link
        nearer than ``padding + tolerance`` to the scene is a collision (``kcplan verify
        --padding``); the advancement then steps by the distance less the padding, so
        the padding is checked without gaps too.
    link_padding : mapping of str to float, optional
        Metres that a link (or an attached part, by its name) keeps instead of
        ``padding`` (``robot.link_padding``).

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
        padding: float = 0.0,
        link_padding: Mapping[str, float] | None = None,
    ) -> None:
        geometry = arm.geometry
        self.arm, self.tolerance, self.padding = arm, float(tolerance), float(padding)
        self._links, self._hulls, reaches, joints = [], [], [], []
        for obj in geometry.geometryObjects:
            shape, reach, hull = _link_geometry(obj)
            self._links.append(fcl.CollisionObject(shape, fcl.Transform()))
            self._hulls.append(None if hull is None else fcl.CollisionObject(hull, fcl.Transform()))
            # the geometry's points lie within its placement's length plus its own reach
            reaches.append(float(np.linalg.norm(obj.placement.translation)) + reach)
            joints.append(int(obj.parentJoint))
        held = {obj.name for obj in arm.attached}  # a held object goes by its own name
        link = [obj.name if obj.name in held else arm.model.frames[obj.parentFrame].name
                for obj in geometry.geometryObjects]  # fmt: skip
        self._names = link
        own = dict(link_padding or {})
        self._paddings = np.array([own.get(name, self.padding) for name in link], dtype=float)
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
        scene, clouds = [], []
        for ob in obstacles:
            if ob.kind in CLOUD_KINDS:  # one FCL surface of its points, less their radius
                clouds.append((fcl.CollisionObject(point_triangles(ob.vertices)),
                               float(ob.extents[0])))  # fmt: skip
                continue
            for shape, tf in fcl_obstacle_parts(ob, 3):
                scene.append(fcl.CollisionObject(shape, tf))
        self._scene = scene  # the manager keeps pointers to these objects
        self._clouds = clouds
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
        for obj, hull, placement in zip(self._links, self._hulls, self._gdata.oMg, strict=True):
            tf = fcl.Transform(placement.rotation, placement.translation)
            obj.setTransform(tf)
            if hull is not None:
                hull.setTransform(tf)

    def _distance(self, item: int) -> float:
        """A lower bound of item ``item``'s distance as placed (link ``item`` against the
        scene, or self pair ``item - links``), exact below :data:`HULL_NEAR`: the links'
        convex hulls are asked first, and their distance, less :data:`HULL_MARGIN`, is
        taken when it exceeds ``HULL_NEAR`` (a hull holds its mesh, so nothing is nearer
        to the mesh than to its hull); the meshes themselves only otherwise."""
        links = len(self._links)
        if item < links:
            if not self._scene and not self._clouds:
                return math.inf
            hull = self._hulls[item]
            if hull is not None:
                near = self._scene_distance(hull) - HULL_MARGIN
                if near > HULL_NEAR:
                    return near
            return self._scene_distance(self._links[item])
        a, b = self._pairs[item - links]
        if self._hulls[a] is not None or self._hulls[b] is not None:
            hull_a, hull_b = self._hulls[a] or self._links[a], self._hulls[b] or self._links[b]
            near = _distance(hull_a, hull_b) - HULL_MARGIN
            if near > HULL_NEAR:
                return near
        return _distance(self._links[a], self._links[b])

    def contact_share(self, pair: tuple[str, str], samples: int = 32, seed: int = 0) -> float:
        """The share of ``samples`` random configurations (uniform within the joint
        limits, seeded) at which the links named ``pair`` touch on their own meshes: 1.0
        for a pair in contact everywhere (two halves of a gripper whose SRDF forgot them),
        which no planner can separate. 0.0 for a pair this checker does not check."""
        return self._contacts([pair], samples, seed, stop=False)[0] / samples

    def touching_everywhere(
        self, pairs: Sequence[tuple[str, str]], samples: int = 32, seed: int = 0
    ) -> list[tuple[str, str]]:
        """The pairs of ``pairs`` whose :meth:`contact_share` is 1.0, at the cost of one
        placement per sample for all of them (a pair is dropped at its first sample
        apart): what ``kcplan robot info`` asks of thousands of pairs."""
        counts = self._contacts(pairs, samples, seed, stop=True)
        return [pair for pair, count in zip(pairs, counts, strict=True) if count == samples]

    def _contacts(self, pairs, samples: int, seed: int, stop: bool) -> list[int]:
        """At how many of ``samples`` seeded random configurations each pair of links
        touches (``stop``: a pair is no longer checked after a sample apart)."""
        index: dict[frozenset, list[int]] = {}
        for m, (a, b) in enumerate(self._pairs):
            index.setdefault(frozenset((self._names[a], self._names[b])), []).append(
                len(self._links) + m
            )
        items = [index.get(frozenset(pair), []) for pair in pairs]
        counts = [0] * len(pairs)
        live = [k for k, found in enumerate(items) if found]
        rng = np.random.default_rng(seed)
        for _ in range(samples):
            if not live:
                break
            self._place(rng.uniform(self.arm.lower, self.arm.upper))
            kept = []
            for k in live:
                if any(self._distance(i) <= self.tolerance for i in items[k]):
                    counts[k] += 1
                    kept.append(k)
                elif not stop:
                    kept.append(k)
            live = kept
        return counts

    def _what(self, item: int) -> str:
        """The names of item ``item``'s two sides (:attr:`ArmPathCheck.what`)."""
        links = len(self._links)
        if item < links:
            return f"{self._names[item]} and an obstacle"
        a, b = self._pairs[item - links]
        return f"{self._names[a]} and {self._names[b]}"

    def _pair_names(self, item: int) -> tuple:
        """The two links of item ``item`` when it is a self pair, else ``()``."""
        links = len(self._links)
        if item < links:
            return ()
        a, b = self._pairs[item - links]
        return (self._names[a], self._names[b])

    def _scene_distance(self, obj: fcl.CollisionObject) -> float:
        d = math.inf
        if self._scene:
            result = fcl.DistanceData()
            self._manager.distance(obj, result, fcl.defaultDistanceCallback)
            d = float(result.result.min_distance)
        for cloud, radius in self._clouds:
            d = min(d, _distance(obj, cloud) - radius)
        return d

    def check(self, states: Sequence[ArrayLike], max_queries: int = 1_000_000) -> ArmPathCheck:
        """Check the path through ``states`` (joint vectors, :attr:`ArmModel.joints`
        order) without gaps; ``max_queries`` distance queries per segment at most
        (RuntimeError beyond)."""
        states = list(self.arm.continuous(states))  # a wrapping angle the shorter way
        pieces = [
            (lambda s, q1=q1, dq=q2 - q1: q1 + s * dq, np.abs(q2 - q1))
            for q1, q2 in zip(states[:-1], states[1:], strict=True)
        ]
        return self.check_pieces(pieces, max_queries)

    def check_pieces(
        self,
        pieces: Sequence[tuple[Callable[[float], NDArray[np.float64]], NDArray[np.float64]]],
        max_queries: int = 1_000_000,
    ) -> ArmPathCheck:
        """Check a curve without gaps, given as pieces ``(f, bound)``: ``f(s)``, ``s`` in
        ``[0, 1]``, is a joint vector within the limits and ``bound[j]`` bounds ``|df_j /
        ds|`` over the piece (a straight segment: ``|q2 - q1|``; any curve:
        :meth:`kcplan.trajectory.curve.BlendedPath.pieces`). The chain's bound then holds
        with ``bound`` in place of ``|dq|``: a point of a link moves at most ``rho @ bound``
        per unit of ``s``. ``where`` names the piece."""
        queries, lowest = 0, math.inf
        for index, (at, bound) in enumerate(pieces):
            bound = np.asarray(bound, dtype=float)
            speeds = np.concatenate([self._rho @ bound, self._rho_pairs @ bound])
            horizon = np.zeros(len(speeds))
            budget = queries + max_queries
            while horizon.size:
                s = float(horizon.min())
                if s > 1.0:
                    break
                self._place(at(s))
                for item in np.flatnonzero(horizon <= s):
                    d = self._distance(int(item))
                    queries += 1
                    lowest = min(lowest, d)
                    if item < len(self._links):  # the scene grown by the link's padding
                        d -= self._paddings[item]
                    if d <= self.tolerance:
                        return ArmPathCheck(True, max(lowest, 0.0), (index, s), queries,
                                            self._what(int(item)),
                                            self._pair_names(int(item)))  # fmt: skip
                    # free on [s, s + d / v): this item's next sample is there
                    v = speeds[item]
                    step = d / v if v > 0 else math.inf
                    horizon[item] = s + max(step * (1.0 - 1e-6), 1e-9)
                if queries >= budget:
                    raise RuntimeError(
                        f"verify: more than {max_queries} queries on segment {index}"
                    )
        return ArmPathCheck(False, lowest, (), queries)


POINT_TRIANGLE = 1e-9
"""Metres: the legs of the triangle that stands for one point of a cloud (point_triangles)."""


def point_triangles(points: NDArray[np.float64]) -> fcl.BVHModel:
    """A cloud's points as one FCL surface: point ``p`` the triangle ``(p, p + e x, p + e
    y)``, ``e`` = :data:`POINT_TRIANGLE`. The triangle holds ``p``, so a shape's distance to
    it never exceeds its distance to ``p``: FCL's BVH (its own, not coal's, and not the
    kernel's tree) then measures a shape's distance to every point at once, from below by at
    most ``e``."""
    p = np.asarray(points, dtype=float)
    vertices = np.stack([p, p + [POINT_TRIANGLE, 0.0, 0.0], p + [0.0, POINT_TRIANGLE, 0.0]], axis=1)
    model = fcl.BVHModel()
    model.beginModel(3 * len(p), len(p))
    model.addSubModel(vertices.reshape(-1, 3), np.arange(3 * len(p)).reshape(-1, 3))
    model.endModel()
    return model


def _distance(a: fcl.CollisionObject, b: fcl.CollisionObject) -> float:
    return float(fcl.distance(a, b, fcl.DistanceRequest(), fcl.DistanceResult()))


def verify_arm_path(
    arm: ArmModel,
    obstacles: Sequence[Obstacle],
    states: Sequence[ArrayLike],
    tolerance: float = 1e-6,
    max_queries: int = 1_000_000,
    allowed: Collection[frozenset] = (),
    padding: float = 0.0,
    link_padding: Mapping[str, float] | None = None,
) -> ArmPathCheck:
    """Check the path through ``states`` (joint vectors, :attr:`ArmModel.joints` order)
    without gaps against ``obstacles`` and self-collision (the pairs of
    :attr:`ArmModel.geometry` whose links are not an ``allowed`` pair); see the module
    docstring. To check many paths in one scene, build an :class:`ArmMeshChecker` once.
    ``padding``: metres every link must keep from the obstacles, ``link_padding`` a link's
    own instead (:class:`ArmMeshChecker`)."""
    checker = ArmMeshChecker(arm, obstacles, allowed, tolerance, padding, link_padding)
    return checker.check(states, max_queries)
