"""Time-optimal timing of a geometric path within joint velocity and acceleration limits.

TOPP-RA (Pham and Pham, "A New Approach to Time-Optimal Path Parameterization Based on
Reachability Analysis", T-RO 34(3), 2018; PyPI ``toppra``) finds the path velocity
``sd(s) = ds/dt`` at gridpoints ``s_0 < ... < s_G`` that reaches the end soonest while

    |q'(s) sd| <= v,    |q''(s) sd^2 + q'(s) sdd| <= a          (per joint, elementwise)

at the gridpoints; between two gridpoints the path acceleration ``sdd`` is constant
(toppra's ``ParametrizeConstAccel`` law), so ``x = sd^2`` is linear in ``s`` there. The
trajectory ``q(t) = path(s(t))`` follows the path exactly: timing never leaves the curve.

*Exact limits.* TOPP-RA constrains the gridpoints only. On a grid interval inside one
piece of a :class:`kcplan.trajectory.curve.BlendedPath` ``q''`` is a constant ``g`` and
``q'(s_i + sigma) = q'_i + g sigma``, so with ``x = x_i + 2 u sigma``

    qdd(sigma) = g x_i + q'_i u + 3 g u sigma                      (linear in sigma)
    qd(sigma)  = (q'_i + g sigma) sqrt(x_i + 2 u sigma)            (one stationary point,
                 sigma* = -(g x_i + q'_i u) / (3 g u))

and :meth:`Trajectory.peak_ratios` takes the largest ``|qd_j| / v_j`` and ``|qdd_j| / a_j``
over the whole trajectory from the interval ends and ``sigma*``, not from samples. Where
either exceeds 1 (TOPP-RA's discretization), :func:`time_path` slows the whole trajectory
by the factor that brings it to 1 (time scaling ``t -> k t`` divides velocities by ``k``
and accelerations by ``k^2``), so the trajectory it returns is within its limits
everywhere. A kept corner (a kink, :attr:`BlendedPath.kinks`) is passed at rest: the path
is timed in sections between kinks, each from rest to rest.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.trajectory.curve import BlendedPath

__all__ = ["GRID_INTERVALS", "Trajectory", "sample_times", "time_path"]

GRID_INTERVALS = 40
"""TOPP-RA grid intervals per section of the path (between kinks), spread by length, every
breakpoint of the path among them and at least :data:`BLEND_INTERVALS` per blend. On a
random 7-joint path with blends of 0.1 rad, 40 give a duration 0.5 % above 1000's (100:
0.2 %); on MBM paths 0.1 % at most, in about half the time of 100."""
BLEND_INTERVALS = 6
SIDE = 1e-3
"""A breakpoint where a blend meets a line has a gridpoint this share of the piece before
it: TOPP-RA reads the path's derivatives at a gridpoint from the piece after it, so the
interval ending there is constrained by its own piece's, up to a change of order SIDE
(1e-7 made TOPP-RA's solver lose the constraint on so short an interval; 1e-2 needed a
0.4 % slow-down; 1e-3 none, and 0.5 % shorter trajectories than without it)."""


def sample_times(duration: float, rate: float) -> NDArray[np.float64]:
    """Seconds ``0, 1 / rate, 2 / rate, ...`` up to ``duration``, which is the last.

    Raises
    ------
    ValueError
        A rate that is not a finite number > 0.
    """
    if not (rate > 0 and math.isfinite(rate)):
        raise ValueError(f"rate: expected a finite number of samples per second > 0, got "
                         f"{rate!r}")  # fmt: skip
    t = np.arange(0.0, duration, 1.0 / rate)
    return np.append(t, duration) if t.size == 0 or t[-1] < duration else t


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A path timed: ``q(t) = path(s(t))`` with ``s(t)`` piecewise quadratic.

    Attributes
    ----------
    path : BlendedPath
    grid : ndarray, shape (G,)
        Gridpoints in ``s``, increasing; breakpoints of the path among them.
    speeds : ndarray, shape (G,)
        ``ds/dt`` at the gridpoints (0 at both ends and at every kink).
    times : ndarray, shape (G,)
        Seconds at the gridpoints, from 0.
    velocity_limits, acceleration_limits : ndarray, shape (n,)
        The limits it was timed with (rad/s and rad/s^2, or m/s and m/s^2 for a prismatic
        joint).
    """

    path: BlendedPath
    grid: NDArray[np.float64]
    speeds: NDArray[np.float64]
    times: NDArray[np.float64]
    velocity_limits: NDArray[np.float64]
    acceleration_limits: NDArray[np.float64]

    @property
    def duration(self) -> float:
        """Seconds from start to end."""
        return float(self.times[-1])

    def _law(self) -> tuple[NDArray, NDArray]:
        """Each interval's ``x_i = sd_i^2`` and path acceleration ``u_i``."""
        x = self.speeds**2
        return x, (x[1:] - x[:-1]) / (2.0 * np.diff(self.grid))

    def at(self, t: ArrayLike) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """``(s, q, qd, qdd)`` at the times ``t`` (seconds, shape ``(m,)``; clipped to
        ``[0, duration]``): ``s`` shape ``(m,)``, the others ``(m, n)``."""
        t = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        _, u = self._law()
        i = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, len(u) - 1)
        dt = t - self.times[i]
        sd = self.speeds[i] + u[i] * dt
        s = np.minimum(self.grid[i] + dt * (self.speeds[i] + 0.5 * u[i] * dt), self.grid[i + 1])
        # the interval's own piece (right of its start), also at its end: dq/ds is linear
        start = self.grid[i]
        d2 = self.path(start, 2)
        d1 = self.path(start, 1) + d2 * (s - start)[:, None]
        return s, self.path(s), d1 * sd[:, None], d2 * (sd**2)[:, None] + d1 * u[i][:, None]

    def sample(self, rate: float) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray]:
        """``(t, s, q, qd, qdd)`` every ``1 / rate`` seconds from 0, the end included."""
        t = sample_times(self.duration, rate)
        return (t, *self.at(t))

    def peak_ratios(self) -> tuple[float, float]:
        """The largest ``|qd_j| / v_j`` and ``|qdd_j| / a_j`` over the whole trajectory,
        exactly (module docstring)."""
        x, u = self._law()
        lo, h = self.grid[:-1], np.diff(self.grid)
        d1 = self.path(lo, 1)  # the piece right of each gridpoint
        g = self.path(lo, 2)
        uu = u[:, None]
        acc = np.maximum(np.abs(g * x[:-1, None] + d1 * uu),
                         np.abs(g * x[:-1, None] + d1 * uu + 3 * g * uu * h[:, None]))  # fmt: skip
        vel = np.maximum(np.abs(d1) * np.sqrt(x[:-1, None]),
                         np.abs(d1 + g * h[:, None]) * np.sqrt(x[1:, None]))  # fmt: skip
        with np.errstate(divide="ignore", invalid="ignore"):
            star = -(g * x[:-1, None] + d1 * uu) / (3 * g * uu)
        inside = np.isfinite(star) & (star > 0) & (star < h[:, None])
        if inside.any():
            sig = np.where(inside, star, 0.0)
            at = np.abs(d1 + g * sig) * np.sqrt(np.maximum(x[:-1, None] + 2 * uu * sig, 0.0))
            vel = np.maximum(vel, np.where(inside, at, 0.0))
        return (float((vel / self.velocity_limits).max(initial=0.0)),
                float((acc / self.acceleration_limits).max(initial=0.0)))  # fmt: skip


