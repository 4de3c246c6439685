"""The FCL collision world of a scenario: collision and clearance queries for the robot.

The plane in FCL
----------------
In 2D the robot is the ellipsoid ``(a1, a2, h)`` with ``h = min(a)`` at height 0, and
every obstacle is a solid whose **slice at z = 0 and projection onto the plane are both
the planar obstacle**: a prism (convex pieces extruded over ``|z| <= max(a)``), a sphere
for a circle, an ellipsoid ``(a1, a2, min(a))`` for an ellipse. The robot has the same
property. Then the 3D answers are exactly the planar ones:

* if the planar shapes overlap, their z = 0 slices overlap in 3D;
* if they do not, the projections of the 3D solids (the planar shapes) are disjoint,
  so the solids are;
* for distances, ``|p - q| >= |p_xy - q_xy|`` for any two points and equality is reached
  by points of the z = 0 slices, so the 3D distance equals the planar one.

``tests/test_world.py`` checks this against independent planar computations.

Obstacles whose orientation is not the identity are given to FCL as convex solids with
world-frame vertices, because FCL sizes the bounding box of a rotated object from its
bounding sphere (a rotated long box would otherwise overlap everything in the
broad phase). Meshes (3D) are ``fcl.BVHModel`` surfaces: a robot wholly inside a closed
mesh touches no triangle and is reported free. A continuous motion into a mesh must cross
its surface, so certified edges are unaffected; only a start or goal placed inside a mesh
would be missed.
"""

from __future__ import annotations

import math
import os
from functools import cached_property

import fcl
import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan._kernel import _core, build_kernel_world
from kcplan.geometry.pose import pose_size, quaternion_multiply, rotate_vector
from kcplan.geometry.robot import Robot
from kcplan.world.obstacles import Obstacle
from kcplan.world.pointcloud import CLOUD_KINDS
from kcplan.world.region import FreeRegion
from kcplan.world.scenario import Scenario, as_rigid_scenario
from kcplan.world.support import (
    EllipsoidSupport,
    ascended_separation,
    box_vertices,
    piece_supports,
    separation,
)

__all__ = [
    "CLEARANCE_RTOL",
    "CLEARANCE_ATOL",
    "CollisionWorld",
    "fcl_obstacle_parts",
    "polygon_prism",
]

CLEARANCE_RTOL = 2e-3
"""Relative error allowed for FCL's iterative (GJK) distances to mesh pieces (which have
no support function). FCL *over*-estimates distances between curved shapes: on 3000
random ellipsoid-sphere pairs the excess reached 3.1e-4 of the distance; between thin
ellipsoids it reached 7.6 % (RESULTS 11.2), so a distance to a convex piece is not
trusted at all: the world takes FCL's direction and the exact support functions'
separation along it (:func:`kcplan.world.support.separation`), and subtracts ``d RTOL +
ATOL`` besides."""
CLEARANCE_ATOL = 1e-6
"""Absolute error allowed for FCL distances, as a fraction of the scene's size (the
largest side of the bounds): near contact the excess is absolute (4.5e-6 at distance
6.6e-5 between an ellipsoid and a 1000-wide box, in a scene 200 wide)."""


def polygon_prism(polygon: NDArray, half_height: float) -> fcl.Convex:
    """The convex prism over a convex CCW polygon, ``|z| <= half_height``: how a planar
    convex piece is given to FCL (see the module docstring)."""
    k = len(polygon)
    V = np.vstack(
        [
            np.column_stack([polygon, np.full(k, -half_height)]),
            np.column_stack([polygon, np.full(k, half_height)]),
        ]
    )
    faces = [k, *range(k - 1, -1, -1), k, *range(k, 2 * k)]  # bottom (outward -z), top
    for i in range(k):
        j = (i + 1) % k
        faces += [4, i, j, k + j, k + i]
    return fcl.Convex(V, k + 2, np.array(faces, dtype=np.int32))


def _box3(ob: Obstacle) -> fcl.Convex:
    # corner 4 i + 2 j + k has signs (i, j, k)
    V = box_vertices(ob.center, ob.rotation, ob.extents)
    quads = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
    faces = np.array([x for q in quads for x in (4, *q)], dtype=np.int32)
    return fcl.Convex(V, 6, faces)


