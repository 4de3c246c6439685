"""The compiled certification kernel: C++17 on coal, bound with nanobind.

One ``checkMotion`` of a kc planner is one call into :class:`EdgeCertifier`, which does
the whole decision in C++ (guard cache, occupancy grid, core sweep, guards, certificates,
advancement) against :class:`World`, the scenario's obstacles as coal geometry in one
broad phase. Each C++ class has a Python twin that is the readable reference and is tested
against it edge by edge:

======================================= ======================================================
C++ (``kcplan/_kernel/``)               Python twin
======================================= ======================================================
``pose.hpp`` ``Pose``, ``Edge``         :mod:`kcplan.geometry.pose`
``robot.hpp`` ``Robot``                 :mod:`kcplan.geometry.robot`
``world.hpp`` ``World``                 :class:`kcplan.world.CollisionWorld`
``occupancy.hpp``                       :mod:`kcplan.world.occupancy`
``guard.hpp``                           :mod:`kcplan.certification.guard`
``certificates.hpp``                    :mod:`kcplan.certification.certificates`
``certifier.hpp`` ``EdgeCertifier``     :mod:`kcplan.certification.certifier`
``mesh_planes.hpp`` ``MeshPlanes``      none: python-fcl measures meshes with
                                        FCL's BVH; tested against it
``primitive_bound.hpp`` ``Primitive``   none: a shortcut before GJK for boxes, balls
                                        and cylinders; tested against exact distances
``point_cloud.hpp`` ``PointCloud``      each point an FCL ball
                                        (:func:`kcplan.world.collision.fcl_obstacle_parts`);
                                        tested against measuring every point
``chain.hpp`` ``Chain``                 :mod:`kcplan.arm.kinematics`, :mod:`kcplan.arm.bounds`
``arm_world.hpp`` ``ArmWorld``          :class:`kcplan.arm.ArmWorld`
``pair_motion.hpp`` ``PairFirstOrder``  :func:`kcplan.arm.bounds.relative_first_order`
``arm_certifier.hpp`` ``ArmCertifier``  :mod:`kcplan.certification.arm_certifier`
``enclosing.hpp``                       :func:`kcplan.geometry.enclosing.khachiyan_weights`
======================================= ======================================================

Conventions: poses are flat, ``[x, y, yaw]`` or ``[x, y, z, qx, qy, qz, qw]`` (scalar
last), lengths in the scenario's unit. Errors (a pose that is not finite given to a world
query, degenerate geometry, a wrong number of pose values) raise ``ValueError`` with one
line saying what was expected; nothing aborts the process. An edge or state with a
non-finite pose is never free: the certifier rejects it. Nothing here is thread-safe: a
world reuses its coal objects and solvers between queries, so use one world (and its
certifiers) per thread.

The extension links coal and Boost from the installed ``libcoal`` wheel (``RPATH``
``site-packages/cmeel.prefix/lib``), so it imports in a fresh process with no environment
variables.
"""

from __future__ import annotations

import functools
import hashlib
import weakref
from pathlib import Path

import numpy as np

from kcplan._kernel import _core
from kcplan._kernel._core import (
    ArmCertifier,
    ArmMotionValidator,
    ArmPlan,
    ArmRRTConnect,
    ArmWorld,
    CertifiedArmMotions,
    Chain,
    CloudOrder,
    DiscreteArmMotions,
    EdgeCertifier,
    Robot,
    ScreenedArmMotions,
    World,
)

__all__ = [
    "COAL_CLEARANCE_ATOL",
    "COAL_CLEARANCE_FLOOR",
    "COAL_CLEARANCE_RTOL",
    "EdgeCertifier",
    "Robot",
    "World",
    "ArmCertifier",
    "ArmMotionValidator",
    "ArmPlan",
    "ArmRRTConnect",
    "ArmWorld",
    "CertifiedArmMotions",
    "Chain",
    "CloudOrder",
    "DiscreteArmMotions",
    "ScreenedArmMotions",
    "add_obstacles",
    "arm_digest",
    "build_kernel_arm",
    "build_kernel_world",
    "kernel_chain",
    "kernel_digest",
    "kernel_robot",
]

