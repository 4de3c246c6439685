"""An arm robot from its URDF: the chain, its joint limits and the bodies that represent
its links, as one immutable description.

Pinocchio reads the URDF (``pinocchio.buildModelFromUrdf``: joints, limits, placements)
and its collision geometry (``pinocchio.buildGeomFromUrdf``), and removes the SRDF's
disabled collision pairs (``pinocchio.removeCollisionPairs``). The *planning group* is a
list of joints in state order; every other joint is locked at a fixed value
(``pinocchio.buildReducedModel``), so the reduced model's configuration is exactly the
group's joint vector (``nq`` = number of joints in the group).

*Representations.* By default (``representation="hulls"``) every link is its own convex
geometry (:mod:`kcplan.arm.hulls`): a mesh by its convex hull (exact for a convex mesh),
or where that hull exceeds a closed mesh by a mean gap of more than
:data:`kcplan.arm.hulls.MAX_GAP` by the hulls of up to
:data:`kcplan.arm.hulls.MAX_PIECES` pieces cut by planes
(:func:`~kcplan.arm.hulls.hull_pieces`); a box exactly, a cylinder by a circumscribed
prism, a sphere exactly (as an ellipsoid). Such a body keeps a bounding ball
(``semi_axes`` all equal to its radius) for the speed bounds, and its hull for the
collision queries. With ``representation="ellipsoids"`` every collision geometry is
covered by ellipsoids (what the KC certificate needs): a mesh by :mod:`kcplan.cover` (its own
triangles, a sound cover, cached per user; by default cut until it sticks out of the mesh
by at most :data:`DEFAULT_MAX_OFFSET`, or a fixed number of bodies per link; a mesh that
is not closed, such as the Panda's link6, by a cover of its convex hull, which holds every
triangle), a sphere exactly, a box
and a cylinder by the smallest ellipsoid through their corners or rims (below). A body's
frame is given in the frame of the joint that carries it (``placement``, a 4 x 4
homogeneous matrix: the geometry's placement in the joint frame times the body's pose in
the geometry's frame), so its world frame at a configuration is ``oMi[joint] @
placement`` (:func:`kcplan.arm.kinematics.body_frames`).

Enclosing ellipsoids of primitives (each contains the primitive, proof by the extreme
points): the box of half sizes ``h`` lies in the ellipsoid of semi-axes ``sqrt(3) h``
(a corner has ``sum (h_i / (sqrt(3) h_i))^2 = 1``, and the box is the hull of its
corners); the cylinder of radius ``r`` and half height ``c`` lies in the ellipsoid of
semi-axes ``(sqrt(3/2) r, sqrt(3/2) r, sqrt(3) c)`` (a rim point has ``r^2 / (3/2 r^2) +
c^2 / (3 c^2) = 2/3 + 1/3 = 1``, and the cylinder is the hull of its two rims).

This module reads files and fits covers; it imports neither OMPL nor FCL.
"""

from __future__ import annotations

import math
import os
import re
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from kcplan.arm.bounds import speeds
from kcplan.arm.description import (
    Description,
    DescriptionError,
    PlanarBase,
    read_description,
    unwrapped,
    wrapped,
)
from kcplan.arm.hulls import BodyHull, box_hull, cached_hull_pieces, cylinder_hull
from kcplan.arm.kinematics import JOINT_KINDS, body_frames, joint_axes
from kcplan.arm.shapes import bvh_mesh
from kcplan.cover.cache import cached_cover
from kcplan.cover.fit import Cover
from kcplan.cover.solid import SolidError
from kcplan.geometry.pose import quaternion_matrix
from kcplan.geometry.robot import MAX_BODIES
from kcplan.geometry.robot_model import RobotModel

__all__ = [
    "DEFAULT_MAX_OFFSET",
    "LIMIT_TOLERANCE",
    "REPRESENTATIONS",
    "JOINT_KINDS",
    "ArmBody",
    "ArmError",
    "ArmModel",
    "hull_bodies",
    "load_arm",
    "mesh_cover",
    "package_folders",
    "plannable_joint",
    "self_pairs_of",
    "movable_joints",
    "urdf_model",
]