def _embed(R: NDArray, n: int) -> NDArray:
    if n == 3:
        return R
    out = np.eye(3)
    out[:2, :2] = R
    return out


def fcl_obstacle_parts(ob: Obstacle, n: int, half_height: float = 1.0) -> list[tuple]:
    """The FCL pieces of an obstacle, ``[(geometry, transform), ...]`` (a polygon gives one
    per convex piece); a planar obstacle becomes a prism ``|z| <= half_height`` (see the
    module docstring)."""
    identity = fcl.Transform()
    center3 = np.append(ob.center, 0.0) if n == 2 else ob.center
    if ob.kind in ("polygon", "box") and n == 2:
        return [(polygon_prism(p, half_height), identity) for p in ob.pieces]
    if ob.kind == "box":
        if np.allclose(ob.rotation, np.eye(3)):
            return [(fcl.Box(*(2 * ob.extents)), fcl.Transform(center3))]
        return [(_box3(ob), identity)]
    if ob.kind in ("circle", "sphere"):
        return [(fcl.Sphere(float(ob.extents[0])), fcl.Transform(center3))]
    if ob.kind == "cylinder":  # arm scenes (kcplan.arm.mbm); extents (r, r, h / 2)
        radius, half = float(ob.extents[0]), float(ob.extents[2])
        return [(fcl.Cylinder(radius, 2.0 * half), fcl.Transform(ob.rotation, center3))]
    if ob.kind in ("ellipse", "ellipsoid"):
        axes = ob.extents if n == 3 else [*ob.extents, float(ob.extents.min())]
        return [(fcl.Ellipsoid(*axes), fcl.Transform(_embed(ob.rotation, n), center3))]
    if ob.kind == "convex":
        faces = np.column_stack([np.full(len(ob.triangles), 3), ob.triangles]).ravel()
        return [(fcl.Convex(ob.vertices, len(ob.triangles), faces.astype(np.int32)), identity)]
    if ob.kind in CLOUD_KINDS:  # each point a ball of the planning radius
        radius = float(ob.extents[0])  # a geometry each: supports are keyed by geometry
        return [(fcl.Sphere(radius), fcl.Transform(p)) for p in ob.vertices]
    if ob.kind == "mesh":
        model = fcl.BVHModel()
        model.beginModel(len(ob.vertices), len(ob.triangles))
        model.addSubModel(ob.vertices, ob.triangles)
        model.endModel()
        return [(model, identity)]
    raise ValueError(f"unknown obstacle kind {ob.kind!r}")  # pragma: no cover