REACH_MARGIN = 1e-3
"""Metres a cloud keeps beyond an arm's reach and padding (:func:`build_kernel_arm`)."""

COAL_CLEARANCE_RTOL = 2e-3
"""Relative error allowed for coal's GJK distances (as python-fcl's,
:data:`kcplan.world.collision.CLEARANCE_RTOL`). coal stops GJK within ``tol (1 + d)`` of
the distance ``d`` (``tol = 1e-6``, set in ``world.cpp``; a ball adds its radius to ``d``).
Against 220,000 exact distances (1e-6 to 1e4) of an ellipsoid robot to half-spaces, boxes,
polytopes, polygons, balls and ellipsoids, ``python scripts/coal_distance_error.py``
(seeds 1 and 2), coal overestimated by at most 1.3e-6 of the distance beyond 10 units:
1,500 times below this allowance. The kernel starts each pair's GJK where the pair's last
query ended (ten poses per world in that script): a warm start changes how fast GJK
converges, not when it stops, and the script measured the same (at most 1.2e-6 of the
distance, worst use of the allowance 0.24, seed 1).

An arm link's convex hull (a coal ``Convex`` of 18-4,093 vertices; ``convex_body.hpp``)
is held to the same allowance: GJK's stopping test is the same for any pair of convex
shapes, and against an independent reference (the largest separation of the two shapes'
exact support functions over directions, a lower bound of the distance at every
direction and the distance at the best; ``tests/test_arm_hulls.py``,
``test_coal_distances_of_hulls_are_below_the_true_distance``) no certain clearance of a
hull, to an obstacle or to another hull, exceeded the distance (RESULTS 13.6)."""
COAL_CLEARANCE_ATOL = 1e-6
"""Absolute error allowed for coal's distances, as a fraction of the scene's size (the
largest side of the bounds, or the robot's reach if larger). Not enough in scenes under
about 1 unit wide: near contact coal's excess is absolute, up to 1.0e-6 length units
(``1e-6 (1 + r)`` next to a ball of radius ``r``) at every ``--scale`` of the same script
from 0.01 to 100. At scale 1 the worst use of ``rtol d + atol s`` was 0.80 (seed 1) and
1.03 (seed 2: one sample, in a scene 0.81 wide); at ``--scale 0.1`` 415 of 220,000 samples
exceeded it. Hence :data:`COAL_CLEARANCE_FLOOR`."""
COAL_CLEARANCE_FLOOR = 2e-6
"""Absolute error allowed for coal's distances in length units, times ``1 + r`` with
``r`` the largest ball obstacle's radius: coal's GJK stops within ``1e-6 (1 + d)`` of the
distance, and handles a ball as its centre plus radius. Twice that tolerance; with it
no sample of ``scripts/coal_distance_error.py`` exceeded the allowance at any ``--scale``
from 0.01 to 100 (worst use 0.48). The kernel's ``atol`` is
``COAL_CLEARANCE_ATOL * scene size + COAL_CLEARANCE_FLOOR * (1 + r)``."""


def kernel_robot(robot) -> _core.Robot:
    """The kernel's twin of a :class:`kcplan.geometry.robot.Robot`."""
    n = robot.dimension
    semi_axes = [float(v) for b in robot.bodies for v in b.semi_axes]
    poses = [float(v) for b in robot.bodies for v in b.pose]
    return _core.Robot(n, semi_axes, poses)


def _embed(rotation: np.ndarray) -> list[float]:
    R = np.eye(3)
    R[: rotation.shape[0], : rotation.shape[1]] = rotation
    return R.ravel().tolist()


def build_kernel_world(scenario, robot, half_height: float) -> _core.World:
    """The scenario's obstacles and ``robot`` as a kernel :class:`World`.

    Parameters
    ----------
    scenario : kcplan.world.Scenario
    robot : kcplan.geometry.robot.Robot
    half_height : float
        Half height of the 2D obstacles' prisms (as in the python-fcl world).
    """
    n = scenario.dimension
    size = max(float(np.ptp(scenario.bounds, axis=0).max()), robot.reach)
    ball = max(
        (float(ob.extents[0]) for ob in scenario.obstacles if ob.kind in ("circle", "sphere")),
        default=0.0,
    )
    atol = COAL_CLEARANCE_ATOL * size + COAL_CLEARANCE_FLOOR * (1.0 + ball)
    world = _core.World(kernel_robot(robot), float(half_height), COAL_CLEARANCE_RTOL, atol)
    world.padding = float(getattr(scenario, "padding", 0.0))
    add_obstacles(world, scenario.obstacles, n)
    world.finalize()
    return world