DEFAULT_MAX_OFFSET = 0.01
"""How far, in metres, a link's cover may stick out of its mesh when nothing else is
asked (:func:`load_arm`). Why 10 mm: on the links' own meshes, MotionBenchMaker's 700
Panda goals leave the scene 6.9 mm (1st percentile) to 11 mm (5th) from link5, 8.7-13 mm
from link6, 12-17 mm from the hand and 11-22 mm from the fingers; a cover within 10 mm of
its mesh is clear of every obstacle the mesh is more than 10 mm from, which is so at 652
of the 700 goals, and in fact the default cover leaves 670 of 700 goals and 700 of 700
starts valid (``scripts/mbm_validity.py --per-class 100 --max-offset default``), where 4
bodies per link left 60 of the first 70 goals. The cost: 286 bodies (the links 0-6 and
the hand stop at :data:`kcplan.cover.fit.MAX_OFFSET_BODIES` bodies, 12-21 mm out) and
13,056 self pairs, against 44 and 336 for 4 bodies per link, and about 20 minutes to fit
once (cached). With at most 16 bodies per link: 148 bodies, 3,584 self pairs, 655 of 700
goals."""

LIMIT_TOLERANCE = 1e-5
"""How far (radians, or metres for a prismatic joint) a start or goal may lie outside a
joint limit and still be taken, clamped to the limit (:meth:`ArmModel.clamp`): data sets
write a joint at pi where the URDF's limit is 3.14159 (MotionBenchMaker's mobile
manipulator: 2.7e-6 outside), and MoveIt accepts such a state within its bounds margin."""

REPRESENTATIONS = ("hulls", "ellipsoids")
"""How links are represented (module docstring); the first is the default."""



class ArmError(ValueError):
    """An arm that cannot be built; ``str(err)`` is ``FILE: FIELD: expected ..., got ...``."""


@dataclass(frozen=True, eq=False)
class ArmBody:
    """One body of a link: a covering ellipsoid, or the link's convex hull.

    Attributes
    ----------
    link : str
        The URDF link whose collision geometry it covers.
    geometry : int
        Index of that geometry in :attr:`ArmModel.geometry`.
    joint : int
        Index, in the reduced model, of the joint that carries the link (0: the universe,
        a body that never moves).
    placement : ndarray, shape (4, 4)
        The body's frame in the joint's frame (its centre and axes).
    semi_axes : ndarray, shape (3,)
        Along the body frame's x, y, z, in metres: the ellipsoid, or for a hull its
        bounding ball (three times its radius), which holds it.
    hull : BodyHull or None
        The convex body in the body's frame, or None for an ellipsoid.
    """

    link: str
    geometry: int
    joint: int
    placement: NDArray[np.float64]
    semi_axes: NDArray[np.float64]
    hull: BodyHull | None = None


