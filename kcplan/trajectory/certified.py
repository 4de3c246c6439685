"""Certified, timed trajectories. An arm's: its path smoothed by blends proved free
(:mod:`kcplan.trajectory.smoothing`), then timed by TOPP-RA within the joints' velocity and
acceleration limits (:mod:`kcplan.trajectory.timing`). A rigid robot's: its certified
edges timed one by one within translational and angular limits, stopping at every
corner (:mod:`kcplan.trajectory.rigid`; no blends).

The trajectory follows the certified curve exactly (timing only chooses the speed along
it), so every configuration it passes through is proved free: the straight pieces by the
planner's certified edges, the blends by :func:`kcplan.trajectory.smoothing.certify_blends`.
Its file (:meth:`CertifiedTrajectory.document`) carries the curve itself (``curve``: the
waypoints and each corner's blend), so that ``kcplan verify`` can check the continuous
curve on the meshes and every sample against it.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.trajectory.curve import BlendedPath
from kcplan.trajectory.rigid import (
    DEFAULT_RIGID_ACCELERATIONS,
    DEFAULT_RIGID_SPEEDS,
    RigidTrajectory,
    time_rigid_path,
)
from kcplan.trajectory.smoothing import BlendCertificate, smooth_path
from kcplan.trajectory.timing import Trajectory, time_path

__all__ = [
    "DEFAULT_ACCELERATION",
    "DEFAULT_RATE",
    "CertifiedTrajectory",
    "RigidTimedPath",
    "certified_trajectory",
    "joint_limits",
    "rigid_limits",
    "timed_rigid_path",
]

DEFAULT_ACCELERATION = 2.0
"""Per second: without acceleration limits a joint may change its speed by twice its
velocity limit in a second (URDFs give no acceleration limit; full speed in 0.5 s)."""
DEFAULT_RATE = 100.0
"""Samples per second written by :meth:`CertifiedTrajectory.document`."""


def joint_limits(
    arm,
    velocity_limits: ArrayLike | None = None,
    acceleration_limits: ArrayLike | float | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The velocity and acceleration limits of the arm's joints (state order).

    Parameters
    ----------
    arm : kcplan.arm.ArmModel
    velocity_limits : array_like, shape (dof,), optional
        Default: the URDF's (``<limit velocity=...>``, rad/s or m/s).
    acceleration_limits : float or array_like, shape (dof,), optional
        One number for every joint, or one per joint; default :data:`DEFAULT_ACCELERATION`
        times the velocity limits.

    Raises
    ------
    ValueError
        A limit that is not a finite number > 0 (the URDF's too), named.
    """
    model = arm.model
    if velocity_limits is None:
        v = np.array([float(model.velocityLimit[model.joints[model.getJointId(name)].idx_v])
                      for name in arm.joints])  # fmt: skip
        bad = [f"{n} {x!r}" for n, x in zip(arm.joints, v, strict=True)
               if not (math.isfinite(x) and x > 0)]  # fmt: skip
        if bad:
            raise ValueError(f"velocity_limits: the URDF gives no usable velocity limit for "
                             f"{', '.join(bad)}; give them")  # fmt: skip
    else:
        v = np.array(velocity_limits, dtype=float).reshape(-1)
    if acceleration_limits is None:
        a = DEFAULT_ACCELERATION * v
    else:
        a = (
            np.broadcast_to(np.array(acceleration_limits, dtype=float), v.shape).copy()
            if np.ndim(acceleration_limits) == 0
            else np.array(acceleration_limits, dtype=float)
        )
    for name, lim in (("velocity_limits", v), ("acceleration_limits", a)):
        if lim.shape != (arm.dof,) or not (np.isfinite(lim).all() and (lim > 0).all()):
            raise ValueError(f"{name}: expected {arm.dof} finite numbers > 0 (one per joint "
                             f"of {list(arm.joints)}), got {lim.tolist()}")  # fmt: skip
    return v, a


def _csv(header: list[str], *columns: NDArray[np.float64]) -> str:
    """Samples as CSV: the header, then one row per sample, every digit kept."""
    rows = np.column_stack(columns)
    lines = [",".join(header)] + [",".join(f"{x:.17g}" for x in row) for row in rows]
    return "\n".join(lines) + "\n"