def add_obstacles(world: _core.World, obstacles, n: int) -> None:
    """Add :class:`kcplan.world.obstacles.Obstacle` s of an ``n``-D scene to a kernel world
    (before its first query)."""
    for ob in obstacles:
        centre = [float(v) for v in ob.center] + [0.0] * (3 - n)
        if ob.kind in ("polygon", "box") and n == 2:
            for piece in ob.pieces:
                world.add_prism(np.asarray(piece, dtype=float).ravel().tolist())
        elif ob.kind == "box":
            world.add_box(centre, _embed(ob.rotation), [float(v) for v in ob.extents])
        elif ob.kind in ("circle", "sphere"):
            world.add_sphere(centre, float(ob.extents[0]))
        elif ob.kind in ("ellipse", "ellipsoid"):
            axes = [float(v) for v in ob.extents]
            world.add_ellipsoid(centre, _embed(ob.rotation), axes if n == 3 else [*axes, min(axes)])
        elif ob.kind == "cylinder":  # arm scenes; extents (r, r, h / 2)
            world.add_cylinder(
                centre, _embed(ob.rotation), float(ob.extents[0]), float(ob.extents[2])
            )
        elif ob.kind == "convex":
            world.add_convex(ob.vertices.ravel().tolist(), ob.triangles.ravel().tolist())
        elif ob.kind == "mesh":
            world.add_mesh(ob.vertices.ravel().tolist(), ob.triangles.ravel().tolist())
        elif ob.kind in ("pointcloud", "depth"):  # extents: the planning radius
            world.add_points(np.ascontiguousarray(ob.vertices, dtype=float), float(ob.extents[0]))
        else:  # pragma: no cover - the scenario loader knows no other kind
            raise ValueError(f"{ob.label}: unknown obstacle kind {ob.kind!r}")


_DIGESTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_CHAINS: dict[str, _core.Chain] = {}
_MOST_CHAINS = 16
"""Chains kept by :func:`kernel_chain` (the oldest is let go first): a Panda's is 0.3 MB."""


@functools.lru_cache(maxsize=1)
def kernel_digest() -> str:
    """A digest of the compiled kernel's file: what a cache of the kernel's results (the
    self pairs' proofs, :mod:`kcplan.arm.pairs`) keys on, so that a rebuilt kernel never
    reuses another's results."""
    return hashlib.sha256(Path(_core.__file__).read_bytes()).hexdigest()


def arm_digest(arm) -> str:
    """A digest of an :class:`kcplan.arm.ArmModel` as the kernel reads it (what
    :func:`kernel_chain` reads: joints, placements, axes, kinds, limits, wrapping, bodies
    and hulls) and of the kernel itself (:func:`kernel_digest`).

    Two arms of one digest are one arm to the kernel, so what it made of one serves the
    other: its chain (:func:`kernel_chain`) and its self pairs' proofs
    (:mod:`kcplan.arm.pairs`). A scenario read again (each MotionBenchMaker problem is
    its own scenario) loads a new arm of the same robot, and the chain and the proofs
    cost 2 ms of its first plan (RESULTS 36.1). Computed once per arm object (0.5 ms for
    the Panda)."""
    digest = _DIGESTS.get(arm)
    if digest is None:
        model = arm.model
        h = hashlib.sha256(kernel_digest().encode())
        h.update(repr((arm.kinds, arm.joints, list(model.parents))).encode())
        for array in (arm.lower, arm.upper, arm.q_index,
                      np.zeros(0) if arm.wraps is None else arm.wraps):  # fmt: skip
            h.update(np.ascontiguousarray(array).tobytes())
        for i in range(1, model.njoints):
            h.update(np.asarray(model.jointPlacements[i].homogeneous, dtype=float).tobytes())
        h.update(np.asarray(arm.joint_axes(), dtype=float).tobytes())
        for body in arm.bodies:
            h.update(repr(body.joint).encode() + body.placement.tobytes())
            h.update(body.semi_axes.tobytes())
            if body.hull is not None:
                h.update(body.hull.vertices.tobytes() + body.hull.triangles.tobytes())
        digest = _DIGESTS[arm] = h.hexdigest()
    return digest