@dataclass(frozen=True, eq=False)
class ArmModel(RobotModel):
    """An arm: the reduced chain of its planning group and the bodies covering its links
    (see the module docstring). Build it with :func:`load_arm`.

    One implementation of :class:`kcplan.geometry.robot_model.RobotModel`: a state is the
    group's joint vector, an edge the straight joint-space segment, and a body's speed
    the chain's bound ``sum_j rho[k, j] |q2_j - q1_j|`` (:func:`kcplan.arm.bounds.speeds`).

    Attributes
    ----------
    model : pinocchio.Model
        The chain with every joint outside the group locked; ``model.nq == len(joints)``.
    geometry : pinocchio.GeometryModel
        The links' collision geometry on ``model``, with the collision pairs left after
        the SRDF's disabled pairs were removed.
    joints : tuple of str
        The planning group, in state order.
    q_index : ndarray of int, shape (len(joints),)
        Where each joint of the state sits in ``model``'s configuration vector.
    lower, upper : ndarray, shape (len(joints),)
        Joint limits (radians, or metres for a prismatic joint), from the URDF.
    kinds : tuple of str
        ``revolute`` or ``prismatic``, per joint of the group.
    bodies : tuple of ArmBody
        Every covering ellipsoid.
    self_pairs : ndarray of int, shape (m, 2)
        Pairs of body indices ``(i, j)``, ``i < j``, that may collide with each other: their
        geometries form a collision pair of :attr:`geometry`.
    urdf, srdf : str
        The files read (``srdf`` empty when none was given).
    package_dirs : tuple of str
        The folders of ``package://`` URIs given to :func:`load_arm`.
    attached : tuple of kcplan.arm.attach.Attached
        The objects the arm holds (:func:`kcplan.arm.attach.attach`), each one more
        collision object of :attr:`geometry` and bodies named after it.
    base_geometry : pinocchio.GeometryModel or None
        :attr:`geometry` without the attached objects (None when none is attached).
    wraps : ndarray of bool, shape (len(joints),) or None
        Which joints' angles wrap (a moving base's yaw, a continuous joint:
        :mod:`kcplan.arm.description`); None: none does.
    description : Description or None
        The URDF as Pinocchio read it (:func:`kcplan.arm.description.read_description`): every
        other reader of the robot's tree (the views' visual geometry) reads it alike.
    """

    model: object
    geometry: object
    joints: tuple[str, ...]
    q_index: NDArray[np.int64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    kinds: tuple[str, ...]
    bodies: tuple[ArmBody, ...]
    self_pairs: NDArray[np.int64]
    urdf: str
    srdf: str = ""
    package_dirs: tuple[str, ...] = ()
    attached: tuple = ()
    base_geometry: object = None
    wraps: NDArray[np.bool_] | None = None
    description: Description | None = None

    @property
    def base(self) -> PlanarBase | None:
        """The moving base (:class:`kcplan.arm.description.PlanarBase`), or None."""
        return None if self.description is None else self.description.base

    @property
    def dof(self) -> int:
        """Number of joints in the planning group (the state's length)."""
        return len(self.joints)

    @property
    def state_size(self) -> int:
        """:attr:`dof`: a state is the joint vector."""
        return self.dof

    @property
    def workspace_dimension(self) -> int:
        return 3

    @property
    def body_count(self) -> int:
        return len(self.bodies)

    def describe(self) -> str:
        """One line for reports: ``arm of 7 joints, 44 bodies (panda.urdf)``."""
        return f"arm of {self.dof} joints, {len(self.bodies)} bodies ({Path(self.urdf).name})"

    def body_frames(self, state: Sequence[float]) -> NDArray[np.float64]:
        """World frames of the bodies, shape ``(len(bodies), 4, 4)``
        (:func:`kcplan.arm.kinematics.body_frames`)."""
        return body_frames(self, state)

    def joint_axes(self) -> NDArray[np.float64]:
        """Unit axis of every joint of the reduced model in its own frame, shape
        ``(njoints, 3)`` (:func:`kcplan.arm.kinematics.joint_axes`)."""
        return joint_axes(self)

    def edge_state(
        self, state1: Sequence[float], state2: Sequence[float], s: float
    ) -> NDArray[np.float64]:
        """``q1 + s (q2 - q1)``: OMPL's interpolation in the joint box, a wrapping angle
        the shorter way round (:meth:`edge_end`)."""
        q1 = np.asarray(state1, dtype=float)
        return q1 + s * (self.edge_end(q1, state2) - q1)

    def edge_end(self, state1: Sequence[float], state2: Sequence[float]) -> NDArray[np.float64]:
        """Where the straight edge from ``state1`` ends: ``state2``, with every wrapping
        angle at ``state1``'s plus the shorter turn (:func:`kcplan.arm.description.unwrapped`;
        outside ``[-pi, pi]`` where the turn crosses it), shape ``(dof,)``."""
        if self.wraps is None:
            return np.asarray(state2, dtype=float)
        return unwrapped(state1, state2, self.wraps)

    def continuous(self, states: Sequence[Sequence[float]]) -> NDArray[np.float64]:
        """A path's states ``(k, dof)`` with every wrapping angle unwrapped along it: each
        state the previous one's :meth:`edge_end`, so that straight segments between the
        rows are the path's edges (what a timing law, a verifier or a view of the path
        interpolates); shape ``(k, dof)``."""
        out = np.array(states, dtype=float, ndmin=2)
        if self.wraps is not None:
            for k in range(1, len(out)):
                out[k] = unwrapped(out[k - 1], out[k], self.wraps)
        return out

    def body_speeds(self, state1: Sequence[float], state2: Sequence[float]) -> NDArray[np.float64]:
        """Metres per unit ``s`` (:func:`kcplan.arm.bounds.speeds`)."""
        return speeds(self, state1, self.edge_end(state1, state2))

    def configuration(self, state: Sequence[float]) -> NDArray[np.float64]:
        """The reduced model's configuration vector of a state ``(dof,)`` (joint values in
        :attr:`joints` order)."""
        state = np.asarray(state, dtype=float)
        if state.shape != (self.dof,):
            raise ValueError(f"state: expected {self.dof} joint values, got shape {state.shape}")
        q = np.zeros(self.dof)
        q[self.q_index] = state
        return q

    def clamp(
        self, q: Sequence[float], tolerance: float = LIMIT_TOLERANCE
    ) -> tuple[NDArray[np.float64], list[str], list[str]]:
        """``q`` (shape ``(dof,)``, finite) with every value within ``tolerance`` outside
        its joint's limits moved onto the limit, and every wrapping angle taken into
        ``[-pi, pi)``.

        Returns
        -------
        q : ndarray, shape (dof,)
            The clamped values.
        clamped : list of str
            One entry per value moved: ``NAME VALUE -> LIMIT``, every digit shown.
        outside : list of str
            One entry per value farther out: ``NAME VALUE > UPPER`` (or ``< LOWER``), with
            the digits that show the difference (``3.141592653589793 > 3.14159``).
        """
        q = np.array(q, dtype=float)
        if self.wraps is not None:  # any angle of a wrapping joint, taken into [-pi, pi)
            q = np.where(self.wraps, wrapped(q), q)
        clamped, outside = [], []
        for j, (name, lo, hi) in enumerate(zip(self.joints, self.lower, self.upper, strict=True)):
            v = float(q[j])
            for beyond, limit, sign in ((v > hi, float(hi), ">"), (v < lo, float(lo), "<")):
                if not beyond:
                    continue
                if abs(v - limit) <= tolerance:
                    clamped.append(f"{name} {v!r} -> {limit!r}")
                    q[j] = limit
                else:
                    outside.append(f"{name} {v!r} {sign} {limit!r}")
        return q, clamped, outside

    def within_limits(self, q: Sequence[float]) -> bool:
        """Whether ``q`` (shape ``(dof,)``) is finite and inside the joint limits (a
        wrapping angle: any finite angle)."""
        q = np.asarray(q, dtype=float)
        if q.shape != (self.dof,) or not np.isfinite(q).all():
            return False
        inside = (q >= self.lower) & (q <= self.upper)
        return bool((inside | (False if self.wraps is None else self.wraps)).all())


def urdf_model(urdf: str | os.PathLike, base: PlanarBase | None = None):
    """The URDF's whole joint tree, as Pinocchio reads it (``pinocchio.Model``, no joint
    locked; with ``base``, the base's joints above its root, and continuous joints as
    wrapping revolute ones: :mod:`kcplan.arm.description`): what :func:`movable_joints`
    and an SRDF's groups (:meth:`kcplan.arm.srdf.Srdf.group_joints`) are read against.

    Raises
    ------
    ArmError
        ``URDF: urdf: expected a readable URDF, got: ...`` for a file Pinocchio cannot
        read; ``URDF: robot.base: ...`` for a base the URDF cannot take.
    """
    try:
        return read_description(urdf, base).model()
    except DescriptionError as err:
        raise ArmError(str(err)) from None
    except (RuntimeError, ValueError, OSError) as err:
        raise ArmError(f"{urdf}: urdf: expected a readable URDF, got: {err}") from None


def movable_joints(urdf: str | os.PathLike, base: PlanarBase | None = None) -> list[str]:
    """Every joint of the URDF that kcplan can move (revolute, continuous or prismatic, and
    the base's), in the URDF's order: the planning group when none is named.

    Raises
    ------
    ArmError
        ``URDF: urdf: expected a readable URDF, got: ...`` for a file Pinocchio cannot read.
    """
    full = urdf_model(urdf, base)
    return [n for n in full.names[1:] if full.joints[full.getJointId(n)].shortname() in JOINT_KINDS]


def load_arm(
    urdf: str | os.PathLike,
    joints: Sequence[str],
    srdf: str | os.PathLike | None = None,
    fixed: Mapping[str, float] | None = None,
    bodies_per_link: int | None = None,
    package_dirs: Sequence[str | os.PathLike] | None = None,
    progress: Callable[[str], None] | None = None,
    max_offset: float | None = None,
    representation: str | None = None,
    base: PlanarBase | None = None,
) -> ArmModel:
    """Read an arm from its URDF (and SRDF) and represent its links by bodies.

    Parameters
    ----------
    urdf : path-like
        The robot's URDF; mesh paths ``package://...`` resolve against ``package_dirs``
        and the usual folders (:func:`package_folders`).
    joints : sequence of str
        The planning group, in state order: revolute or prismatic joints of the URDF,
        each named once.
    srdf : path-like, optional
        Its ``disable_collisions`` pairs are never checked for self-collision. Without
        one, links joined by a joint may touch (as MoveIt's setup assistant marks them
        "Adjacent"; links fixed to each other count as one) and every other pair is
        checked, or proven apart (:mod:`kcplan.arm.pairs`).
    fixed : mapping of str to float, optional
        Values of joints outside the group (default 0, or the nearest limit when 0 lies
        outside them).
    bodies_per_link : int, optional
        Alone: exactly this many ellipsoids per mesh geometry, the fit minimising their
        union's volume (:func:`kcplan.cover.cache.cached_cover`). With ``max_offset``:
        the most per mesh (default :data:`kcplan.cover.fit.MAX_OFFSET_BODIES`).
    package_dirs : sequence of path-like, optional
        Folders that hold the packages of ``package://PACKAGE/...`` mesh URIs (each
        ``PACKAGE`` is a subfolder of one); :func:`package_folders` adds the URDF's folder,
        ``ROS_PACKAGE_PATH`` and example-robot-data's share folder.
    progress : callable, optional
        Called with one line per mesh covered (fitted or from the cache, how long it
        took, how far it sticks out, and the fit's note when it hit the most bodies).
    max_offset : float, optional
        Cut each mesh's cover until no body sticks out of the mesh by more than this, in
        metres (a proved bound, :mod:`kcplan.cover.offset`). When neither this nor
        ``bodies_per_link`` is given: :data:`DEFAULT_MAX_OFFSET`.
    representation : {"hulls", "ellipsoids"}, optional
        Links as their convex hulls, or as ellipsoid covers (module docstring). Default:
        ``"ellipsoids"`` when ``bodies_per_link`` or ``max_offset`` is given, else
        ``"hulls"``.
    base : PlanarBase, optional
        A base that drives (:mod:`kcplan.arm.description`): its joints ``NAME/x``,
        ``NAME/y``, ``NAME/theta`` may be in ``joints``. Continuous joints are revolute
        joints whose angle wraps, with or without a base.

    Raises
    ------
    ArmError
        One line naming the file, the field and what is expected.
    """
    import pinocchio as pin  # imported here: the rigid planners never need it

    source = os.fspath(urdf)
    if representation is None:
        cover_asked = bodies_per_link is not None or max_offset is not None
        representation = "ellipsoids" if cover_asked else REPRESENTATIONS[0]
    if representation not in REPRESENTATIONS:
        raise ArmError(
            f"{source}: representation: expected one of {', '.join(REPRESENTATIONS)}, "
            f"got {representation!r}"
        )
    if representation == "hulls" and (bodies_per_link is not None or max_offset is not None):
        raise ArmError(
            f"{source}: representation: bodies_per_link and max_offset are for "
            "ellipsoid covers, got them with hulls"
        )
    if representation == "ellipsoids" and bodies_per_link is None and max_offset is None:
        max_offset = DEFAULT_MAX_OFFSET
    if bodies_per_link is not None and not (
        isinstance(bodies_per_link, int) and 1 <= bodies_per_link <= MAX_BODIES
    ):
        raise ArmError(
            f"{source}: bodies_per_link: expected 1 to {MAX_BODIES}, got {bodies_per_link!r}"
        )
    if max_offset is not None and not (math.isfinite(max_offset) and max_offset > 0):
        raise ArmError(f"{source}: max_offset: expected a positive number, got {max_offset!r}")
    if not Path(source).is_file():
        raise ArmError(f"{source}: urdf: expected a URDF file, found none")
    dirs = package_folders(source, package_dirs)
    try:
        description = read_description(source, base)
        full = description.model()
        full_geometry = description.geometry(full, pin.GeometryType.COLLISION, dirs)
    except DescriptionError as err:
        raise ArmError(str(err)) from None
    except (RuntimeError, ValueError, OSError) as err:
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        missing = re.search(r"Mesh (\S+) could not be found", first)
        if missing:
            raise ArmError(
                f"{source}: collision: expected the mesh {missing.group(1)} in a package folder "
                f"({', '.join(dirs)}), found none: name the folder that holds its package in "
                "robot.package_dirs (--package-dir) or ROS_PACKAGE_PATH"
            ) from None
        raise ArmError(f"{source}: urdf: expected a readable URDF, got: {first}") from None
    group = _group(full, joints, source)
    fixed = dict(fixed or {})
    q_fixed = pin.neutral(full)
    for name, value in fixed.items():
        if not full.existJointName(name):
            raise ArmError(f"{source}: fixed: {name!r} is not a joint of the URDF")
        if name in group:
            raise ArmError(f"{source}: fixed: {name!r} is in the planning group")
        joint = full.joints[full.getJointId(name)]
        try:
            value = float(value)
        except (TypeError, ValueError):
            value = math.nan  # not a number: refused below, as a non-finite one
        if joint.nq != 1 or not math.isfinite(value):
            raise ArmError(
                f"{source}: fixed.{name}: expected a finite value of a 1-DOF joint, "
                f"got {fixed[name]!r}"
            )
        low, high = full.lowerPositionLimit[joint.idx_q], full.upperPositionLimit[joint.idx_q]
        if not low <= value <= high:  # the covers and bounds hold within the limits only
            raise ArmError(
                f"{source}: fixed.{name}: expected a value within the joint's limits "
                f"[{low:g}, {high:g}], got {value:g}"
            )
        q_fixed[joint.idx_q] = value
    for name in full.names[1:]:
        joint = full.joints[full.getJointId(name)]
        if name not in group and name not in fixed and joint.nq == 1:
            low, high = full.lowerPositionLimit[joint.idx_q], full.upperPositionLimit[joint.idx_q]
            q_fixed[joint.idx_q] = min(max(0.0, low), high)
    locked = [full.getJointId(n) for n in full.names[1:] if n not in group]
    full_geometry.addAllCollisionPairs()
    if srdf is not None:
        if not Path(srdf).is_file():
            raise ArmError(f"{os.fspath(srdf)}: srdf: expected an SRDF file, found none")
        try:
            pin.removeCollisionPairs(full, full_geometry, os.fspath(srdf))
        except (RuntimeError, ValueError) as err:
            raise ArmError(
                f"{os.fspath(srdf)}: srdf: expected a readable SRDF, got: {err}"
            ) from None
    else:  # as MoveIt's setup assistant marks them: links joined by a joint may touch
        for pair in list(full_geometry.collisionPairs):
            a = full_geometry.geometryObjects[pair.first].parentJoint
            b = full_geometry.geometryObjects[pair.second].parentJoint
            if full.parents[a] == b or full.parents[b] == a:
                full_geometry.removeCollisionPair(pair)
    try:
        model, geometry = pin.buildReducedModel(full, full_geometry, locked, q_fixed)
    except (RuntimeError, ValueError) as err:  # e.g. a link and a fixed joint of one name
        raise ArmError(
            f"{source}: joints: expected a group Pinocchio can reduce the URDF to (every "
            f"other joint locked), got: {err}"
        ) from None
    if len(geometry.geometryObjects) == 0:
        raise ArmError(f"{source}: collision: expected links with collision geometry, got none")
    ids = [model.getJointId(n) for n in group]
    kinds = tuple(JOINT_KINDS[model.joints[i].shortname()][0] for i in ids)
    q_index = np.array([model.joints[i].idx_q for i in ids], dtype=np.int64)
    lower, upper = model.lowerPositionLimit[q_index], model.upperPositionLimit[q_index]
    if not (np.isfinite(lower).all() and np.isfinite(upper).all() and (lower <= upper).all()):
        raise ArmError(f"{source}: limits: expected finite joint limits, got {lower} to {upper}")
    bodies = []
    for index, obj in enumerate(geometry.geometryObjects):
        placement = np.asarray(obj.placement.homogeneous, dtype=float)
        link = model.frames[obj.parentFrame].name
        if representation == "hulls":
            for frame, semi_axes, hull in hull_bodies(obj, source, progress):
                bodies.append(
                    ArmBody(link, index, int(obj.parentJoint), placement @ frame, semi_axes, hull)
                )
            continue
        for frame, semi_axes in _cover(obj, bodies_per_link, max_offset, source, progress):
            bodies.append(ArmBody(link, index, int(obj.parentJoint), placement @ frame, semi_axes))
    self_pairs = self_pairs_of(geometry, bodies)
    wraps = np.array([name in description.wrapping for name in group], dtype=bool)
    return ArmModel(
        model, geometry, tuple(group), q_index, np.array(lower), np.array(upper), kinds,
        tuple(bodies), self_pairs, source, "" if srdf is None else os.fspath(srdf),
        tuple(os.fspath(d) for d in package_dirs or ()),
        wraps=wraps if wraps.any() else None, description=description,
    )  # fmt: skip


def package_folders(
    urdf: str | os.PathLike, given: Sequence[str | os.PathLike] | None = None
) -> list[str]:
    """Where ``package://PACKAGE/...`` URIs of ``urdf`` are looked for, in order, as ROS
    does: the ``given`` folders, the URDF's own folder, every folder of
    ``ROS_PACKAGE_PATH``, and the ``share`` folder of the cmeel prefix that holds
    Pinocchio (where PyPI's ``example-robot-data`` installs ``example-robot-data/...``).
    Folders that do not exist are left out."""
    import pinocchio as pin

    folders = [os.fspath(d) for d in given or ()]
    folders.append(os.fspath(Path(urdf).resolve().parent))
    folders += [d for d in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if d]
    folders.append(os.fspath(Path(pin.__file__).resolve().parents[4] / "share"))
    out: list[str] = []
    for folder in folders:
        if Path(folder).is_dir() and folder not in out:
            out.append(folder)
    return out


def _group(full, joints: Sequence[str], source: str) -> list[str]:
    """The planning group's names, checked against the URDF."""
    group = list(joints)
    if not group:
        raise ArmError(f"{source}: joints: expected at least one joint of the URDF, got none")
    for name in group:
        if not isinstance(name, str) or not full.existJointName(name):
            known = ", ".join(full.names[1:])
            raise ArmError(f"{source}: joints: {name!r} is not a joint of the URDF ({known})")
        if group.count(name) > 1:
            raise ArmError(f"{source}: joints: {name!r} is named twice")
        plannable_joint(full, name, f"{source}: joints")
    return group


def plannable_joint(model, joint: str, where: str) -> int:
    """Joint ``joint``'s id in ``model`` (a ``pinocchio.Model`` that has it), when kcplan
    can plan it: revolute (continuous included) or prismatic.

    Raises
    ------
    ArmError
        ``WHERE: 'joint' is a floating joint; expected ...`` for any other kind.
    """
    index = model.getJointId(joint)
    shortname = model.joints[index].shortname()
    if shortname not in JOINT_KINDS:
        raise ArmError(f"{where}: {joint!r} is a {_joint_kind(shortname)}; expected revolute "
                       "or prismatic joints with limits")  # fmt: skip
    return index


def _joint_kind(shortname: str) -> str:
    """A Pinocchio joint kind as a URDF names it (``JointModelRUBX``: continuous)."""
    if shortname.startswith("JointModelRUB"):
        return "continuous joint"
    names = {"JointModelFreeFlyer": "floating joint", "JointModelPlanar": "planar joint",
             "JointModelSpherical": "spherical joint"}  # fmt: skip
    return names.get(shortname, shortname)


def hull_bodies(
    obj, source: str, progress: Callable[[str], None] | None = None
) -> list[tuple[NDArray[np.float64], NDArray[np.float64], BodyHull | None]]:
    """``(frame, semi_axes, hull)`` of each convex body of one geometry (module docstring:
    its hull, or the hulls of its pieces where it is not convex), frames ``(4, 4)`` in
    the geometry's frame; a sphere is an ellipsoid (``hull`` None)."""
    shape = obj.geometry
    kind = type(shape).__name__
    if kind == "Sphere":
        return [(np.eye(4), np.full(3, float(shape.radius)), None)]
    if kind == "Box":
        pieces = [box_hull(np.asarray(shape.halfSide, dtype=float))]
    elif kind == "Cylinder":
        pieces = [cylinder_hull(float(shape.radius), float(shape.halfLength))]
    elif hasattr(shape, "vertices"):  # a mesh: Pinocchio's BVH model of a file, or a held mesh
        start = time.perf_counter()
        vertices, triangles = bvh_mesh(shape)  # any format assimp reads, already scaled
        try:
            pieces, _ = cached_hull_pieces(vertices, triangles, _single_precision(vertices))
        except ValueError as err:
            raise ArmError(f"{source}: collision: {obj.name}: {obj.meshPath}: {err}") from None
        took = time.perf_counter() - start
        if progress is not None and took > 1.0:  # a large mesh: say where the time goes
            count = sum(len(h.vertices) for _, h in pieces)
            progress(f"{obj.name}: {len(pieces)} hull(s) of {count} vertices in {took:.1f} s")
    else:
        raise ArmError(
            f"{source}: collision: {obj.name}: expected a mesh, box, cylinder or sphere, got {kind}"
        )
    out = []
    for centre, hull in pieces:
        frame = np.eye(4)
        frame[:3, 3] = centre
        out.append((frame, np.full(3, hull.radius), hull))
    return out


def _single_precision(vertices: NDArray[np.float64]) -> float:
    """How far a vertex Pinocchio read may lie from the file's (metres): assimp keeps
    single precision, a relative 2^-24 of each coordinate, so 2^-23 of the largest."""
    return 2.0**-23 * float(np.abs(vertices).max(initial=0.0))


def _cover(
    obj,
    bodies: int | None,
    max_offset: float | None,
    source: str,
    progress: Callable[[str], None] | None = None,
) -> list[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """``(frame, semi_axes)`` of the ellipsoids covering one geometry, frames ``(4, 4)`` in
    the geometry's frame (see the module docstring for the primitives)."""
    shape = obj.geometry
    kind = type(shape).__name__
    eye = np.eye(4)
    if kind == "Sphere":
        return [(eye, np.full(3, float(shape.radius)))]
    if kind == "Box":
        return [(eye, math.sqrt(3.0) * np.asarray(shape.halfSide, dtype=float))]
    if kind == "Cylinder":
        r, c = float(shape.radius), float(shape.halfLength)
        return [(eye, np.array([math.sqrt(1.5) * r, math.sqrt(1.5) * r, math.sqrt(3.0) * c]))]
    if not obj.meshPath:
        raise ArmError(
            f"{source}: collision: {obj.name}: expected a mesh, box, cylinder or sphere, got {kind}"
        )
    scale = np.asarray(obj.meshScale, dtype=float)
    if not np.allclose(scale, scale[0]):
        raise ArmError(
            f"{source}: collision: {obj.name}: expected a uniform mesh scale, got {scale.tolist()}"
        )
    start = time.perf_counter()
    try:
        cover, origin = mesh_cover(obj.meshPath, bodies, float(scale[0]), max_offset)
    except SolidError as err:
        raise ArmError(f"{source}: collision: {obj.name}: {err}") from None
    if progress is not None:
        count = len(cover.bodies)
        line = f"{obj.name}: {count} bod{'y' if count == 1 else 'ies'}, {origin} in "
        line += f"{time.perf_counter() - start:.1f} s"
        if not math.isnan(cover.offset):
            line += f", sticking out by at most {1000 * cover.offset:.1f} mm"
        progress(line + (f" ({cover.note})" if cover.note else ""))
    out = []
    for body in cover.bodies:
        frame = np.eye(4)
        frame[:3, :3] = quaternion_matrix(body.pose[3:])
        frame[:3, 3] = body.pose[:3]
        out.append((frame, np.asarray(body.semi_axes, dtype=float)))
    return out


def mesh_cover(
    path: str | os.PathLike,
    bodies: int | None,
    scale: float = 1.0,
    max_offset: float | None = None,
) -> tuple[Cover, str]:
    """The cover of a link's collision mesh (:func:`kcplan.cover.cache.cached_cover`: by
    ``bodies`` ellipsoids, or with ``max_offset`` by at most ``bodies`` that stick out of
    the mesh by at most ``max_offset``), or of its convex hull when the mesh is not closed
    (a surface: its hull holds every triangle; the offset is then from the hull);
    ``origin`` says which and whether it came from the cache.

    Raises
    ------
    SolidError
        When neither the mesh nor its hull can be covered.
    """
    try:
        return cached_cover(path, bodies, scale=scale, max_offset=max_offset)
    except SolidError as err:
        try:
            cover, origin = cached_cover(
                path, bodies, scale=scale, hull=True, max_offset=max_offset
            )
        except SolidError:
            raise err from None
        return cover, f"{origin} (its convex hull: the mesh is not closed)"


def self_pairs_of(geometry, bodies: Sequence[ArmBody]) -> NDArray[np.int64]:
    """Body pairs whose geometries form a collision pair of ``geometry``."""
    by_geometry: dict[int, list[int]] = {}
    for k, body in enumerate(bodies):
        by_geometry.setdefault(body.geometry, []).append(k)
    pairs = []
    for pair in geometry.collisionPairs:
        for i in by_geometry.get(pair.first, []):
            for j in by_geometry.get(pair.second, []):
                pairs.append((min(i, j), max(i, j)))
    return np.array(sorted(set(pairs)), dtype=np.int64).reshape(-1, 2)
