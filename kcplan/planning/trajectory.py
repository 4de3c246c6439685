"""An arm's certified, timed trajectory: its path smoothed by blends proved free
(:mod:`kcplan.planning.smoothing`), then timed by TOPP-RA within the joints' velocity and
acceleration limits (:mod:`kcplan.trajectory.timing`).

The trajectory follows the certified curve exactly (timing only chooses the speed along
it), so every configuration it passes through is proved free: the straight pieces by the
planner's certified edges, the blends by :func:`kcplan.planning.smoothing.certify_blends`.
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

from kcplan.planning.smoothing import BlendCertificate, smooth_path
from kcplan.trajectory.curve import BlendedPath
from kcplan.trajectory.timing import Trajectory, time_path

__all__ = [
    "DEFAULT_ACCELERATION",
    "DEFAULT_RATE",
    "CertifiedTrajectory",
    "certified_trajectory",
    "joint_limits",
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
                "(kcplan.planning.smoothing)",
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
        rows = np.column_stack([t, q, qd, qdd])
        lines = [",".join(header)] + [",".join(f"{x:.17g}" for x in row) for row in rows]
        return "\n".join(lines) + "\n"


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

    def array(field: str, shape: tuple) -> NDArray[np.float64]:
        try:
            x = np.array(data[field], dtype=float)
        except KeyError:
            raise ValueError(f"{field}: expected the field (a trajectory file of kcplan plan "
                             "--trajectory)") from None  # fmt: skip
        except (TypeError, ValueError):
            x = np.zeros(0)
        if x.shape != shape or not np.isfinite(x).all():
            raise ValueError(f"{field}: expected finite numbers of shape {shape}, got "
                             f"{x.shape if x.size else 'none'}")  # fmt: skip
        return x

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
    return TrajectoryFile(
        tuple(data.get("joints") or ()),
        path,
        array("t", (m,)),
        array("s", (m,)),
        array("q", (m, dof)),
        array("qd", (m, dof)),
        array("qdd", (m, dof)),
        array("velocity_limits", (dof,)),
        array("acceleration_limits", (dof,)),
    )
