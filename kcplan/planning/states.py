"""Conversions between OMPL states and kcplan's flat vectors: SE(2)/SE(3) poses of rigid
robots, and arms' joint vectors (a ``RealVectorStateSpace``, or a compound one with
``SO2StateSpace`` parts for angles that wrap).

Only getters and setters are used: ``copyFromReals`` segfaults and ``copyToReals``
silently does nothing on the OMPL 2.0 wheel (ompl-python-notes 1).
"""

from __future__ import annotations

import operator
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike
from ompl import base as ob

from kcplan.arm.description import wrapped

__all__ = [
    "joint_reader",
    "joint_space",
    "joint_state",
    "joint_writer",
    "set_joint_state",
    "set_state",
    "state_pose",
    "state_space",
]


def state_space(low: ArrayLike, high: ArrayLike) -> ob.StateSpace:
    """``SE2StateSpace`` or ``SE3StateSpace`` with translation bounds ``low``..``high``."""
    low, high = np.asarray(low, dtype=float), np.asarray(high, dtype=float)
    n = len(low)
    space = ob.SE2StateSpace() if n == 2 else ob.SE3StateSpace()
    bounds = ob.RealVectorBounds(n)
    for i in range(n):
        bounds.setLow(i, float(low[i]))
        bounds.setHigh(i, float(high[i]))
    space.setBounds(bounds)
    return space


def state_pose(state, n: int) -> np.ndarray:
    """Flat pose of an OMPL state: ``[x, y, yaw]`` or ``[x, y, z, qx, qy, qz, qw]``."""
    if n == 2:
        return np.array([state.getX(), state.getY(), state.getYaw()])
    r = state.rotation()
    return np.array([state.getX(), state.getY(), state.getZ(), r.x, r.y, r.z, r.w])


def _runs(dof: int, wraps: ArrayLike | None) -> list[tuple[bool, range]]:
    """The joints in state order as runs: ``(True, range(j, j + 1))`` for a wrapping
    angle (an ``SO2StateSpace``), ``(False, range(a, b))`` for joints that do not wrap
    (one ``RealVectorStateSpace``)."""
    flags = np.zeros(dof, dtype=bool) if wraps is None else np.asarray(wraps, dtype=bool)
    runs: list[tuple[bool, range]] = []
    for j, wrap in enumerate(flags):
        if wrap or not runs or runs[-1][0]:
            runs.append((bool(wrap), range(j, j + 1)))
        else:
            runs[-1] = (False, range(runs[-1][1].start, j + 1))
    return runs


def joint_space(
    lower: ArrayLike, upper: ArrayLike, wraps: ArrayLike | None = None
) -> ob.StateSpace:
    """The joint space of an arm's planning group: a ``RealVectorStateSpace`` with bounds
    ``lower``, ``upper`` (shape ``(dof,)``, the joint limits); where ``wraps`` (shape
    ``(dof,)``) marks angles that wrap (a moving base's yaw, a continuous joint:
    :mod:`kcplan.arm.description`), a ``CompoundStateSpace`` of ``SO2StateSpace`` for each
    of them and ``RealVectorStateSpace`` for the runs of other joints between them, in
    state order, every weight 1. OMPL then interpolates a wrapping angle the shorter way
    round, and measures distance as the sum of the parts' (L2 within a run)."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    runs = _runs(len(lower), wraps)
    if len(runs) == 1 and not runs[0][0]:
        return _box(lower, upper)
    space = ob.CompoundStateSpace()
    for wrap, joints in runs:
        part = ob.SO2StateSpace() if wrap else _box(lower[joints], upper[joints])
        space.addSubspace(part, 1.0)
    return space


def _box(lower: np.ndarray, upper: np.ndarray) -> ob.RealVectorStateSpace:
    space = ob.RealVectorStateSpace(len(lower))
    bounds = ob.RealVectorBounds(len(lower))
    for j, (low, high) in enumerate(zip(lower, upper, strict=True)):
        bounds.setLow(j, float(low))
        bounds.setHigh(j, float(high))
    space.setBounds(bounds)
    return space


def joint_state(state, dof: int, wraps: ArrayLike | None = None) -> np.ndarray:
    """Joint vector of a state of :func:`joint_space`, shape ``(dof,)``."""
    return np.array(joint_reader(dof, wraps)(state))


def joint_reader(dof: int, wraps: ArrayLike | None = None) -> Callable[[object], tuple[float, ...]]:
    """A function reading the ``dof`` joint values of a state of :func:`joint_space` as a
    tuple. For a ``RealVectorStateSpace``: ``operator.itemgetter``, whose ``dof`` reads
    run in C (0.5 µs for 7 joints against 1.5 µs for a list comprehension, on every state
    an OMPL callback sees); for a compound space, the parts' values in turn."""
    runs = _runs(dof, wraps)
    if len(runs) > 1 or runs[0][0]:
        parts = [(k, wrap, len(joints)) for k, (wrap, joints) in enumerate(runs)]

        def read(state) -> tuple[float, ...]:
            out: list[float] = []
            for k, wrap, count in parts:
                part = state[k]
                if wrap:
                    out.append(part.value)
                else:
                    out.extend(part[i] for i in range(count))
            return tuple(out)

        return read
    if dof == 1:  # itemgetter of one index returns the value, not a tuple
        return lambda state: (state[0],)
    return operator.itemgetter(*range(dof))


def set_joint_state(state, q: ArrayLike, wraps: ArrayLike | None = None) -> None:
    """Write a joint vector into a state of :func:`joint_space` (a wrapping angle brought
    into ``[-pi, pi)``)."""
    joint_writer(len(q), wraps)(state, q)  # the writer makes q an array


def joint_writer(dof: int, wraps: ArrayLike | None = None) -> Callable[[object, ArrayLike], None]:
    """A function writing ``dof`` joint values into a state of :func:`joint_space` (the
    layout worked out once: :func:`set_joint_state` for many states)."""
    runs = _runs(dof, wraps)
    if len(runs) == 1 and not runs[0][0]:

        def write_box(state, q: ArrayLike) -> None:
            for j, value in enumerate(np.asarray(q, dtype=float)):
                state[j] = float(value)

        return write_box

    def write(state, q: ArrayLike) -> None:
        q = np.asarray(q, dtype=float)
        for k, (wrap, joints) in enumerate(runs):
            part = state[k]
            if wrap:
                part.value = float(wrapped(q[joints.start]))
            else:
                for i, j in enumerate(joints):
                    part[i] = float(q[j])

    return write


def set_state(state, pose: ArrayLike, n: int) -> None:
    """Write a flat pose into an OMPL state (quaternions are normalised)."""
    p = np.asarray(pose, dtype=float)
    if n == 2:
        state.setX(float(p[0]))
        state.setY(float(p[1]))
        state.setYaw(float(p[2]))
        return
    state.setXYZ(float(p[0]), float(p[1]), float(p[2]))
    q = p[3:] / np.linalg.norm(p[3:])
    r = state.rotation()
    r.x, r.y, r.z, r.w = (float(v) for v in q)