class _Section:
    """``path`` restricted to ``[lo, hi]`` (TOPP-RA reads the interval off the path)."""

    def __init__(self, path: BlendedPath, lo: float, hi: float) -> None:
        self._path, self.path_interval = path, np.array([lo, hi])
        self.dof = path.dof

    def __call__(self, s, order: int = 0):
        return self._path(s, order)


def _grid(path: BlendedPath, lo: float, hi: float, intervals: int) -> NDArray[np.float64]:
    """Gridpoints of ``[lo, hi]``: every breakpoint, each piece cut evenly so that no
    interval exceeds ``h = (hi - lo) / intervals``, a blend into at least
    :data:`BLEND_INTERVALS`, and a straight piece also at ``h / 16 .. h / 2`` from each end,
    where its speed turns into a blend's (on a random 7-joint path with blends of 0.1 rad,
    at 100 intervals, 0.2 % above the duration on a grid ten times finer, against 11 %
    without)."""
    breaks = path.breakpoints
    breaks = breaks[(breaks >= lo) & (breaks <= hi)]
    step = (hi - lo) / intervals
    out = [breaks[:1]]
    for a, b in zip(breaks[:-1], breaks[1:], strict=True):
        k = int(np.searchsorted(path.breakpoints, a, side="right") - 1)
        n = max(math.ceil((b - a) / step), BLEND_INTERVALS if path.curved[k] else 1)
        points = np.linspace(a, b, n + 1)[1:]
        if not path.curved[k]:
            h = min(step, b - a) * np.array([1 / 16, 1 / 8, 1 / 4, 1 / 2])
            points = np.concatenate([points, a + h, b - h])
        if k + 1 < len(path.curved) and path.curved[k] != path.curved[k + 1]:
            points = np.append(points, b - SIDE * (b - a))  # the piece's own end (below)
        out.append(np.unique(points))
    return np.concatenate(out)


