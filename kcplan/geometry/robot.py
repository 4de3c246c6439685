"""Rigid robots made of one or several ellipses (2D) or ellipsoids (3D).

A robot is a list of *bodies*, each an ellipsoid ``E_k = {p_k + R_k A_k u : |u| <= 1}``
given in the robot's own frame by its semi-axes ``a_k`` (``A_k = diag(a_k)``), the
position ``p_k`` of its centre and its orientation ``R_k``. At the robot pose
``q = (R, t)`` body ``k`` occupies ``{t + R (p_k + R_k A_k u)}``, i.e. it has the world
pose ``(R R_k, t + R p_k)``. A one-body robot centred at the origin is the paper's
``E_a``. Body poses use the pose layout of :mod:`kcplan.geometry.pose`: ``[x, y, yaw]``
or ``[x, y, z, qx, qy, qz, qw]``, relative to the robot frame.

Numbers every certificate needs, per body (lengths in the robot's unit, per radian):

* the *lever* ``|p_k| + a_max,k - a_min,k``: the support function of body ``k`` in any
  fixed direction changes by at most this much per radian of rotation about the robot's
  origin (``|p_k|`` from the arc of the centre, ``a_max - a_min`` from the body's own
  turning; proof in :mod:`kcplan.certification.certificates.ball`);
* the *reach* ``|p_k| + a_max,k``: the farthest a point of body ``k`` lies from the
  robot's origin (the plain lever of conservative advancement).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.geometry.pose import Edge, pose_frame, pose_size, quaternion_multiply
from kcplan.geometry.robot_model import RobotModel

__all__ = ["MAX_BODIES", "Body", "Robot"]

MAX_BODIES = 32
"""Largest number of bodies of one robot (every body costs one FCL query per pose)."""


@dataclass(frozen=True, eq=False)
class Body:
    """One ellipse or ellipsoid of a robot, in the robot's frame.

    Attributes
    ----------
    semi_axes : ndarray, shape (n,)
    pose : ndarray, shape (3,) or (7,)
        Centre and orientation relative to the robot's frame: ``[x, y, yaw]`` or
        ``[x, y, z, qx, qy, qz, qw]`` (unit quaternion, scalar last).
    """

    semi_axes: NDArray[np.float64]
    pose: NDArray[np.float64]

    @property
    def dimension(self) -> int:
        return len(self.semi_axes)

    @property
    def position(self) -> NDArray[np.float64]:
        """The body's centre in the robot frame, shape (n,)."""
        return self.pose[: self.dimension]

    @property
    def offset(self) -> float:
        """``|p_k|``: distance of the body's centre from the robot's origin."""
        return float(np.linalg.norm(self.position))

    @property
    def lever(self) -> float:
        """``|p_k| + a_max - a_min``: bound on the rate of change of the body's support
        function per radian of robot rotation (see the module docstring)."""
        a = self.semi_axes
        return self.offset + float(a.max() - a.min())

    @property
    def reach(self) -> float:
        """``|p_k| + a_max``: every point of the body lies this close to the origin."""
        return self.offset + float(self.semi_axes.max())

    @property
    def at_origin(self) -> bool:
        """Centred at the robot's origin with the robot's orientation."""
        identity = np.zeros(pose_size(self.dimension))
        if self.dimension == 3:
            identity[6] = 1.0
        return bool(np.array_equal(self.pose, identity))