def _field(data: dict, field: str, shape: tuple, value=None) -> NDArray[np.float64]:
    """A trajectory file's numeric field of ``shape`` (``value`` in place of
    ``data[field]`` when given), or ``FIELD: expected ...`` (ValueError)."""
    source = data.get(field) if value is None else value
    if source is None:
        raise ValueError(f"{field}: expected the field (a trajectory file of kcplan plan "
                         "--trajectory)")  # fmt: skip
    try:
        x = np.array(source, dtype=float)
    except (TypeError, ValueError):
        x = np.zeros(0)
    if x.shape != shape or not np.isfinite(x).all():
        raise ValueError(f"{field}: expected finite numbers of shape {shape}, got "
                         f"{x.shape if x.size else 'none'}")  # fmt: skip
    return x


@dataclass(frozen=True, eq=False)
class CertifiedTrajectory:
    """A timed trajectory along a certified curve.

    Attributes
    ----------
    joints : tuple of str
        The state order.
    timed : Trajectory
        The smoothed curve timed (its limits, its ``duration`` in seconds).
    certificate : BlendCertificate
        What proved the blends.
    stop_duration : float
        Seconds the same path takes timed alike with a stop at every corner (no blend).
    seconds : float
        Wall-clock seconds spent smoothing and timing.
    edges : int
        Certified edges of the path smoothed.
    """

    joints: tuple[str, ...]
    timed: Trajectory
    certificate: BlendCertificate
    stop_duration: float
    seconds: float
    edges: int

    @property
    def path(self) -> BlendedPath:
        """The certified curve."""
        return self.timed.path

    def document(self, rate: float = DEFAULT_RATE) -> dict:
        """The trajectory file: ``joints``, ``t`` (s, from 0), ``s`` (the curve's
        parameter), ``q``, ``qd``, ``qdd`` (one row per sample, ``rate`` per second, the end
        included), ``velocity_limits`` and ``acceleration_limits`` (per joint, what it was
        timed with), ``duration``, ``stop_at_corners_duration``, ``peak_ratios`` (the
        largest ``|qd| / v`` and ``|qdd| / a`` over the whole trajectory, exactly),
        ``curve`` (``waypoints`` and ``blends``: :class:`BlendedPath`) and ``certificate``."""
        t, s, q, qd, qdd = self.timed.sample(rate)
        rv, ra = self.timed.peak_ratios()
        return {
            "joints": list(self.joints),
            "rate": float(rate),
            "duration": self.timed.duration,
            "stop_at_corners_duration": self.stop_duration,
            "velocity_limits": self.timed.velocity_limits.tolist(),
            "acceleration_limits": self.timed.acceleration_limits.tolist(),
            "peak_ratios": {"velocity": rv, "acceleration": ra},
            "certificate": {
                "edges": self.edges,
                "edge_certificate": "the planner's motion validator (kcplan.planning)",
                "blend_certificate": "guards along each blend, chain bound "
                "(kcplan.trajectory.smoothing)",
                **self.certificate.summary(),
                "seconds": self.seconds,
            },
            "curve": {
                "waypoints": self.path.waypoints.tolist(),
                "blends": self.path.blends.tolist(),
            },
            "t": t.tolist(),
            "s": s.tolist(),
            "q": q.tolist(),
            "qd": qd.tolist(),
            "qdd": qdd.tolist(),
        }

    def csv(self, rate: float = DEFAULT_RATE) -> str:
        """The samples as CSV: ``t``, then ``q_``, ``qd_`` and ``qdd_`` of each joint."""
        t, _, q, qd, qdd = self.timed.sample(rate)
        header = ["t"] + [f"{p}_{name}" for p in ("q", "qd", "qdd") for name in self.joints]
        return _csv(header, t, q, qd, qdd)