class CollisionWorld:
    """Collision and clearance queries for a scenario's robot against its obstacles.

    Parameters
    ----------
    scenario : Scenario or path-like
        The obstacles and the robot, or the path of their scenario file.
    robot : Robot or array_like, optional
        Query a different robot (semi-axes ``(n,)`` for one body at the origin, e.g. a
        guard ``(1 + eps) a``); default the scenario's robot.

    Notes
    -----
    Poses are flat vectors, ``[x, y, yaw]`` or ``[x, y, z, qx, qy, qz, qw]``
    (:mod:`kcplan.geometry.pose`), of the robot's frame; body ``k`` is placed at
    ``(R R_k, t + R p_k)`` (:mod:`kcplan.geometry.robot`). The bounds of the scenario
    are not obstacles: they limit where the planner samples the robot's origin.

    ``counters`` counts FCL queries issued through this object: ``collision_queries``,
    ``distance_queries`` and ``region_queries`` go up by exactly one per robot pose
    queried, ``body_queries`` by the number of bodies actually queried (a collision
    query stops at the first colliding body); ``body_query_counts`` splits the latter
    per body. Not thread-safe: the robot's FCL objects are reused between queries.
    """

    def __init__(
        self, scenario: Scenario | str | os.PathLike, robot: Robot | ArrayLike | None = None
    ):
        scenario = as_rigid_scenario(scenario)
        n = scenario.dimension
        if robot is None:
            robot = scenario.robot
        elif not isinstance(robot, Robot):
            a = np.asarray(robot, dtype=float)
            if a.shape != (n,) or not (a > 0).all():
                raise ValueError(f"semi_axes: expected {n} positive numbers, got {a.tolist()}")
            robot = Robot.single(a)
        if robot.dimension != n:
            raise ValueError(f"robot: expected a {n}D robot, got {robot.dimension}D")
        self.dimension = n
        self.robot = robot
        self.scenario = scenario
        self._geometries = [
            fcl.Ellipsoid(*a) if n == 3 else fcl.Ellipsoid(a[0], a[1], float(a.min()))
            for a in (b.semi_axes for b in robot.bodies)
        ]
        self._bodies = [fcl.CollisionObject(g, fcl.Transform()) for g in self._geometries]
        # body poses in the robot frame as plain floats: (x, y, z), quaternion [x, y, z, w]
        self._offsets = [tuple(b.position.tolist()) + (0.0,) * (3 - n) for b in robot.bodies]
        self._turns = [
            (0.0, 0.0, math.sin(0.5 * b.pose[2]), math.cos(0.5 * b.pose[2]))
            if n == 2
            else tuple(b.pose[3:].tolist())
            for b in robot.bodies
        ]
        self._single = robot.is_single
        self._half_height = float(max(robot.largest_semi_axis, 1.0))
        self._pose_size = pose_size(n)
        self.clearance_atol = CLEARANCE_ATOL * float(
            max(np.ptp(scenario.bounds, axis=0).max(), robot.reach)
        )
        self._horizon_boxes: dict[tuple[int, float], fcl.CollisionObject] = {}
        self._pair_request = fcl.DistanceRequest(enable_nearest_points=True)
        self._kernel: _core.World | None = None
        self._fcl_counters = {
            "collision_queries": 0,
            "distance_queries": 0,
            "region_queries": 0,
            "region_pairs": 0,
            "body_queries": 0,
        }
        self._fcl_body_counts = [0] * len(robot.bodies)

    @cached_property
    def _scene(self) -> tuple:
        """The obstacles' FCL objects, the obstacle index of each, the support function of
        each FCL geometry (by id; None where a piece has none) and the broad phase, made on
        first use: a planner on the compiled kernel never asks (a point cloud of 10^5
        points would otherwise cost a second of FCL objects)."""
        objects, owner, support_of = [], [], {}
        for ob in self.scenario.obstacles:
            parts = fcl_obstacle_parts(ob, self.dimension, self._half_height)
            for (geom, tf), support in zip(parts, piece_supports(ob), strict=True):
                support_of[id(geom)] = support
                objects.append(fcl.CollisionObject(geom, tf))
                owner.append(ob.index)
        manager = fcl.DynamicAABBTreeCollisionManager()
        if objects:
            manager.registerObjects(objects)
            manager.setup()
        return objects, owner, support_of, manager

    _objects = property(lambda self: self._scene[0])
    owner = property(lambda self: self._scene[1], doc="The obstacle index of each FCL object.")
    _support_of = property(lambda self: self._scene[2])
    _manager = property(lambda self: self._scene[3])

    @property
    def counters(self) -> dict[str, int]:
        """Queries issued through this world, python-fcl's and the kernel's together
        (see the class notes)."""
        if self._kernel is None:
            return dict(self._fcl_counters)
        compiled = self._kernel.counters
        return {key: value + compiled[key] for key, value in self._fcl_counters.items()}

    @property
    def body_query_counts(self) -> list[int]:
        """``body_queries`` per body, python-fcl's and the kernel's together."""
        if self._kernel is None:
            return list(self._fcl_body_counts)
        compiled = self._kernel.body_query_counts
        return [a + b for a, b in zip(self._fcl_body_counts, compiled, strict=True)]

    @property
    def kernel(self) -> _core.World:
        """The same world in the compiled kernel (:mod:`kcplan._kernel`), built on first
        use: the same obstacles as coal geometry in one broad phase, the same robot, and
        coal's own error allowance (:data:`kcplan._kernel.COAL_CLEARANCE_RTOL`). Its
        queries are counted in :attr:`counters`."""
        if self._kernel is None:
            self._kernel = build_kernel_world(self.scenario, self.robot, self._half_height)
        return self._kernel

    @property
    def n_objects(self) -> int:
        """Number of FCL objects (polygons contribute one per convex piece)."""
        return len(self._objects)

    def reset_counters(self) -> None:
        """Set the query counters to zero."""
        for key in self._fcl_counters:
            self._fcl_counters[key] = 0
        self._fcl_body_counts = [0] * len(self._bodies)
        if self._kernel is not None:
            self._kernel.reset_counters()

    def _place(self, pose: ArrayLike) -> None:
        """Move every body's FCL object to the robot pose ``pose``."""
        p = pose if isinstance(pose, np.ndarray) else np.asarray(pose, dtype=float)
        if p.shape != (self._pose_size,):
            raise ValueError(
                f"pose: expected {self._pose_size} numbers in {self.dimension}D, "
                f"got shape {p.shape}"
            )
        # plain floats: numpy costs microseconds per call on 4-vectors
        values = p.tolist()
        if not all(map(math.isfinite, values)):
            raise ValueError(f"pose: expected finite numbers, got {values}")
        if self.dimension == 2:
            x, y, yaw = values
            t, half = (x, y, 0.0), 0.5 * yaw
            q = (0.0, 0.0, math.sin(half), math.cos(half))
        else:
            x, y, z, qx, qy, qz, qw = values
            norm = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
            if norm == 0.0:
                raise ValueError("pose: expected a non-zero quaternion, got [0, 0, 0, 0]")
            t, q = (x, y, z), (qx / norm, qy / norm, qz / norm, qw / norm)
        if self._single:
            self._bodies[0].setTransform(
                fcl.Transform(np.array([q[3], q[0], q[1], q[2]]), np.array(t))
            )
            return
        for body, offset, turn in zip(self._bodies, self._offsets, self._turns, strict=True):
            ox, oy, oz = rotate_vector(q, offset)
            bx, by, bz, bw = quaternion_multiply(q, turn)
            centre = np.array([t[0] + ox, t[1] + oy, t[2] + oz])
            body.setTransform(fcl.Transform(np.array([bw, bx, by, bz]), centre))  # [w, x, y, z]

    def _count_body(self, k: int) -> None:
        self._fcl_counters["body_queries"] += 1
        self._fcl_body_counts[k] += 1

    def in_collision(self, pose: ArrayLike) -> bool:
        """Whether some body of the robot at ``pose`` touches or overlaps an obstacle
        (one collision query; one FCL query per body until a body collides)."""
        self._place(pose)
        self._fcl_counters["collision_queries"] += 1
        if not self._objects:
            return False
        for k, body in enumerate(self._bodies):
            self._count_body(k)
            if self._collides(body):
                return True
        return False

    def _collides(self, obj: fcl.CollisionObject) -> bool:
        """One broad- and narrow-phase collision query of ``obj`` against the obstacles."""
        data = fcl.CollisionData()
        self._manager.collide(obj, data, fcl.defaultCollisionCallback)
        return bool(data.result.is_collision)

    def body_clearances(self, pose: ArrayLike) -> NDArray[np.float64]:
        """Distance from each body of the robot at ``pose`` to the nearest obstacle, shape
        ``(k,)``: 0 when the body touches or overlaps one, ``inf`` without obstacles (one
        distance query; one FCL query per body). In length units. To a convex piece it is
        a lower bound whatever FCL's error (:meth:`_body_distance`); to a mesh piece it is
        FCL's, which may overestimate: see :meth:`safe_body_clearances`."""
        self._place(pose)
        self._fcl_counters["distance_queries"] += 1
        if not self._objects:
            return np.full(len(self._bodies), math.inf)
        out = np.empty(len(self._bodies))
        for k in range(len(self._bodies)):
            self._count_body(k)
            out[k] = self._body_distance(k)
        return out

    def _body_support(self, k: int) -> EllipsoidSupport:
        """The exact support function of body ``k`` as placed, in the scenario's
        dimension."""
        n, body = self.dimension, self._bodies[k]
        rotation = np.asarray(body.getRotation(), dtype=float)[:n, :n]
        centre = np.asarray(body.getTranslation(), dtype=float)[:n]
        return EllipsoidSupport(centre, rotation, self.robot.bodies[k].semi_axes)

    def _pair_distance(
        self, k: int, support: EllipsoidSupport, piece: fcl.CollisionObject
    ) -> tuple[float, float, NDArray | None, object]:
        """FCL's distance between body ``k`` and ``piece``, a lower bound of the true one
        (0 on contact), FCL's unit direction from the piece towards the body (None on
        contact or for a mesh piece, whose lower bound is FCL's distance itself) and the
        piece's support function (None for a mesh).

        The lower bound is the separation of the exact support functions along FCL's
        direction (:func:`kcplan.world.support.separation`), never too large whatever
        FCL's error. FCL's GJK errs differently with the pair's order (the thin pair of
        RESULTS 11.2: 7.6 % over with the body first, right with the piece first; a
        direction off by 10 degrees near contact in hand_through_slot), so when the
        first direction does not confirm FCL's distance the pair is asked the other way
        round too and the better bound kept. When neither confirms it, the bound is
        climbed from the better direction (:func:`kcplan.world.support.ascended_separation`):
        0.4 mm from a box, both of FCL's directions once bounded the distance by 0 only."""
        body, n = self._bodies[k], self.dimension
        fcl_d, low, u, piece_support = math.inf, 0.0, None, None
        tried = None  # FCL's first direction, whatever bound it gave
        for first, second in ((body, piece), (piece, body)):
            result = fcl.DistanceResult()
            d = fcl.distance(first, second, self._pair_request, result)
            if d <= 0.0:
                return 0.0, 0.0, None, None
            fcl_d = min(fcl_d, d)
            # FCL swaps the pair (and its nearest points) for some geometry types; its
            # result names the geometries we made (callbacks pass new object wrappers)
            if result.o1 is self._geometries[k]:
                geometry, (p_body, p_piece) = result.o2, result.nearest_points
            else:
                geometry, (p_piece, p_body) = result.o1, result.nearest_points
            piece_support = self._support_of[id(geometry)]
            if piece_support is None:  # a mesh: FCL's distance, under the allowance
                return d, d, None, None
            direction = np.asarray(p_body, dtype=float)[:n] - np.asarray(p_piece, dtype=float)[:n]
            length = math.sqrt(float(direction @ direction))
            if length == 0.0:
                continue
            v = direction / length  # from the piece towards the body
            tried = v if tried is None else tried
            bound = min(max(separation(piece_support, support, v), 0.0), d)
            if bound > low:
                low, u = bound, v
            if low >= d * (1.0 - CLEARANCE_RTOL):  # the direction confirms FCL's distance
                return fcl_d, low, u, piece_support
        if tried is not None:  # neither order's direction confirms: climb from the better
            bound, v = ascended_separation(
                piece_support, support, tried if u is None else u, fcl_d * (1.0 - CLEARANCE_RTOL)
            )
            if bound > low:
                low, u = min(bound, fcl_d), v
        return fcl_d, low, u, piece_support

    def _body_distance(self, k: int) -> float:
        """A lower bound of the distance from body ``k`` (placed) to every obstacle: the
        broad phase visits the pieces nearer than the smallest FCL distance so far, each
        is bounded by :meth:`_pair_distance`, and a piece the broad phase skips is farther
        than that FCL distance, which therefore bounds the answer too."""
        support = self._body_support(k)
        smallest = [math.inf, math.inf]  # FCL's distance (the pruning bound), lower bound
        failures: list[BaseException] = []

        def visit(piece, _robot, _data):  # the manager passes the robot as o2
            try:
                d, low, _, _ = self._pair_distance(k, support, piece)
            except BaseException as err:  # python-fcl would print it and carry on
                failures.append(err)
                return True, 0.0
            smallest[0], smallest[1] = min(smallest[0], d), min(smallest[1], low)
            return smallest[1] <= 0.0, smallest[0]

        self._manager.distance(self._bodies[k], None, visit)
        if failures:
            raise failures[0]
        return max(min(smallest), 0.0)

    def _distance(self, obj: fcl.CollisionObject) -> float:
        """One broad- and narrow-phase distance query of any FCL object (placed by the
        caller) against the obstacles, FCL's distance (0 on contact or overlap)."""
        data = fcl.DistanceData()
        self._manager.distance(obj, data, fcl.defaultDistanceCallback)
        return max(float(data.result.min_distance), 0.0)

    def _safe(self, d):
        """FCL's error allowance: ``max(d (1 - CLEARANCE_RTOL) - clearance_atol, 0)``."""
        return np.maximum(d * (1.0 - CLEARANCE_RTOL) - self.clearance_atol, 0.0)

    def clearance(self, pose: ArrayLike) -> float:
        """Distance from the robot at ``pose`` to the nearest obstacle, the minimum of
        :meth:`body_clearances` (one distance query)."""
        return float(self.body_clearances(pose).min())

    def safe_body_clearances(self, pose: ArrayLike) -> NDArray[np.float64]:
        """:meth:`body_clearances` reduced by FCL's error allowance, distances that are
        certain: ``max(d (1 - CLEARANCE_RTOL) - clearance_atol, 0)`` with
        ``clearance_atol = CLEARANCE_ATOL * scene size`` (one distance query; to convex
        pieces ``d`` is already a lower bound, the allowance is for mesh pieces)."""
        return self._safe(self.body_clearances(pose))

    def object_clearance(self, obj: fcl.CollisionObject) -> float:
        """Distance from any FCL object, placed by the caller, to the nearest obstacle,
        reduced by FCL's error allowance as in :meth:`safe_body_clearances` (one distance
        query; ``inf`` without obstacles). :mod:`kcplan.world.part` measures a robot's
        own mesh with it."""
        self._fcl_counters["distance_queries"] += 1
        if not self._objects:
            return math.inf
        return float(self._safe(self._distance(obj)))

    @property
    def half_height(self) -> float:
        """Half height of the prisms that stand for planar obstacles in FCL (2D)."""
        return self._half_height

    @property
    def reach(self) -> float:
        """:attr:`kcplan.geometry.robot.Robot.reach` of the robot queried."""
        return self.robot.reach

    def safe_clearance(self, pose: ArrayLike) -> float:
        """The minimum of :meth:`safe_body_clearances` (one distance query)."""
        return float(self.safe_body_clearances(pose).min())

    def free_regions(self, pose: ArrayLike, horizon: float) -> tuple[FreeRegion, ...]:
        """For each body of the robot at ``pose``: the separating planes and clearances of
        every obstacle piece within ``horizon`` of the body (one region query: per body a
        broad-phase query, then one narrow-phase distance per piece found; see
        :mod:`kcplan.world.region`).

        Pieces are found by their FCL bounding boxes overlapping the cube of half side
        ``max(a_k) + horizon`` around body ``k``'s centre, which contains every point
        within ``horizon`` of the body; a piece outside it is therefore at least
        ``horizon`` away. A body with no piece that close gets one distance query
        (counted as such) that widens its horizon to its clearance. As soon
        as a piece touches a body, every region is :meth:`FreeRegion.colliding`.
        """
        n = self.dimension
        self._place(pose)
        self._fcl_counters["region_queries"] += 1
        horizon = float(horizon)
        if not self._objects:
            return (FreeRegion.empty(n, math.inf),) * len(self._bodies)
        regions = []
        rtol = 1.0 - CLEARANCE_RTOL
        near: list[fcl.CollisionObject] = []

        def collect(o1, _o2, _data) -> bool:
            near.append(o1)
            return False  # keep going: every piece in the box

        for k, body in enumerate(self._bodies):
            self._count_body(k)
            box = self._horizon_box(k, horizon)
            box.setTranslation(body.getTranslation())
            near.clear()
            self._manager.collide(box, None, collect)
            self._fcl_counters["region_pairs"] += len(near)
            if not near:  # open space: the clearance to everything is the better horizon
                self._fcl_counters["distance_queries"] += 1
                d = self._body_distance(k)
                regions.append(FreeRegion.empty(n, max(horizon, d * rtol - self.clearance_atol)))
                continue
            normals, offsets, clearances = [], [], []
            support = self._body_support(k)
            for piece in near:
                d, low, u, piece_support = self._pair_distance(k, support, piece)
                if d <= 0.0:
                    return (FreeRegion.colliding(n),) * len(self._bodies)
                clearances.append(max(low * rtol - self.clearance_atol, 0.0))
                if u is None:  # a mesh piece (or a degenerate direction): its clearance only
                    normals.append(np.zeros(n))
                    offsets.append(math.inf)
                    continue
                normals.append(u)
                offsets.append(piece_support(u))
            regions.append(
                FreeRegion(
                    np.array(normals).reshape(-1, n),
                    np.array(offsets),
                    np.array(clearances),
                    horizon,
                )
            )
        return tuple(regions)

    def _horizon_box(self, k: int, horizon: float) -> fcl.CollisionObject:
        """The broad-phase box of body ``k`` for ``horizon`` (built once)."""
        box = self._horizon_boxes.get((k, horizon))
        if box is None:
            side = 2.0 * (float(self.robot.bodies[k].semi_axes.max()) + horizon)
            height = side if self.dimension == 3 else 4.0 * self._half_height  # every prism
            box = fcl.CollisionObject(fcl.Box(side, side, height), fcl.Transform())
            self._horizon_boxes[(k, horizon)] = box
        return box

    def ball_collides(self, center: ArrayLike, radius: float) -> bool:
        """Whether the ball (2D: disc) of ``radius`` about ``center`` meets an obstacle
        (one FCL collision query; builds :class:`kcplan.world.occupancy.CoreOccupancy`)."""
        self._fcl_counters["collision_queries"] += 1
        if not self._objects:
            return False
        c = np.zeros(3)
        c[: self.dimension] = np.asarray(center, dtype=float)[: self.dimension]
        ball = fcl.CollisionObject(fcl.Sphere(float(radius)), fcl.Transform(c))
        return self._collides(ball)

    def sweep_core_collides(self, t1: ArrayLike, t2: ArrayLike, radius: float) -> bool:
        """Whether the capsule of ``radius`` around the segment ``t1 -> t2`` (centre
        positions) meets an obstacle (one FCL collision query).

        The robot contains the ball of radius ``min(a)`` about its centre in every
        orientation, so when the robot's centre moves along the segment with that
        radius, a hit proves that the motion collides; it never proves a motion free.
        """
        n = self.dimension
        a = [float(v) for v in t1[:n]] + [0.0] * (3 - n)
        b = [float(v) for v in t2[:n]] + [0.0] * (3 - n)
        self._fcl_counters["collision_queries"] += 1
        if not self._objects:
            return False
        dx, dy, dz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
        length = math.sqrt(dx * dx + dy * dy + dz * dz)
        centre = np.array([0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])])
        # the rotation taking the capsule's z axis onto the segment, as the half-way
        # quaternion [w, x, y, z] = normalise([1 + z . u, z x u]) for u = segment / length
        if length > 0.0:
            ux, uy, uz = dx / length, dy / length, dz / length
        else:
            ux, uy, uz = 0.0, 0.0, 1.0
        w, qx, qy = 1.0 + uz, -uy, ux
        norm = math.sqrt(w * w + qx * qx + qy * qy)
        q = np.array([w / norm, qx / norm, qy / norm, 0.0] if norm > 1e-9 else [0.0, 1.0, 0.0, 0.0])
        capsule = fcl.CollisionObject(fcl.Capsule(float(radius), length), fcl.Transform(q, centre))
        return self._collides(capsule)

    def in_collision_many(self, poses: ArrayLike) -> NDArray[np.bool_]:
        """:meth:`in_collision` for each row of ``poses`` (shape ``(k, 3 or 7)``)."""
        P = np.asarray(poses, dtype=float).reshape(-1, self._pose_size)
        return np.array([self.in_collision(p) for p in P], dtype=bool)

    def clearance_many(self, poses: ArrayLike) -> NDArray[np.float64]:
        """:meth:`clearance` for each row of ``poses`` (shape ``(k, 3 or 7)``)."""
        P = np.asarray(poses, dtype=float).reshape(-1, self._pose_size)
        return np.array([self.clearance(p) for p in P], dtype=float)

    def colliding_obstacles(self, pose: ArrayLike) -> list[int]:
        """Indices of the obstacles some body of the robot at ``pose`` touches (diagnostics; one
        narrow-phase test per FCL object, not counted)."""
        self._place(pose)
        request, hits = fcl.CollisionRequest(), []
        for obj, owner in zip(self._objects, self.owner, strict=True):
            if owner not in hits and any(
                fcl.collide(body, obj, request, fcl.CollisionResult()) for body in self._bodies
            ):
                hits.append(owner)
        return hits
