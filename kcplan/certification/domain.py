"""The poses a certifier decides; the others are rejected before any arithmetic on them.

Compiled twin: ``kcplan/_kernel/domain.hpp`` (``PoseDomain``; same box, same limits).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["PoseDomain"]


class PoseDomain:
    """The box of robot origins, yaw range and quaternion norms inside which every number
    a certificate computes (squared norms, speeds, distances, grid indices, the AABB of a
    sweep) is finite and exact to the margins the certificates assume.

    A flat pose (:mod:`kcplan.geometry.pose`) is admitted when it is finite and

    * its translation lies in the bounds ``[low, high]`` padded on every side by
      ``pad = |high - low| + reach`` (the bounds' diagonal plus the robot's reach): a
      robot farther out is outside the scene by more than the scene's size, and OMPL's
      planners never produce it; without bounds, in ``|x| <= LIMIT``;
    * in 2D, ``|yaw| <= 2 pi``: OMPL's SO(2) states lie in ``[-pi, pi]``, and a larger
      angle loses digits (its rounding error times the robot's reach would exceed the
      guards' margin);
    * in 3D, the quaternion's squared norm lies in ``[1e-200, 1e200]``, so that its
      normalisation neither overflows nor divides by a number that underflowed.

    Rejecting a pose is always sound: :meth:`admits` only narrows what is certified.

    Parameters
    ----------
    dimension : int
        2 or 3.
    low, high : array_like, shape (dimension,), optional
        Bounds of the robot's origin, in length units; both or neither.
    reach : float
        The robot's reach (farthest point of a body from the robot's origin).

    Raises
    ------
    ValueError
        Bounds that are not finite, ``low > high``, or a padded box beyond ``LIMIT``.
    """

    LIMIT = 1e100
    """Largest admitted coordinate magnitude: squared distances stay finite."""
    QUATERNION_SQUARED_NORMS = (1e-200, 1e200)

    def __init__(
        self,
        dimension: int,
        low: ArrayLike | None = None,
        high: ArrayLike | None = None,
        reach: float = 0.0,
    ):
        self.dimension = int(dimension)
        n = self.dimension
        if low is None or high is None:
            self.low = [-self.LIMIT] * n
            self.high = [self.LIMIT] * n
            return
        lo = np.asarray(low, dtype=float)[:n]
        hi = np.asarray(high, dtype=float)[:n]
        if not (np.isfinite(lo).all() and np.isfinite(hi).all() and (lo <= hi).all()):
            raise ValueError("bounds: expected finite numbers with low <= high")
        if not (math.isfinite(reach) and reach >= 0.0):
            raise ValueError("reach: expected a finite number >= 0")
        pad = math.hypot(*(hi - lo).tolist()) + reach
        self.low = (lo - pad).tolist()
        self.high = (hi + pad).tolist()
        if not max(map(abs, self.low + self.high)) <= self.LIMIT:
            raise ValueError("bounds: expected |low|, |high| and the scene's size <= 1e100")

    def admits(self, pose: ArrayLike) -> bool:
        """Whether ``pose`` (shape ``(3,)`` or ``(7,)``) is decided (True) or rejected
        unseen (False)."""
        p = [float(v) for v in np.asarray(pose, dtype=float).ravel()]
        n = self.dimension
        if len(p) != (3 if n == 2 else 7) or not all(map(math.isfinite, p)):
            return False
        for x, lo, hi in zip(p[:n], self.low, self.high, strict=True):
            if not lo <= x <= hi:
                return False
        if n == 2:
            return abs(p[2]) <= 2.0 * math.pi
        q = p[3:]
        if max(map(abs, q)) > self.LIMIT:
            return False
        low, high = self.QUATERNION_SQUARED_NORMS
        return low <= sum(v * v for v in q) <= high