def certified_trajectory(
    world,
    waypoints: Sequence[ArrayLike],
    velocity_limits: ArrayLike | None = None,
    acceleration_limits: ArrayLike | float | None = None,
) -> CertifiedTrajectory:
    """Smooth a certified path of ``world``'s arm and time it (module docstring).

    Parameters
    ----------
    world : kcplan.arm.ArmWorld
        The scene the path was certified in.
    waypoints : sequence of array_like, shape (N, dof)
        The path (every edge certified); repeated consecutive waypoints are merged.
    velocity_limits, acceleration_limits
        :func:`joint_limits`.
    """
    start = time.perf_counter()
    arm = world.arm
    v, a = joint_limits(arm, velocity_limits, acceleration_limits)
    W = [np.asarray(waypoints[0], dtype=float)]
    for q in waypoints[1:]:
        q = np.asarray(q, dtype=float)
        if np.linalg.norm(q - W[-1]) > 0:
            W.append(q)
    if len(W) < 2:
        raise ValueError("waypoints: expected a path that moves (two distinct waypoints)")
    path, certificate = smooth_path(world, W)
    timed = time_path(path, v, a)
    seconds = time.perf_counter() - start
    stop = time_path(BlendedPath(W), v, a).duration
    return CertifiedTrajectory(tuple(arm.joints), timed, certificate, stop, seconds, len(W) - 1)


@dataclass(frozen=True)
class TrajectoryFile:
    """A trajectory file read back (:func:`read_trajectory`): its curve and its samples."""

    joints: tuple[str, ...]
    path: BlendedPath
    t: NDArray[np.float64]
    s: NDArray[np.float64]
    q: NDArray[np.float64]
    qd: NDArray[np.float64]
    qdd: NDArray[np.float64]
    velocity_limits: NDArray[np.float64]
    acceleration_limits: NDArray[np.float64]

    def deviations(self) -> dict[str, float]:
        """How far the samples are from the curve and the limits: ``curve`` (the largest
        ``|q - curve(s)|``, rad), ``velocity`` and ``acceleration`` (the largest ``|qd_j| /
        v_j`` and ``|qdd_j| / a_j``), ``time`` (the smallest step of ``t``, s) and
        ``parameter`` (the smallest step of ``s``)."""
        return {
            "curve": float(np.abs(self.q - self.path(self.s)).max(initial=0.0)),
            "velocity": float((np.abs(self.qd) / self.velocity_limits).max(initial=0.0)),
            "acceleration": float((np.abs(self.qdd) / self.acceleration_limits).max(initial=0.0)),
            "time": float(np.diff(self.t).min(initial=np.inf)),
            "parameter": float(np.diff(self.s).min(initial=np.inf)),
        }


def read_trajectory(data: dict, dof: int) -> TrajectoryFile:
    """A trajectory file's fields (:meth:`CertifiedTrajectory.document`), checked.

    Raises
    ------
    ValueError
        ``FIELD: expected ...`` for the first field that is missing or malformed.
    """

    curve = data.get("curve")
    if not isinstance(curve, dict):
        raise ValueError("curve: expected {waypoints, blends}: the certified curve")
    try:
        W = np.array(curve.get("waypoints"), dtype=float)
        blends = np.array(curve.get("blends"), dtype=float)
    except (TypeError, ValueError):
        W = blends = np.zeros(0)
    if W.ndim != 2 or W.shape[1:] != (dof,) or len(W) < 2 or not np.isfinite(W).all():
        raise ValueError(f"curve.waypoints: expected at least two joint vectors of {dof} "
                         "numbers")  # fmt: skip
    try:
        path = BlendedPath(W, blends)
    except ValueError as err:
        raise ValueError(f"curve.{err}") from None
    t = np.array(data.get("t", []), dtype=float) if isinstance(data.get("t"), list) else None
    if t is None or t.ndim != 1 or len(t) < 2:
        raise ValueError("t: expected a list of at least two sample times (s)")
    m = len(t)
    shapes = {"t": (m,), "s": (m,), "q": (m, dof), "qd": (m, dof), "qdd": (m, dof),
              "velocity_limits": (dof,), "acceleration_limits": (dof,)}  # fmt: skip
    fields = {name: _field(data, name, shape) for name, shape in shapes.items()}
    return TrajectoryFile(tuple(data.get("joints") or ()), path, **fields)


