"""A ladder of the paper's convex lower bounds ``P_eps`` of one robot, cached on disk.

The KC-polytope certificate (:mod:`kcplan.certification.certificates.polytope`) picks the
largest inflation a guard's clearance allows and asks the ladder how far ``P_eps``
reaches along the edge's KC direction (its gauge: one matrix-vector product).
"""

from __future__ import annotations

import bisect
import hashlib
import math
import os
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from kcplan.files import atomic_output
from kcplan.geometry import containment as containment_module
from kcplan.geometry import ellipsoid as ellipsoid_module
from kcplan.geometry import rotations as rotations_module
from kcplan.kc import convex as convex_module
from kcplan.kc.convex import ConvexLowerBound

__all__ = ["DEFAULT_LADDER", "GuardLadder", "polytope_cache_dir"]

DEFAULT_LADDER = {
    2: (0.002, 0.005, 0.01, 0.02, 0.04, 0.08, 0.16, 0.32, 0.64, 1.28),
    3: (0.005, 0.02, 0.08, 0.3),
}
"""Guard inflations built per robot. 2D polytopes cost about 0.15 s each, 3D ones 1 to
3 s (72 vertices, 2048 half-spaces), hence the shorter 3D ladder."""


CACHE_ENV = "KCPLAN_CACHE_DIR"
"""Environment variable naming the polytope cache folder; ``off`` disables the cache.
Default ``$XDG_CACHE_HOME/kcplan`` (``~/.cache/kcplan``)."""


def polytope_cache_dir() -> Path | None:
    """Folder of cached guard polytopes, or None when the cache is off."""
    value = os.environ.get(CACHE_ENV)
    if value == "off":
        return None
    if value:
        return Path(value)
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "kcplan"


@lru_cache(maxsize=1)
def _algorithm_digest() -> str:
    # A cached polytope is only reused by the exact code that built it.
    h = hashlib.sha256()
    for module in (convex_module, containment_module, rotations_module, ellipsoid_module):
        h.update(Path(module.__file__).read_bytes())
    return h.hexdigest()[:16]


@lru_cache(maxsize=64)
def _halfspaces(semi_axes: tuple, inflation: float) -> tuple[np.ndarray, np.ndarray]:
    """``(A, c)`` of ``ConvexLowerBound(a, eps)``: from memory, the disk cache, or built.

    Building costs 0.15 s (2D) to 5 s (3D) per polytope; every ``kcplan plan`` and every
    benchmark run is a new process, so the rows are kept on disk, keyed by ``(a, eps)``
    and a digest of the code that builds them, and written atomically.
    """
    folder = polytope_cache_dir()
    key = hashlib.sha256(repr((semi_axes, inflation, _algorithm_digest())).encode()).hexdigest()
    cached = folder / f"polytope-{key[:24]}.npz" if folder else None
    if cached is not None and cached.is_file():
        try:
            with np.load(cached) as data:
                if str(data["key"]) == key:
                    return data["A"], data["c"]
        except (OSError, ValueError, KeyError):
            pass  # unreadable or foreign file: rebuild and overwrite
    A, c = ConvexLowerBound(np.array(semi_axes), inflation).halfspaces
    if cached is not None:
        try:
            folder.mkdir(parents=True, exist_ok=True)
            with atomic_output(cached) as tmp:
                np.savez(tmp, A=A, c=c, key=key)
        except OSError:
            pass  # a read-only home only costs the rebuild next time
    return A, c


class GuardLadder:
    """Convex lower bounds of one robot for an increasing list of guard inflations.

    Polytopes depend only on ``(a, eps)``, never on the guard's pose, so they are built
    once and shared: in memory per process, and on disk across processes (see
    :func:`polytope_cache_dir`; set ``KCPLAN_CACHE_DIR=off`` to always rebuild).

    Parameters
    ----------
    semi_axes : array_like, shape (n,)
    inflations : sequence of float, optional
        Increasing guard inflations; default :data:`DEFAULT_LADDER`.
    """

    def __init__(self, semi_axes: ArrayLike, inflations: Sequence[float] | None = None):
        a = np.asarray(semi_axes, dtype=float)
        n = len(a)
        levels = tuple(sorted(float(e) for e in (inflations or DEFAULT_LADDER[n])))
        self.semi_axes, self.inflations = a, np.array(levels)
        rows = [_halfspaces(tuple(a.tolist()), e) for e in levels]
        # rows scaled to A_i / c_i (c > 0: the origin is interior), so the gauge needs
        # only a matrix-vector product and two reductions
        self._scaled = [A / c[:, None] for A, c in rows]
        self._levels = levels
        self.scale = float(a.max())

    @property
    def scaled_rows(self) -> list[np.ndarray]:
        """Per level, the rows ``A_i / c_i`` of ``P_eps``, shape ``(rows, 3 or 6)``."""
        return list(self._scaled)

    def level_for(self, clearance: float) -> int:
        """Index of the largest inflation a guard with this clearance allows, or -1."""
        return bisect.bisect_right(self._levels, clearance / self.scale) - 1

    def reach(self, level: int, direction: np.ndarray) -> tuple[float, float]:
        """How far ``P_eps = {xi : A xi <= c}`` extends along ``+direction`` and
        ``-direction``: ``1 / max_i (A_i d / c_i)`` and ``1 / max_i (-A_i d / c_i)``
        (``inf`` where no row bounds that side)."""
        proj = self._scaled[level] @ direction
        top, bottom = float(proj.max()), float(proj.min())
        return (1.0 / top if top > 0.0 else math.inf, -1.0 / bottom if bottom < 0.0 else math.inf)
