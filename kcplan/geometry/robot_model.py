"""What every kind of robot says about itself: one concept, two implementations.

Every certificate rests on three things a robot says about itself: its states, where its
bodies are at a state, and how far any point of a body can move along the edge between
two states (a guard's clearance divided by that speed is the stretch it proves, before
any sharper bound). :class:`RobotModel` is that contract, which each kind of robot keeps;
the certifiers add their own sharper, kind-specific bounds (the rigid robots' levers and
KC sets, the arms' chain bounds) on top of it:

* :class:`kcplan.geometry.robot.Robot`: a rigid robot of ellipses (2D) or ellipsoids
  (3D); its state is a pose ``[x, y, yaw]`` or ``[x, y, z, qx, qy, qz, qw]``, an edge is
  OMPL's interpolation in SE(2) or SE(3) (:class:`kcplan.geometry.pose.Edge`);
* :class:`kcplan.arm.ArmModel`: an arm's planning group; its state is a joint vector
  (radians, metres for a prismatic joint), an edge the straight joint-space segment.

The world a robot moves in says what is near its bodies (a ``CollisionWorld`` or an
``ArmWorld``), and :func:`kcplan.certification.certifiers.certifier_for` combines the two into
the certifier, chosen once.

This module imports neither OMPL nor FCL.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["RobotModel"]


class RobotModel(ABC):
    """A kind of robot (module docstring): its states, its bodies at a state, and how far
    they move along an edge.

    Contract, for every implementation:

    * a state is :attr:`state_size` floats (:meth:`edge_state` returns one);
    * :meth:`body_frames` places body ``k`` rigidly: a point ``x`` in the body's own frame
      lies at ``F_k(q) [x, 1]`` in the world at the state ``q``;
    * :meth:`body_speeds` bounds the motion of every point of every body along the edge
      ``q(s) = edge_state(q1, q2, s)``, ``s in [0, 1]``: for all ``s, s'`` and every
      point ``x`` of body ``k``, ``|F_k(q(s')) x - F_k(q(s)) x| <= v_k |s' - s|``. A
      certifier's guard with clearance ``d`` therefore proves the stretch ``|s - m| <
      d / v_k`` of body ``k`` free (conservative advancement; Schwarzer, Saha and Latombe
      2005).

    ``tests/test_robot_model.py`` holds both implementations to it (hypothesis).
    """

    @property
    @abstractmethod
    def state_size(self) -> int:
        """Floats in a state (OMPL's state as a flat vector)."""

    @property
    @abstractmethod
    def workspace_dimension(self) -> int:
        """2 or 3: the dimension of the space the bodies move in."""

    @property
    @abstractmethod
    def body_count(self) -> int:
        """Number of bodies (ellipsoids, or an arm's hulls and primitives)."""

    @abstractmethod
    def describe(self) -> str:
        """One line for reports, e.g. ``ellipse [5, 3.5]`` or ``arm of 7 joints, 10
        bodies (panda.urdf)``."""

    @abstractmethod
    def body_frames(self, state: ArrayLike) -> NDArray[np.float64]:
        """World frames of the bodies at ``state``.

        Parameters
        ----------
        state : array_like, shape (state_size,)

        Returns
        -------
        ndarray, shape (body_count, d + 1, d + 1)
            Homogeneous frames, ``d`` the :attr:`workspace_dimension`: body ``k``'s
            origin is its centre and its axes are its own.
        """

    @abstractmethod
    def edge_state(self, state1: ArrayLike, state2: ArrayLike, s: float) -> NDArray[np.float64]:
        """The state at ``s in [0, 1]`` along the straight edge from ``state1`` to
        ``state2`` (OMPL's interpolation in the robot's state space)."""

    @abstractmethod
    def body_speeds(self, state1: ArrayLike, state2: ArrayLike) -> NDArray[np.float64]:
        """Bound on how fast any point of each body moves along the edge, shape
        ``(body_count,)``, length units per unit of the edge parameter ``s`` (the class
        contract)."""