class Robot(RobotModel):
    """A rigid robot made of one or more ellipsoidal bodies (see the module docstring).

    One implementation of :class:`kcplan.geometry.robot_model.RobotModel`: a state is a
    pose, an edge OMPL's interpolation in SE(2) or SE(3) (:class:`kcplan.geometry.pose.
    Edge`), and body ``k``'s speed ``|t2 - t1| + reach_k |w12|``.

    Parameters
    ----------
    bodies : sequence of Body
        At least one, at most :data:`MAX_BODIES`, all of the same dimension.
    """

    def __init__(self, bodies: list[Body] | tuple[Body, ...]):
        bodies = tuple(bodies)
        if not bodies:
            raise ValueError("bodies: expected at least one body, got none")
        if len(bodies) > MAX_BODIES:
            raise ValueError(f"bodies: expected at most {MAX_BODIES} bodies, got {len(bodies)}")
        n = bodies[0].dimension
        if any(b.dimension != n for b in bodies):
            raise ValueError("bodies: expected bodies of one dimension")
        self.bodies = bodies
        self.dimension = n
        self.is_single = len(bodies) == 1 and bodies[0].at_origin
        """One body at the origin: the paper's ``E_a``."""

    @classmethod
    def single(cls, semi_axes: ArrayLike) -> Robot:
        """The one-body robot ``E_a`` centred at the origin."""
        a = np.asarray(semi_axes, dtype=float)
        if a.ndim != 1 or len(a) not in (2, 3) or not (a > 0).all():
            raise ValueError(f"semi_axes: expected 2 or 3 positive numbers, got {a.tolist()}")
        pose = np.zeros(pose_size(len(a)))
        if len(a) == 3:
            pose[6] = 1.0
        return cls((Body(a, pose),))

    @classmethod
    def of(cls, robot: Robot | ArrayLike) -> Robot:
        """``robot`` itself, or the one-body robot with semi-axes ``robot``."""
        return robot if isinstance(robot, Robot) else cls.single(robot)

    def __len__(self) -> int:
        return len(self.bodies)

    def __repr__(self) -> str:
        if self.is_single:
            return f"Robot.single({self.semi_axes.tolist()})"
        return f"Robot({len(self)} bodies)"

    @property
    def semi_axes(self) -> NDArray[np.float64]:
        """The semi-axes of a one-body robot centred at the origin.

        Raises
        ------
        ValueError
            For any other robot (what needs this, e.g. the paper's polytope, applies only
            to ``E_a`` itself).
        """
        if not self.is_single:
            raise ValueError(
                f"robot: expected one body centred at the robot's origin, got {len(self)} "
                "bodies (this needs the paper's single ellipsoid E_a)"
            )
        return self.bodies[0].semi_axes

    @property
    def reach(self) -> float:
        """Largest distance of a robot point from the robot's origin."""
        return max(b.reach for b in self.bodies)

    @property
    def levers(self) -> tuple[float, ...]:
        """:attr:`Body.lever` of every body."""
        return tuple(b.lever for b in self.bodies)

    @property
    def largest_semi_axis(self) -> float:
        """The largest semi-axis of any body."""
        return max(float(b.semi_axes.max()) for b in self.bodies)

    @property
    def smallest_semi_axis(self) -> float:
        """The smallest semi-axis of any body (the robot's thinnest part)."""
        return min(float(b.semi_axes.min()) for b in self.bodies)

    @property
    def core_radius(self) -> float:
        """Radius of a ball about the robot's origin that the robot contains in every
        orientation; 0 when no body covers the origin.

        Body ``k`` contains ``B(p_k, a_min,k)``, which contains ``B(0, a_min,k - |p_k|)``.
        """
        return max(0.0, max(float(b.semi_axes.min()) - b.offset for b in self.bodies))

    @property
    def state_size(self) -> int:
        """3 (``[x, y, yaw]``) or 7 (``[x, y, z, qx, qy, qz, qw]``)."""
        return pose_size(self.dimension)

    @property
    def workspace_dimension(self) -> int:
        return self.dimension

    @property
    def body_count(self) -> int:
        return len(self.bodies)

    def body_frames(self, state: ArrayLike) -> NDArray[np.float64]:
        """World frames of the bodies at the pose ``state``, shape ``(k, n + 1, n + 1)``
        (:meth:`body_poses` as homogeneous matrices)."""
        n = self.dimension
        R, t = pose_frame(self.body_poses(state), n)
        frames = np.zeros((len(self.bodies), n + 1, n + 1))
        frames[:, :n, :n], frames[:, :n, n], frames[:, n, n] = R, t, 1.0
        return frames

    def edge_state(self, state1: ArrayLike, state2: ArrayLike, s: float) -> NDArray[np.float64]:
        """The pose at ``s`` of OMPL's interpolation (:meth:`kcplan.geometry.pose.Edge.pose`)."""
        return Edge(state1, state2, self.dimension).pose(s)

    def body_speeds(self, state1: ArrayLike, state2: ArrayLike) -> NDArray[np.float64]:
        """``|t2 - t1| + reach_k |w12|`` per body (:meth:`kcplan.geometry.pose.Edge.
        sweep_speed`; a turn by ``phi`` moves a point at ``r`` from the origin by a chord of
        at most ``r phi``)."""
        edge = Edge(state1, state2, self.dimension)
        return np.array([edge.sweep_speed(b.reach) for b in self.bodies])

    def body_poses(self, pose: ArrayLike) -> NDArray[np.float64]:
        """World poses of the bodies at the robot pose ``pose``.

        Parameters
        ----------
        pose : array_like, shape (3,) or (7,)

        Returns
        -------
        ndarray, shape (k, 3) or (k, 7)
            Body ``k`` at ``(R R_k, t + R p_k)``.
        """
        n = self.dimension
        p = np.asarray(pose, dtype=float)
        R, t = pose_frame(p, n)
        out = np.empty((len(self.bodies), pose_size(n)))
        for k, body in enumerate(self.bodies):
            out[k, :n] = t + R @ body.position
            if n == 2:
                out[k, 2] = math.remainder(float(p[2] + body.pose[2]), 2.0 * math.pi)
            else:
                q = p[3:] / np.linalg.norm(p[3:])
                out[k, 3:] = quaternion_multiply(q, body.pose[3:])
        return out

    def to_spec(self) -> dict:
        """The robot as the scenario file's ``robot`` fields (without ``inflation``)."""
        if self.is_single:
            return {"semi_axes": self.semi_axes.tolist()}
        n, bodies = self.dimension, []
        for b in self.bodies:
            spec = {"semi_axes": b.semi_axes.tolist(), "position": b.position.tolist()}
            if n == 2:
                spec["yaw"] = float(b.pose[2])
            else:
                spec["quaternion"] = b.pose[3:].tolist()
            bodies.append(spec)
        return {"bodies": bodies}

    def describe(self) -> str:
        """A short human-readable description, e.g. ``ellipse [5, 3.5]`` or
        ``3 ellipsoids``."""
        shape = "ellipse" if self.dimension == 2 else "ellipsoid"
        if self.is_single:
            return f"{shape} {[float(v) for v in self.semi_axes]}"
        return f"{len(self)} {shape}s"
