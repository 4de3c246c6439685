"""A joint-space path with its corners replaced by quadratic blends.

The planner's path is a polyline through the waypoints ``W_0 .. W_{N-1}`` (joint vectors,
``n`` each). At an interior waypoint ``c = W_i`` with incoming unit direction ``u1 = (W_i -
W_{i-1}) / |W_i - W_{i-1}|`` and outgoing ``u2``, a *blend* of size ``delta_i > 0`` leaves
the polyline at ``a = c - delta_i u1`` and rejoins it at ``b = c + delta_i u2`` along the
quadratic Bezier curve with control points ``a, c, b``:

    B(t) = (1 - t)^2 a + 2 t (1 - t) c + t^2 b,        t in [0, 1].

So ``B(t) - c = -(1 - t)^2 delta_i u1 + t^2 delta_i u2``: every point of the blend lies
within ``delta_i max(|u1_j|, |u2_j|)`` of ``c`` in each joint ``j`` (as ``(1 - t)^2 + t^2 <=
1``), which is what :mod:`kcplan.trajectory.smoothing` proves free. ``delta_i = 0`` keeps
the corner (the curve then has a kink there and a trajectory stops at it).

The curve is parametrised by ``s``: arc length (Euclidean, in joint space) on the
straight pieces, and ``s - s_0 = 2 delta_i t`` on a blend, so that ``dq/ds`` is continuous:
``u1`` where the blend begins and ``u2`` where it ends. Every piece is then a quadratic in
``tau = s - s_0``,

    q(tau) = P0 + P1 tau + P2 tau^2,   line: P1 = u, P2 = 0;
                                       blend: P0 = a, P1 = u1, P2 = (u2 - u1) / (4 delta_i),

which is how :class:`BlendedPath` stores it (a :class:`scipy.interpolate.PPoly`): the curve
is C^1 where no corner is kept, ``d^2q/ds^2`` is piecewise constant. It imports neither
OMPL nor FCL.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import PPoly

__all__ = ["BlendedPath", "corner_directions"]

TURN_FLOOR = 1e-12
"""A corner whose unit directions differ by less than this (in norm) is straight: it is
neither blended nor kept as a kink."""
BLEND_FLOOR = 1e-4
"""Radians: a blend smaller than this is no blend (the corner is kept as a kink; a
trajectory stops there, as it nearly would through so sharp a turn: TOPP-RA on blends of
5e-9 and 5e-6 rad took 4 % and 2.5 % longer than stopping)."""


def corner_directions(waypoints: NDArray[np.float64]) -> tuple[NDArray, NDArray, NDArray]:
    """The unit directions into and out of each interior waypoint and the segments' lengths.

    Parameters
    ----------
    waypoints : ndarray, shape (N, n)
        The polyline's vertices; consecutive ones must differ.

    Returns
    -------
    incoming, outgoing : ndarray, shape (N - 2, n)
        ``u1`` and ``u2`` of each interior waypoint (module docstring).
    lengths : ndarray, shape (N - 1,)
        The segments' Euclidean lengths.
    """
    steps = np.diff(waypoints, axis=0)
    lengths = np.linalg.norm(steps, axis=1)
    if (lengths <= 0).any():
        raise ValueError(f"waypoints: expected consecutive waypoints to differ, segment "
                         f"{int(np.argmin(lengths))} has length 0")  # fmt: skip
    units = steps / lengths[:, None]
    return units[:-1], units[1:], lengths


class BlendedPath:
    """The polyline through ``waypoints`` with a quadratic blend of size ``blends[i]`` at
    each interior waypoint (module docstring); a geometric path in TOPP-RA's sense
    (``__call__(s, order)``, ``dof``, ``path_interval``).

    Parameters
    ----------
    waypoints : array_like, shape (N, n)
        At least two joint vectors; consecutive ones differ.
    blends : array_like, shape (N - 2,), optional
        ``delta_i >= 0`` of each interior waypoint, in the joint space's length unit (rad);
        the two blends of a segment must fit on it (``delta_i + delta_{i+1} <=`` its length,
        the end waypoints having none); one below :data:`BLEND_FLOOR` keeps its corner.
        Default: no blend (the polyline).
    """

    def __init__(self, waypoints: ArrayLike, blends: ArrayLike | None = None) -> None:
        W = np.array(waypoints, dtype=float)
        if W.ndim != 2 or len(W) < 2 or not np.isfinite(W).all():
            raise ValueError("waypoints: expected at least two finite joint vectors (N, n)")
        u1, u2, lengths = corner_directions(W)
        delta = np.zeros(len(W) - 2) if blends is None else np.array(blends, dtype=float)
        if delta.shape != (len(W) - 2,) or not (delta >= 0).all():
            raise ValueError(f"blends: expected {len(W) - 2} numbers >= 0, got {delta.shape}")
        turns = np.linalg.norm(u2 - u1, axis=1)
        delta = np.where((turns < TURN_FLOOR) | (delta < BLEND_FLOOR), 0.0, delta)
        ends = np.concatenate([[0.0], delta, [0.0]])  # what each waypoint's blend takes
        straight = lengths - ends[:-1] - ends[1:]
        if (straight < -1e-12 * np.maximum(lengths, 1.0)).any():
            k = int(np.argmin(straight))
            raise ValueError(f"blends: the blends at both ends of segment {k} exceed its "
                             f"length {float(lengths[k])!r}")  # fmt: skip
        units = np.diff(W, axis=0) / lengths[:, None]
        coefficients, breaks, self._kinks = [], [0.0], []
        for k in range(len(lengths)):
            if k > 0 and delta[k - 1] > 0:  # the blend at waypoint k
                d = delta[k - 1]
                coefficients.append(((u2[k - 1] - u1[k - 1]) / (4 * d), u1[k - 1],
                                     W[k] - d * u1[k - 1]))  # fmt: skip
                breaks.append(breaks[-1] + 2 * d)
            elif k > 0 and turns[k - 1] >= TURN_FLOOR:
                self._kinks.append(breaks[-1])
            if straight[k] > 0:
                coefficients.append((np.zeros(W.shape[1]), units[k], W[k] + ends[k] * units[k]))
                breaks.append(breaks[-1] + straight[k])
        self.waypoints, self.blends = W, delta
        self._poly = PPoly(np.array(coefficients).transpose(1, 0, 2), np.array(breaks))
        self._speed = self._poly.derivative()
        self._accel = self._speed.derivative()

    @property
    def dof(self) -> int:
        """Joints per configuration."""
        return int(self.waypoints.shape[1])

    @property
    def path_interval(self) -> NDArray[np.float64]:
        """``[0, S]``: the curve's parameter range (``S`` its length in ``s``)."""
        return np.array([0.0, float(self._poly.x[-1])])

    @property
    def length(self) -> float:
        """``S``, the end of the parameter range."""
        return float(self._poly.x[-1])

    @property
    def breakpoints(self) -> NDArray[np.float64]:
        """Where the pieces meet (``s``), ends included."""
        return np.array(self._poly.x)

    @property
    def curved(self) -> NDArray[np.bool_]:
        """Per piece: whether it is a blend (its ``d^2q/ds^2`` is not 0)."""
        return np.any(self._poly.c[0] != 0.0, axis=1)

    @property
    def kinks(self) -> list[float]:
        """``s`` of each corner kept (``delta_i = 0`` where the path turns): a trajectory
        must stop there."""
        return list(self._kinks)

    def __call__(self, s: float | ArrayLike, order: int = 0) -> NDArray[np.float64]:
        """``q(s)``, ``dq/ds`` or ``d^2q/ds^2`` (``order`` 0, 1, 2) at ``s``: shape ``(n,)``
        for a scalar, ``(len(s), n)`` for an array. A breakpoint takes the piece after it."""
        poly = (self._poly, self._speed, self._accel)[order]
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        return poly(s)

    def eval(self, s):  # TOPP-RA's names
        return self(s, 0)

    def evald(self, s):
        return self(s, 1)

    def evaldd(self, s):
        return self(s, 2)

    def pieces(self) -> list[tuple[Callable[[float], NDArray[np.float64]], NDArray[np.float64]]]:
        """Each piece as ``(f, bound)``: ``f(sigma)``, ``sigma`` in ``[0, 1]``, is the
        configuration at ``s_0 + sigma (s_1 - s_0)``, and ``bound[j]`` bounds ``|df_j /
        dsigma|`` over the piece (the derivative is linear in ``sigma``, so its largest
        size is at an end); for a gap-free check such as
        :meth:`kcplan.arm.verify.ArmMeshChecker.check_pieces`."""
        out = []
        x, c = self._poly.x, self._poly.c
        for k in range(len(x) - 1):
            P2, P1, P0 = c[0, k], c[1, k], c[2, k]
            h = float(x[k + 1] - x[k])
            bound = h * np.maximum(np.abs(P1), np.abs(P1 + 2 * P2 * h))

            def f(sigma: float, P0=P0, P1=P1, P2=P2, h=h) -> NDArray[np.float64]:
                tau = sigma * h
                return P0 + tau * (P1 + tau * P2)

            out.append((f, bound))
        return out
