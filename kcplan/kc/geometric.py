"""The geometric lower bound of the KC C-space (paper Sec. 5, eq. 15-19, 28, 33-37).

For each orientation ``R`` of the robot, the linear map ``T = R diag(a / r) R^T``,
``r = min(a)``, turns ``R E_a`` into the ball of radius ``r``; ``T^{-1} E_b`` is an
ellipsoid ``E_b'`` with semi-axes ``b'`` along the orthonormal columns of ``V``. The
Minkowski difference of ``E_b'`` and the ball is the inward parallel body of ``E_b'``
at distance ``r``; along its semi-axis ``i`` it extends to ``d_i*`` (eq. 19 with the
critical radius of eq. 28, see :func:`kcplan.geometry.sphere_frames`). The
cross-polytope ``conv{+/- d_i* V e_i}`` lies inside the (convex) parallel body, so
``T`` maps it into ``E_b - R E_a``: a polytope of
translations, per orientation, all of which keep the robot inside the guard. The
formula is checked in the tests against the exact radial function of the Minkowski
difference (:func:`kcplan.geometry.radial_extent`): the two agree to 1e-12.
"""

from __future__ import annotations

from math import factorial

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.geometry.ellipsoid import as_inflation, as_semi_axes
from kcplan.geometry.minkowski import sphere_frames
from kcplan.geometry.rotations import rotation_dimension, split_xi
from kcplan.kc.volume import orientation_quadrature

__all__ = ["GeometricLowerBound"]


class GeometricLowerBound:
    """Per-orientation cross-polytopes inside the KC C-space of ``E_a`` in ``(1+eps) E_a``.

    Parameters
    ----------
    semi_axes : array_like, shape (n,)
        Robot semi-axes ``a``, n = 2 or 3.
    inflation : float
        ``eps > 0``; the guard has semi-axes ``b = (1 + eps) a``.

    Notes
    -----
    Not convex across orientations, but exact per orientation up to the cross-polytope
    inscribed in a convex slice; cheap to query and to integrate. The right tool for
    "is this whole set of poses inside the target?" (paper Sec. 9.2).
    """

    def __init__(self, semi_axes: ArrayLike, inflation: float) -> None:
        self.a = as_semi_axes(semi_axes)
        self.inflation = as_inflation(inflation)
        self.b = (1.0 + self.inflation) * self.a
        self.n = self.a.shape[0]
        self.radius = float(self.a.min())

    def _frames(self, omega: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        """``T^{-1}`` (k, n, n), the shrunk guard's axes ``V`` (k, n, n) and ``d*`` (k, n)."""
        T, V, d = sphere_frames(self.a, self.b, omega)
        return np.linalg.inv(T), V, d

    def extreme_distances(self, omega: ArrayLike) -> NDArray[np.float64]:
        """``d_i*`` of eq. 19 along the shrunk guard's semi-axes, for each orientation.

        Parameters
        ----------
        omega : array_like, shape (k, r) or (r,)

        Returns
        -------
        ndarray, shape (k, n) or (n,)
            Zeros where ``R E_a`` does not fit in ``E_b``.
        """
        om = np.asarray(omega, dtype=float)
        single = om.ndim == 1
        d = self._frames(np.atleast_2d(om).reshape(-1, rotation_dimension(self.n)))[2]
        return d[0] if single else d

    def vertices_at(self, omega: ArrayLike) -> NDArray[np.float64]:
        """The ``2n`` cross-polytope vertices (translations) at one orientation, shape (2n, n)."""
        T_inv, V, d = self._frames(np.atleast_2d(np.asarray(omega, dtype=float)))
        T = np.linalg.inv(T_inv[0])
        half = (T @ V[0] * d[0][None, :]).T
        return np.vstack([half, -half])

    def contains(self, xi: ArrayLike) -> NDArray[np.bool_] | bool:
        """True for KC coordinates whose translation lies in the cross-polytope of its rotation.

        Parameters
        ----------
        xi : array_like, shape (k, d) or (d,)
        """
        omega, tau, single = split_xi(xi, self.n)
        T_inv, V, d = self._frames(omega)
        z = np.einsum("kji,kj->ki", V, np.einsum("kij,kj->ki", T_inv, tau))
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(d > 0, np.abs(z) / d, np.where(z == 0, 0.0, np.inf)).sum(axis=1)
        inside = (s <= 1.0) & np.all(d > 0, axis=1)
        return bool(inside[0]) if single else inside

    def volume_at(self, omega: ArrayLike) -> NDArray[np.float64] | float:
        """Volume of the cross-polytope at each orientation: ``2^n/n! prod(d*) det(T)``."""
        om = np.asarray(omega, dtype=float)
        single = om.ndim == 1
        d = self.extreme_distances(np.atleast_2d(om).reshape(-1, rotation_dimension(self.n)))
        v = 2.0**self.n / factorial(self.n) * np.prod(d, axis=1) * np.prod(self.a / self.radius)
        return float(v[0]) if single else v

    def volume(self, measure: str = "exponential", accuracy: str = "normal") -> float:
        """Integral of :meth:`volume_at` over the identity component of orientations.

        Same measure and component conventions as :func:`kcplan.kc.kc_volume`.
        """
        scale = 2 if accuracy == "high" else 1
        quad = orientation_quadrature(
            self.a,
            self.b,
            radial_nodes=(64 if self.n == 2 else 16) * scale,
            axis_nodes=8 * scale,
            measure=measure,
        )
        return quad.integrate(self.volume_at(quad.omega))

    def __repr__(self) -> str:
        return f"GeometricLowerBound(semi_axes={self.a.tolist()}, inflation={self.inflation})"