def kernel_chain(arm) -> _core.Chain:
    """The kernel's twin of an :class:`kcplan.arm.ArmModel`'s chain and bodies: the
    reduced model's joint placements, axes and kinds (``arm.joint_axes()``), each joint's
    place in the state, the limits and the bodies (a hull's vertices and triangles with
    it). The kernel imports nothing of kcplan's above it: the arm is read, not imported.

    Made once per arm as the kernel reads it (:func:`arm_digest`; a :class:`Chain` is an
    immutable description that each kernel world copies, sharing its hulls): building
    the hulls' coal geometry again cost 2.4 ms of every Panda plan."""
    digest = arm_digest(arm)
    chain = _CHAINS.get(digest)
    if chain is None:
        if len(_CHAINS) >= _MOST_CHAINS:
            del _CHAINS[next(iter(_CHAINS))]
        chain = _CHAINS[digest] = _build_chain(arm)
    return chain


def _build_chain(arm) -> _core.Chain:
    model = arm.model
    state_of = {int(i): j for j, i in enumerate(arm.q_index)}
    axes = arm.joint_axes()
    parents, placements, axis, prismatic, states = [], [], [], [], []
    for i in range(1, model.njoints):
        parents.append(int(model.parents[i]))
        placements += np.asarray(model.jointPlacements[i].homogeneous, dtype=float).ravel().tolist()
        axis += axes[i].tolist()
        states.append(state_of[int(model.joints[i].idx_q)])
        prismatic.append(arm.kinds[states[-1]] == "prismatic")
    return _core.Chain(
        parents, placements, axis, prismatic, states,
        arm.lower.tolist(), arm.upper.tolist(),
        [int(b.joint) for b in arm.bodies],
        [float(v) for b in arm.bodies for v in b.placement.ravel()],
        [float(v) for b in arm.bodies for v in b.semi_axes],
        [[] if b.hull is None else b.hull.vertices.ravel().tolist() for b in arm.bodies],
        [[] if b.hull is None else b.hull.triangles.ravel().tolist() for b in arm.bodies],
        [] if arm.wraps is None else [bool(w) for w in arm.wraps],
    )  # fmt: skip


def build_kernel_arm(world) -> _core.ArmWorld:
    """The kernel's twin of an :class:`kcplan.arm.ArmWorld`: the same chain, bodies, self
    pairs and obstacles, with coal's error allowance for a scene of the world's size
    (:data:`COAL_CLEARANCE_ATOL`, :data:`COAL_CLEARANCE_FLOOR`)."""
    ball = max((float(ob.extents[0]) for ob in world.obstacles if ob.kind == "sphere"), default=0.0)
    atol = COAL_CLEARANCE_ATOL * world.size + COAL_CLEARANCE_FLOOR * (1.0 + ball)
    pairs = [(int(k), int(m)) for k, m in world.self_pairs]
    kernel = _core.ArmWorld(kernel_chain(world.arm), pairs, COAL_CLEARANCE_RTOL, atol)
    kernel.scene.padding = float(world.padding)
    own = world.link_padding  # a link's own padding, for its bodies
    for k, body in enumerate(world.arm.bodies):
        if body.link in own:
            kernel.scene.set_body_padding(k, float(own[body.link]))
    if any(ob.kind in ("pointcloud", "depth") for ob in world.obstacles):
        # a cloud keeps the points the padded bodies can meet (1 mm beyond, for coal's
        # allowance of about 1e-6 m): a third of an MBM Panda cloud lies farther
        centre, radius = world.reach
        padding = max([float(world.padding), *map(float, own.values())])
        kernel.scene.set_reach([float(v) for v in centre], radius + padding + REACH_MARGIN)
    add_obstacles(kernel.scene, world.obstacles, 3)
    kernel.scene.finalize()
    return kernel
