"""Collision and clearance queries of an arm's bodies (ellipsoids or link hulls), on python-fcl.

The reference world of arms (the compiled kernel will hold its twin): the bodies of an
:class:`kcplan.arm.ArmModel` placed at a joint configuration (:func:`body_frames`),
against the scene's obstacles (the scenario's 3D kinds, built as
:class:`kcplan.world.CollisionWorld` builds them) and against each other for the pairs
that may collide (:attr:`ArmModel.self_pairs`).

Distances from FCL's GJK can be too large between thin curved shapes: between two of the
Panda's covering ellipsoids (box_1, seed 1) FCL gave 0.1256 m where the distance is 0.1167
m (7.6 % over; on random thin ellipsoids 3 pairs in 1,500 beyond 0.2 %, up to 0.6 %, and
ellipsoid-sphere up to 2.5 %: far beyond the rigid world's allowance,
:data:`kcplan.world.collision.CLEARANCE_RTOL`). So :meth:`ArmWorld.clearances` takes only
the *direction* from FCL's nearest points and the distance from the two shapes' exact
support functions along it (:func:`kcplan.world.support.separation`), a lower bound
whatever FCL's error; a mesh obstacle, which has no support function, keeps FCL's
distance. The ``safe_*`` queries then subtract the rigid world's allowance as well.
A link's hull (:attr:`kcplan.arm.ArmBody.hull`) is an ``fcl.Convex`` whose support
function is its vertices' (:class:`kcplan.world.support.PointsSupport`).
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from functools import cached_property

import fcl
import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan._kernel import arm_digest, build_kernel_arm
from kcplan.arm.bounds import reach_ball
from kcplan.arm.kinematics import body_frames
from kcplan.arm.model import ArmModel
from kcplan.arm.pairs import prove_pairs as prove_pairs_of
from kcplan.world.collision import CLEARANCE_ATOL, CLEARANCE_RTOL, fcl_obstacle_parts
from kcplan.world.obstacles import Obstacle
from kcplan.world.pointcloud import CLOUD_KINDS
from kcplan.world.support import EllipsoidSupport, PointsSupport, piece_supports, separation

__all__ = ["ArmWorld", "checked_pairs"]


def checked_pairs(arm: ArmModel, allowed: Collection[frozenset]) -> NDArray[np.int64]:
    """The body pairs of ``arm.self_pairs`` whose links are not an ``allowed`` pair."""
    keep = [
        (i, j)
        for i, j in arm.self_pairs
        if frozenset((arm.bodies[i].link, arm.bodies[j].link)) not in allowed
    ]
    return np.array(keep, dtype=np.int64).reshape(-1, 2)


def _box(obstacle: Obstacle, support) -> NDArray[np.float64]:
    """A piece's bounding box ``[low, high]``, from its support function along the axes
    (``high_i = h(e_i)``, ``low_i = -h(-e_i)``) or a mesh's vertices."""
    if support is None:
        return obstacle.vertex_box
    axes = np.eye(3)
    return np.array([[-support(-e) for e in axes], [support(e) for e in axes]])


_REACHES: dict[str, tuple] = {}
""":attr:`ArmWorld.reach` by arm (:func:`kcplan._kernel.arm_digest`)."""