def time_path(
    path: BlendedPath,
    velocity_limits: ArrayLike,
    acceleration_limits: ArrayLike,
    intervals: int = GRID_INTERVALS,
) -> Trajectory:
    """Time ``path`` from rest to rest with TOPP-RA, within the limits everywhere.

    Parameters
    ----------
    path : BlendedPath
    velocity_limits, acceleration_limits : array_like, shape (n,)
        Per joint, > 0 and finite (rad/s and rad/s^2; m/s and m/s^2 for a prismatic joint).
    intervals : int
        Grid intervals per section (:data:`GRID_INTERVALS`).

    Returns
    -------
    Trajectory
        Its :meth:`Trajectory.peak_ratios` are at most 1 (module docstring).

    Raises
    ------
    ValueError
        Bad limits.
    RuntimeError
        TOPP-RA found no parametrization (it reports the path uncontrollable).
    """
    import toppra

    n = path.dof
    v = np.array(velocity_limits, dtype=float).reshape(-1)
    a = np.array(acceleration_limits, dtype=float).reshape(-1)
    for name, lim in (("velocity_limits", v), ("acceleration_limits", a)):
        if lim.shape != (n,) or not (np.isfinite(lim).all() and (lim > 0).all()):
            raise ValueError(f"{name}: expected {n} finite numbers > 0, got {lim.tolist()}")
    toppra.setup_logging("ERROR")
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.column_stack([-v, v])),
        toppra.constraint.JointAccelerationConstraint(np.column_stack([-a, a])),
    ]
    cuts = [0.0, *path.kinks, path.length]
    grids, speeds = [], []
    for lo, hi in zip(cuts[:-1], cuts[1:], strict=True):
        grid = _grid(path, lo, hi, intervals)
        algorithm = toppra.algorithm.TOPPRA(constraints, _Section(path, lo, hi), gridpoints=grid)
        _, sd, _ = algorithm.compute_parameterization(0.0, 0.0)
        if sd is None or not np.isfinite(sd).all():
            raise RuntimeError(f"TOPP-RA found no timing of the path on s in [{lo}, {hi}]")
        sd = np.maximum(sd, 0.0)
        sd[0] = sd[-1] = 0.0
        if grids:  # a kink: the sections meet at rest
            grid, sd = grid[1:], sd[1:]
        grids.append(grid), speeds.append(sd)
    grid, sd = np.concatenate(grids), np.concatenate(speeds)
    trajectory = _timed(path, grid, sd, v, a)
    rv, ra = trajectory.peak_ratios()
    scale = max(rv, math.sqrt(ra))
    if scale > 1.0:  # TOPP-RA's gridpoints only: slow it all down to the limits
        trajectory = _timed(path, grid, sd / (scale * (1.0 + 1e-12)), v, a)
    return trajectory


def _timed(path, grid, sd, v, a) -> Trajectory:
    dt = 2.0 * np.diff(grid) / (sd[:-1] + sd[1:])
    return Trajectory(path, grid, sd, np.concatenate([[0.0], np.cumsum(dt)]), v, a)