POSE_NAMES = {2: ("x", "y", "yaw"), 3: ("x", "y", "z", "qx", "qy", "qz", "qw")}
VELOCITY_NAMES = {2: ("vx", "vy", "wz"), 3: ("vx", "vy", "vz", "wx", "wy", "wz")}


def rigid_limits(
    velocity_limits: ArrayLike | None = None, acceleration_limits: ArrayLike | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A rigid robot's translational and angular limits, checked: one number for both or
    two (default :data:`~kcplan.trajectory.rigid.DEFAULT_RIGID_SPEEDS` and
    :data:`~kcplan.trajectory.rigid.DEFAULT_RIGID_ACCELERATIONS`)."""
    out = []
    for name, given, default in (("velocity_limits", velocity_limits, DEFAULT_RIGID_SPEEDS),
                                 ("acceleration_limits", acceleration_limits,
                                  DEFAULT_RIGID_ACCELERATIONS)):  # fmt: skip
        lim = np.array(default if given is None else given, dtype=float).reshape(-1)
        lim = np.repeat(lim, 2) if lim.shape == (1,) else lim
        if lim.shape != (2,) or not (np.isfinite(lim).all() and (lim > 0).all()):
            raise ValueError(f"{name}: expected a translational and an angular limit > 0 "
                             f"(or one for both), got {lim.tolist()}")  # fmt: skip
        out.append(lim)
    return out[0], out[1]


@dataclass(frozen=True, eq=False)
class RigidTimedPath:
    """A rigid robot's certified path timed edge by edge, stopping at every corner.

    Attributes
    ----------
    timed : RigidTrajectory
    seconds : float
        Wall-clock seconds spent timing.
    """

    timed: RigidTrajectory
    seconds: float

    @property
    def joints(self) -> tuple[str, ...]:
        """The pose's components (:mod:`kcplan.geometry.pose` layout)."""
        return POSE_NAMES[self.timed.dimension]

    @property
    def stop_duration(self) -> float:
        """The same as the duration: a rigid path stops at every corner."""
        return self.timed.duration

    def document(self, rate: float = DEFAULT_RATE) -> dict:
        """The trajectory file of a rigid robot: ``joints`` (the pose's components), ``t``,
        ``s`` (edge index plus the fraction along it), ``q`` (poses), ``qd`` and ``qdd``
        (``velocity_components``: the linear velocity of the robot's frame and its angular
        velocity, world frame), ``velocity_limits`` and ``acceleration_limits``
        (``limit_names``: translational, angular), ``duration``, ``peak_ratios``, ``curve``
        (the waypoints; no blends) and ``certificate``."""
        t, s, q, qd, qdd = self.timed.sample(rate)
        rv, ra = self.timed.peak_ratios()
        W = self.timed.waypoints
        return {
            "joints": list(self.joints),
            "velocity_components": list(VELOCITY_NAMES[self.timed.dimension]),
            "limit_names": ["translational", "angular"],
            "rate": float(rate),
            "duration": self.timed.duration,
            "stop_at_corners_duration": self.timed.duration,
            "velocity_limits": self.timed.velocity_limits.tolist(),
            "acceleration_limits": self.timed.acceleration_limits.tolist(),
            "peak_ratios": {"velocity": rv, "acceleration": ra},
            "certificate": {
                "edges": len(W) - 1,
                "edge_certificate": "the planner's motion validator (kcplan.planning)",
                "blends": 0,
                "seconds": self.seconds,
            },
            "curve": {"waypoints": W.tolist(), "blends": []},
            "t": t.tolist(),
            "s": s.tolist(),
            "q": q.tolist(),
            "qd": qd.tolist(),
            "qdd": qdd.tolist(),
        }

    def csv(self, rate: float = DEFAULT_RATE) -> str:
        """The samples as CSV: ``t``, the pose, its velocity and acceleration."""
        t, _, q, qd, qdd = self.timed.sample(rate)
        names = VELOCITY_NAMES[self.timed.dimension]
        return _csv(["t", *self.joints, *names, *(f"d{name}" for name in names)], t, q, qd, qdd)


def timed_rigid_path(
    waypoints: Sequence[ArrayLike],
    dimension: int,
    velocity_limits: ArrayLike | None = None,
    acceleration_limits: ArrayLike | None = None,
) -> RigidTimedPath:
    """A rigid robot's certified path timed edge by edge (:func:`rigid_limits`)."""
    start = time.perf_counter()
    v, a = rigid_limits(velocity_limits, acceleration_limits)
    timed = time_rigid_path(waypoints, dimension, v, a)
    return RigidTimedPath(timed, time.perf_counter() - start)


@dataclass(frozen=True)
class RigidTrajectoryFile:
    """A rigid robot's trajectory file read back (:func:`read_rigid_trajectory`)."""

    dimension: int
    waypoints: NDArray[np.float64]
    t: NDArray[np.float64]
    s: NDArray[np.float64]
    q: NDArray[np.float64]
    qd: NDArray[np.float64]
    qdd: NDArray[np.float64]
    velocity_limits: NDArray[np.float64]
    acceleration_limits: NDArray[np.float64]

    def deviations(self) -> dict[str, float]:
        """As :meth:`TrajectoryFile.deviations`: ``curve`` is the largest distance of a
        sample's pose from the path's pose at its ``s`` (translation, plus the yaw
        difference in 2D or the chord between the unit quaternions in 3D), ``velocity``
        and ``acceleration`` the largest size of the linear or angular part over its
        limit."""
        from kcplan.geometry.pose import Edge, wrap_angle

        n, W = self.dimension, self.waypoints
        edges = [Edge(W[k], W[k + 1], n) for k in range(len(W) - 1)]  # each built once
        k = np.clip(np.floor(self.s).astype(int), 0, len(W) - 2)
        off = 0.0
        for i, (edge_index, q) in enumerate(zip(k, self.q, strict=True)):
            pose = edges[edge_index].pose(self.s[i] - edge_index)
            d = float(np.linalg.norm(pose[:n] - q[:n]))
            if n == 2:
                d += abs(float(wrap_angle(pose[2] - q[2])))
            else:  # the chord between the quaternions, either sign (robust near 0)
                d += min(float(np.linalg.norm(pose[3:] - q[3:])),
                         float(np.linalg.norm(pose[3:] + q[3:])))  # fmt: skip
            off = max(off, d)

        def ratio(x: NDArray, limits: NDArray) -> float:
            parts = (np.linalg.norm(x[:, :n], axis=1), np.linalg.norm(x[:, n:], axis=1))
            pairs = zip(parts, limits, strict=True)
            return float(max((p / lim).max(initial=0.0) for p, lim in pairs))

        return {
            "curve": off,
            "velocity": ratio(self.qd, self.velocity_limits),
            "acceleration": ratio(self.qdd, self.acceleration_limits),
            "time": float(np.diff(self.t).min(initial=np.inf)),
            "parameter": float(np.diff(self.s).min(initial=np.inf)),
        }


def read_rigid_trajectory(data: dict, dimension: int) -> RigidTrajectoryFile:
    """A rigid robot's trajectory file (:meth:`RigidTimedPath.document`), checked.

    Raises
    ------
    ValueError
        ``FIELD: expected ...`` for the first field that is missing or malformed.
    """
    from kcplan.geometry.pose import pose_size

    width, twist = pose_size(dimension), len(VELOCITY_NAMES[dimension])
    curve = data.get("curve")
    if not isinstance(curve, dict):
        raise ValueError("curve: expected {waypoints, blends}: the certified path")
    t = data.get("t")
    if not isinstance(t, list) or len(t) < 2:
        raise ValueError("t: expected a list of at least two sample times (s)")
    m = len(t)
    shapes = {"t": (m,), "s": (m,), "q": (m, width), "qd": (m, twist), "qdd": (m, twist),
              "velocity_limits": (2,), "acceleration_limits": (2,)}  # fmt: skip
    fields = {name: _field(data, name, shape) for name, shape in shapes.items()}
    waypoints = curve.get("waypoints")
    count = len(waypoints) if isinstance(waypoints, list) else 0
    W = _field(data, "curve.waypoints", (max(count, 2), width), waypoints or [])
    return RigidTrajectoryFile(dimension, W, **fields)