class ArmWorld:
    """The scene of an arm: its obstacles and its self-collision pairs.

    Parameters
    ----------
    arm : ArmModel
    obstacles : sequence of Obstacle
        3D obstacles (:class:`kcplan.world.obstacles.Obstacle`), in the arm's base frame.
    size : float, optional
        Size of the scene in metres, for FCL's absolute error allowance (default: the
        larger of 2 m and the obstacles' extent).
    allowed : collection of frozenset of str, optional
        Link pairs allowed to touch (a scene's allowed collision matrix): their bodies
        are not checked against each other.
    prove_pairs : bool, optional
        Leave out the self pairs proven apart over the whole joint box
        (:mod:`kcplan.arm.pairs`, once per arm); False checks them all (the ablation).
    padding : float, optional
        Metres every body keeps from every obstacle in the compiled :attr:`kernel`'s
        queries (MoveIt's link padding; self pairs are not padded).
    link_padding : mapping of str to float, optional
        Metres that the bodies of a link (or of an attached part, by its name) keep
        instead of ``padding`` (MoveIt's per-link padding).

    Notes
    -----
    States are joint vectors of shape ``(arm.dof,)`` in :attr:`ArmModel.joints` order.
    ``counters`` counts ``collision_queries`` and ``distance_queries`` (one per state
    queried). Not thread-safe: the bodies' FCL objects are reused.
    """

    def __init__(
        self,
        arm: ArmModel,
        obstacles: Sequence[Obstacle] = (),
        size: float | None = None,
        allowed: Collection[frozenset] = (),
        prove_pairs: bool = True,
        padding: float = 0.0,
        link_padding: Mapping[str, float] | None = None,
    ):
        self.arm = arm
        self.obstacles = tuple(obstacles)
        if not (padding >= 0.0 and math.isfinite(padding)):
            raise ValueError(f"padding: expected a finite number >= 0, got {padding!r}")
        self.padding = float(padding)
        """Metres every body keeps from every obstacle, kept by :attr:`kernel`'s queries
        (the python-fcl queries of this class do not pad)."""
        links = {b.link for b in arm.bodies}
        self.link_padding = dict(link_padding or {})
        """Metres the bodies of a link (or attached part) keep instead of :attr:`padding`."""
        for name, value in self.link_padding.items():
            if name not in links:
                raise ValueError(f"link_padding: {name!r} is not a link with bodies "
                                 f"(expected one of {', '.join(sorted(links))})")  # fmt: skip
            if not (value >= 0.0 and math.isfinite(value)):
                raise ValueError(f"link_padding.{name}: expected a finite number >= 0, "
                                 f"got {value!r}")  # fmt: skip
        self.allowed = frozenset(allowed)
        pairs = checked_pairs(arm, self.allowed)
        self.proven_apart = 0
        """How many of those pairs were left out, proven apart (:mod:`kcplan.arm.pairs`)."""
        if prove_pairs and len(pairs):
            keep = [p.verdict != "apart" for p in prove_pairs_of(arm, pairs)]
            self.proven_apart = len(pairs) - sum(keep)
            pairs = pairs[np.array(keep, dtype=bool)]
        self.self_pairs = pairs
        """The pairs of :attr:`ArmModel.self_pairs` whose links are not allowed to touch
        and that are not proven apart."""
        for ob in self.obstacles:
            if len(ob.center) != 3:
                raise ValueError(f"{ob.label}: expected a 3D obstacle for an arm")
        if size is None:
            corners = [
                corner
                for ob in self.obstacles
                for corner in (ob.vertex_box if ob.kind in CLOUD_KINDS else (ob.center,))
            ] or [np.zeros(3)]
            size = max(2.0, float(np.ptp(np.array(corners), axis=0).max()))
        self.size = float(size)
        """Size of the scene in metres (the error allowances' scale)."""
        self.clearance_atol = CLEARANCE_ATOL * self.size
        self._fcl_counters = {"collision_queries": 0, "distance_queries": 0}
        self._request = fcl.DistanceRequest(enable_nearest_points=True)
        self._kernel = None

    @cached_property
    def _shapes(self) -> list:
        """The bodies' FCL shapes, made on first use (a planner on the kernel never asks)."""
        return [_fcl_shape(b) for b in self.arm.bodies]

    @cached_property
    def _bodies(self) -> list:
        """The bodies' FCL objects, placed by each query."""
        return [fcl.CollisionObject(shape, fcl.Transform()) for shape in self._shapes]

    @cached_property
    def _scene(self) -> tuple:
        """The obstacles' FCL objects, support functions, nearest-point functions, boxes
        and broad phase, made on first use: a planner on the compiled kernel never asks
        (a point cloud of 10^5 points would otherwise cost a second of FCL objects)."""
        objects, supports, nearest, boxes = [], [], [], []
        for ob in self.obstacles:
            parts = fcl_obstacle_parts(ob, 3)
            for (geometry, tf), support in zip(parts, piece_supports(ob), strict=True):
                objects.append(fcl.CollisionObject(geometry, tf))
                supports.append(support)
                nearest.append(_nearest_point(ob) if len(parts) == 1 else None)
                boxes.append(_box(ob, support))
        manager = fcl.DynamicAABBTreeCollisionManager()
        if objects:
            manager.registerObjects(objects)
            manager.setup()
        return objects, supports, nearest, np.array(boxes).reshape(-1, 2, 3), manager

    _objects = property(lambda self: self._scene[0])
    _supports = property(lambda self: self._scene[1])
    _nearest = property(lambda self: self._scene[2])
    _boxes = property(lambda self: self._scene[3])
    _manager = property(lambda self: self._scene[4])

    @cached_property
    def reach(self) -> tuple[NDArray[np.float64], float]:
        """A ball (centre ``(3,)``, radius in metres) that holds every body at every state
        (:func:`kcplan.arm.bounds.reach_ball`): :attr:`kernel`'s clouds keep the points
        whose balls meet it grown by the padding, and no other. Computed once per arm as
        the kernel reads it (:func:`kcplan._kernel.arm_digest`): 0.8 ms for the Panda,
        1.6 ms for the UR5."""
        digest = arm_digest(self.arm)
        reach = _REACHES.get(digest)
        if reach is None:
            reach = _REACHES[digest] = reach_ball(self.arm)
        return reach

    @property
    def kernel(self):
        """The same scene in the compiled kernel (a :class:`kcplan._kernel.ArmWorld` on
        coal: the same chain, bodies, self pairs and obstacles, with coal's error
        allowance), built on first use. Its queries are counted in :attr:`counters`."""
        if self._kernel is None:
            self._kernel = build_kernel_arm(self)
        return self._kernel

    @property
    def counters(self) -> dict[str, int]:
        """Queries issued through this world, python-fcl's and the kernel's together:
        ``collision_queries`` and ``distance_queries``, one per state queried."""
        out = dict(self._fcl_counters)
        if self._kernel is not None:
            compiled = self._kernel.counters
            out = {key: value + compiled[key] for key, value in out.items()}
        return out

    def reset_counters(self) -> None:
        """Set the query counters to zero."""
        self._fcl_counters = dict.fromkeys(self._fcl_counters, 0)
        if self._kernel is not None:
            self._kernel.reset_counters()

    def _joints(self, state: ArrayLike) -> NDArray[np.float64]:
        q = np.asarray(state, dtype=float)
        if q.shape != (self.arm.dof,) or not np.isfinite(q).all():
            raise ValueError(
                f"state: expected {self.arm.dof} finite joint values, got {q.tolist()}"
            )
        return q

    def _place(self, state: ArrayLike) -> list:
        """Place the bodies at ``state``; their support functions there."""
        supports = []
        frames = self._frames = body_frames(self.arm, self._joints(state))
        for obj, frame, body in zip(self._bodies, frames, self.arm.bodies, strict=True):
            obj.setTransform(fcl.Transform(frame[:3, :3], frame[:3, 3]))
            supports.append(_support(body, frame))
        return supports

    def _distance(self, k: int, support_a, b: fcl.CollisionObject, support_b) -> float:
        """A lower bound of the distance between body ``k`` and ``b`` (0 on contact): the
        support functions' separation along FCL's nearest points (module docstring), or
        FCL's distance where ``b`` has no support function (a mesh)."""
        return self._distance_between(self._bodies[k], self._shapes[k], support_a, b, support_b)

    def _distance_between(self, a, shape_a, support_a, b: fcl.CollisionObject, support_b) -> float:
        """:meth:`_distance` of the object ``a`` (of geometry ``shape_a``) and ``b``."""
        d, direction = self._nearest_direction(a, shape_a, b)
        if d <= 0.0:
            return 0.0
        if support_b is None:
            return d
        if direction is None:
            return 0.0
        return max(separation(support_a, support_b, direction), 0.0)

    def _nearest_direction(self, a, shape_a, b) -> tuple[float, NDArray | None]:
        """FCL's distance between the object ``a`` (of geometry ``shape_a``) and ``b`` (0
        on contact), and the unit direction from ``a``'s nearest point to ``b``'s (None
        on contact or where the points coincide)."""
        result = fcl.DistanceResult()
        d = fcl.distance(a, b, self._request, result)
        if d <= 0.0:
            return 0.0, None
        if result.o1 is shape_a:
            p_a, p_b = result.nearest_points
        else:  # FCL swaps some pairs (and their points)
            p_b, p_a = result.nearest_points
        direction = np.asarray(p_b, dtype=float) - np.asarray(p_a, dtype=float)
        length = math.sqrt(float(direction @ direction))
        return float(d), (direction / length if length > 0.0 else None)

    def in_collision(self, state: ArrayLike) -> bool:
        """Whether a body at ``state`` touches an obstacle or a body it may collide with
        (one collision query)."""
        self._place(state)
        self._fcl_counters["collision_queries"] += 1
        if self._objects:
            for obj in self._bodies:
                data = fcl.CollisionData()
                self._manager.collide(obj, data, fcl.defaultCollisionCallback)
                if data.result.is_collision:
                    return True
        request = fcl.CollisionRequest()
        for i, j in self.self_pairs:
            result = fcl.CollisionResult()
            if fcl.collide(self._bodies[i], self._bodies[j], request, result):
                return True
        return False

    def _body_boxes(self, supports: list) -> NDArray[np.float64]:
        """Bounding boxes of the placed bodies, ``(bodies, 2, 3)``: the ellipsoid
        ``c + M^T u`` (``M = diag(a) R^T``) spans ``c_i +- |M e_i|`` along axis ``i``; a
        hull its vertices' box."""
        boxes = np.empty((len(supports), 2, 3))
        for k, s in enumerate(supports):
            if isinstance(s, PointsSupport):
                boxes[k] = s.vertices.min(axis=0), s.vertices.max(axis=0)
            else:
                half = np.linalg.norm(s.shape, axis=0)
                boxes[k] = s.center - half, s.center + half
        return boxes

    def clearances(self, state: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Distances at ``state``, never too large (module docstring): of each body to the
        nearest obstacle ``(bodies,)`` (``inf`` without obstacles) and between the bodies
        of each self pair ``(pairs,)``, metres, 0 on contact (one distance query: every
        body against every obstacle piece, and every pair)."""
        supports = self._place(state)
        self._fcl_counters["distance_queries"] += 1
        scene = np.full(len(self._bodies), math.inf)
        # a piece whose bounding box is farther than the body's best bound cannot lower it
        for k, box in enumerate(self._body_boxes(supports)):
            gaps = np.maximum(np.maximum(self._boxes[:, 0] - box[1], box[0] - self._boxes[:, 1]), 0)
            far = np.linalg.norm(gaps, axis=1)
            for i in np.argsort(far):
                if far[i] >= scene[k]:
                    break
                piece = self._supports[i]
                scene[k] = min(scene[k], self._distance(k, supports[k], self._objects[i], piece))
        return scene, self._pair_clearances(supports)

    def separations(self, state: ArrayLike) -> tuple[NDArray, NDArray, NDArray]:
        """How each body at ``state`` is kept apart from each obstacle piece: ``normals``
        ``(bodies, pieces, 3)``, unit directions from the body towards the piece (FCL's
        nearest points), ``gaps`` ``(bodies, pieces)``, the separation of the two exact
        support functions along them (the body lies in ``{n . x <= b}``, the piece in
        ``{n . x >= b + gap}``; ``-inf`` for a mesh piece or a degenerate direction, 0 on
        contact) and ``clearances`` ``(bodies, pieces)``, certain distances as
        :meth:`safe_clearances` measures them. A box, ball or cylinder is taken along the
        line from its point nearest the body's centre where the two are apart along it
        (its clearance then that separation), as the kernel takes it. These are the slabs
        of the plane certificate (:mod:`kcplan.certification.arm_certifier`; the kernel's
        ``ArmWorld::body_separations``). One distance query: every body against every
        piece."""
        supports = self._place(state)
        self._fcl_counters["distance_queries"] += 1
        shape = (len(self._bodies), len(self._objects))
        normals, gaps = np.zeros(shape + (3,)), np.full(shape, -math.inf)
        clearances = np.zeros(shape)
        exact = np.zeros(shape, dtype=bool)  # a primitive's separation: no allowance
        for k, obj in enumerate(self._bodies):
            centre = self._frames[k][:3, 3]
            for i, (piece, support) in enumerate(zip(self._objects, self._supports, strict=True)):
                if self._nearest[i] is not None:
                    line = self._nearest[i](centre) - centre  # from the body towards the piece
                    length = math.sqrt(float(line @ line))
                    gap = separation(supports[k], support, line / length) if length > 0 else 0.0
                    if gap > 0.0:
                        normals[k, i], gaps[k, i], clearances[k, i] = line / length, gap, gap
                        exact[k, i] = True
                        continue
                d, direction = self._nearest_direction(obj, self._shapes[k], piece)
                if d > 0.0 and support is None:  # a mesh: FCL's distance alone
                    clearances[k, i] = d
                    continue
                if direction is None:  # in contact
                    gaps[k, i] = 0.0
                    continue
                normals[k, i] = direction
                gaps[k, i] = separation(supports[k], support, direction)
                clearances[k, i] = max(gaps[k, i], 0.0)
        return normals, gaps, np.where(exact, clearances, self._safe(clearances))

    def grown_clear(self, state: ArrayLike, scale: float) -> NDArray[np.bool_]:
        """Whether each body at ``state``, grown about its centre by ``scale`` (semi-axes
        times ``scale >= 1``), is certainly clear of the obstacles, ``(bodies,)``: its
        distance (module docstring) less FCL's allowance is positive. These are the KC
        guards of :mod:`kcplan.certification.arm_certifier`; self pairs are not looked at (one
        collision query). A hull body has no KC guard: False, not asked."""
        if not (math.isfinite(scale) and scale >= 1.0):
            raise ValueError(f"scale: expected a finite number >= 1, got {scale!r}")
        frames = body_frames(self.arm, self._joints(state))
        self._fcl_counters["collision_queries"] += 1
        clear = np.ones(len(frames), dtype=bool)
        if not self._objects:
            return clear
        for k, (frame, body) in enumerate(zip(frames, self.arm.bodies, strict=True)):
            if body.hull is not None:
                clear[k] = False  # KC's guard is an ellipsoid's
                continue
            axes = scale * body.semi_axes
            grown = fcl.Ellipsoid(*axes.tolist())
            obj = fcl.CollisionObject(grown, fcl.Transform(frame[:3, :3], frame[:3, 3]))
            support = EllipsoidSupport(frame[:3, 3], frame[:3, :3], axes)
            box = self._body_boxes([support])[0]
            gaps = np.maximum(np.maximum(self._boxes[:, 0] - box[1], box[0] - self._boxes[:, 1]), 0)
            for i in np.flatnonzero(np.linalg.norm(gaps, axis=1) <= self.clearance_atol):
                d = self._distance_between(obj, grown, support, self._objects[i], self._supports[i])
                if not self._safe(np.array([d]))[0] > 0.0:
                    clear[k] = False
                    break
        return clear

    def _pair_clearances(self, supports: list) -> NDArray[np.float64]:
        """The self pairs' separations along FCL's nearest points, ``(pairs,)``, with the
        bodies placed (:func:`kcplan.world.support.separation` for all pairs at once)."""
        m = len(self.self_pairs)
        directions, touching = np.zeros((m, 3)), np.zeros(m, dtype=bool)
        for row, (i, j) in enumerate(self.self_pairs):
            result = fcl.DistanceResult()
            if fcl.distance(self._bodies[i], self._bodies[j], self._request, result) <= 0.0:
                touching[row] = True
                continue
            p_i, p_j = result.nearest_points
            if result.o1 is not self._shapes[i]:  # FCL swaps some pairs (and their points)
                p_i, p_j = p_j, p_i
            directions[row] = np.asarray(p_j, dtype=float) - np.asarray(p_i, dtype=float)
        length = np.linalg.norm(directions, axis=1)
        touching |= length == 0.0
        n = directions / np.where(touching, 1.0, length)[:, None]
        if any(b.hull is not None for b in self.arm.bodies):  # one pair at a time
            gaps = [
                0.0 if touching[row] else separation(supports[i], supports[j], n[row])
                for row, (i, j) in enumerate(self.self_pairs)
            ]
            return np.maximum(np.array(gaps, dtype=float), 0.0)
        centres = np.array([s.center for s in supports]).reshape(-1, 3)
        shapes = np.array([s.shape for s in supports]).reshape(-1, 3, 3)
        first, second = self.self_pairs[:, 0], self.self_pairs[:, 1]
        # -h_j(-n) - h_i(n), h(n) = c . n + |diag(a) R^T n| (EllipsoidSupport)
        gap = np.einsum("mk,mk->m", centres[second] - centres[first], n)
        gap -= np.linalg.norm(np.einsum("mab,mb->ma", shapes[second], n), axis=1)
        gap -= np.linalg.norm(np.einsum("mab,mb->ma", shapes[first], n), axis=1)
        return np.where(touching, 0.0, np.maximum(gap, 0.0))

    def safe_clearances(self, state: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """:meth:`clearances` less FCL's error allowance: distances that are certain."""
        scene, pairs = self.clearances(state)
        return self._safe(scene), self._safe(pairs)

    def _safe(self, d: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.maximum(d * (1.0 - CLEARANCE_RTOL) - self.clearance_atol, 0.0)


def _nearest_point(obstacle: Obstacle):
    """The point of a box, ball or cylinder obstacle nearest a point ``x`` (``x`` itself
    inside), as a function of ``x`` ``(3,)``; None for any other kind (the kernel's
    ``Primitive::nearest``)."""
    c, R, e = obstacle.center, obstacle.rotation, obstacle.extents
    if obstacle.kind == "box":
        return lambda x: c + R @ np.clip(R.T @ (x - c), -e, e)
    if obstacle.kind == "sphere":
        def ball(x):
            d = x - c
            r = math.sqrt(float(d @ d))
            return x if r <= e[0] else c + d * (e[0] / r)
        return ball
    if obstacle.kind == "cylinder":  # extents (r, r, h / 2) about the local z axis
        def cylinder(x):
            local = R.T @ (x - c)
            r = math.hypot(local[0], local[1])
            if r > e[0]:
                local[:2] *= e[0] / r
            local[2] = min(max(local[2], -e[2]), e[2])
            return c + R @ local
        return cylinder
    return None


def _fcl_shape(body):
    """The body's FCL shape: its hull as a Convex, else its ellipsoid."""
    if body.hull is None:
        return fcl.Ellipsoid(*body.semi_axes.tolist())
    triangles = body.hull.triangles
    faces = np.hstack([np.full((len(triangles), 1), 3), triangles]).ravel()
    return fcl.Convex(body.hull.vertices, len(triangles), faces)


def _support(body, frame: NDArray[np.float64]):
    """The body's support function at ``frame`` ``(4, 4)``."""
    if body.hull is None:
        return EllipsoidSupport(frame[:3, 3], frame[:3, :3], body.semi_axes)
    return PointsSupport(body.hull.vertices @ frame[:3, :3].T + frame[:3, 3])
