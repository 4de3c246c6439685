"""Volumes in the KC C-space: quadrature over orientations and the true KC volume (eq. 5).

Measure
-------
Volumes are integrals over KC coordinates ``xi = [omega, tau]``. With
``measure="exponential"`` (default) the rotation part is Lebesgue measure on the
exponential coordinates, ``d omega`` (``d theta`` in 2D): the measure in which a
polytope in ``xi`` has its ordinary volume, so the three volumes of
``kcplan bounds`` are comparable. ``measure="haar"`` weights 3D rotations by the
density of the Haar measure in exponential coordinates, ``2 (1 - cos t) / t^2``
with ``t = |omega|`` (1 at the identity; the SO(3) measure of the paper's eq. 37 up to
normalisation); in 2D both measures are ``d theta``. For the small rotations of a
KC set the two differ by less than ``t^2 / 12`` (0.8 % at ``t = 0.3``).

Which component
---------------
An ellipsoid is invariant under rotations by pi about its principal axes, so the
full KC set has 2 (2D) or 4 (3D, distinct semi-axes) congruent components. All
volumes here are those of the component that contains the identity, which is what
the lower bounds approximate; multiply by 2 or 4 for all of SO(n).

The identity component is taken to be star-shaped in exponential coordinates: along
each rotation direction it extends from 0 to the first angle at which ``R E_a`` no
longer fits in ``E_b`` (found by bisection on :func:`centred_margin`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.geometry.ellipsoid import as_inflation, as_semi_axes, check_pair
from kcplan.geometry.minkowski import (
    centred_margin,
    circle_directions,
    radial_extent,
    sphere_directions,
    sphere_frames,
)

__all__ = ["OrientationQuadrature", "orientation_quadrature", "kc_volume", "slice_volume"]

MEASURES = ("exponential", "haar")


@dataclass(frozen=True)
class OrientationQuadrature:
    """Nodes and weights for integrals over the identity component's orientations.

    Attributes
    ----------
    omega : ndarray, shape (k, r)
        Exponential coordinates of the nodes (radians).
    weights : ndarray, shape (k,)
        Quadrature weights in the chosen measure (rad^r).
    """

    omega: NDArray[np.float64]
    weights: NDArray[np.float64]

    def integrate(self, values: ArrayLike) -> float:
        """``sum_k w_k f(omega_k)`` for values of shape (k,)."""
        return float(np.dot(self.weights, np.asarray(values, dtype=float)))


def _rotation_limit(a: NDArray, b: NDArray, axes: NDArray, iterations: int = 60) -> NDArray:
    """First angle along each unit rotation axis at which ``R E_a`` stops fitting in ``E_b``."""
    lo = np.zeros(axes.shape[0])
    hi = np.full(axes.shape[0], np.pi)
    fits_at_pi = centred_margin(a, b, np.pi * axes) <= 1.0
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        fits = centred_margin(a, b, mid[:, None] * axes) <= 1.0
        lo, hi = np.where(fits, mid, lo), np.where(fits, hi, mid)
    return np.where(fits_at_pi & (lo > np.pi - 1e-9), np.pi, lo)


def orientation_quadrature(
    a: ArrayLike,
    b: ArrayLike,
    radial_nodes: int = 48,
    axis_nodes: int = 10,
    measure: str = "exponential",
) -> OrientationQuadrature:
    """Quadrature over the orientations at which ``R E_a`` fits in ``E_b``.

    2D: Gauss-Legendre in ``theta`` on ``[-theta_max, theta_max]`` with ``2 radial_nodes``
    nodes. 3D: for ``2 axis_nodes^2`` rotation axes (Gauss-Legendre in ``z`` times
    azimuths), Gauss-Legendre in the angle on ``[0, t_max(axis)]`` with ``radial_nodes``
    nodes and weight ``t^2`` (times the Haar density for ``measure="haar"``).
    """
    a_arr, b_arr = as_semi_axes(a, "a"), as_semi_axes(b, "b")
    if measure not in MEASURES:
        raise ValueError(f"measure: expected one of {MEASURES}, got {measure!r}")
    n = a_arr.shape[0]
    if n == 2:
        limit = _rotation_limit(a_arr, b_arr, np.array([[1.0]]))[0]
        x, w = np.polynomial.legendre.leggauss(2 * radial_nodes)
        return OrientationQuadrature((limit * x)[:, None], limit * w)
    axes, w_axes = sphere_directions(axis_nodes)
    limit = _rotation_limit(a_arr, b_arr, axes)
    x, w = np.polynomial.legendre.leggauss(radial_nodes)
    t = 0.5 * limit[:, None] * (x[None, :] + 1.0)  # (axes, nodes)
    wt = 0.5 * limit[:, None] * w[None, :] * t**2
    if measure == "haar":
        ts = np.where(t > 1e-8, t, 1.0)
        wt = wt * np.where(t > 1e-8, 2.0 * (1.0 - np.cos(ts)) / ts**2, 1.0)
    omega = (t[:, :, None] * axes[:, None, :]).reshape(-1, 3)
    weights = (wt * w_axes[:, None]).reshape(-1)
    return OrientationQuadrature(omega, weights)


def slice_volume(
    a: ArrayLike, b: ArrayLike, omega: ArrayLike, directions: int = 24
) -> NDArray[np.float64]:
    """Volume (area in 2D) of ``K(R) = E_b - R E_a`` at each orientation.

    ``K(R)`` can be very flat near the edge of the orientation range, so it is first
    mapped to a nearly round body by ``L = T V diag(d*)`` (the geometric lower bound's
    cross-polytope axes, :func:`kcplan.geometry.sphere_frames`), whose image of the unit
    cross-polytope lies inside ``K(R)``. Then ``vol K = |det L| (1/n) integral rho^n``
    over unit directions of the round body, with ``rho`` from the exact radial function
    (:func:`kcplan.geometry.radial_extent`); 2D uses ``8 directions`` equally spaced
    angles, 3D the product rule of :func:`sphere_directions` with ``directions`` z-nodes.

    Returns
    -------
    ndarray, shape (k,)
    """
    a_arr, b_arr = check_pair(a, b)
    n = a_arr.shape[0]
    dirs, w = circle_directions(8 * directions) if n == 2 else sphere_directions(directions)
    om = np.atleast_2d(np.asarray(omega, dtype=float))
    out = np.zeros(om.shape[0])
    for start in range(0, om.shape[0], 256):  # bound the (k, m, n) temporaries
        chunk = slice(start, start + 256)
        T, V, d = sphere_frames(a_arr, b_arr, om[chunk])
        L = T @ V * d[:, None, :]
        mapped = np.einsum("kij,mj->kmi", L, dirs)
        length = np.linalg.norm(mapped, axis=2)
        ok = np.all(d > 0, axis=1)
        safe = np.where(length > 0, length, 1.0)
        rho = radial_extent(a_arr, b_arr, om[chunk], mapped / safe[..., None]) / safe
        out[chunk] = np.where(ok, np.abs(np.linalg.det(L)) * ((rho**n) @ w) / n, 0.0)
    return out


def kc_volume(
    semi_axes: ArrayLike,
    inflation: float,
    measure: str = "exponential",
    accuracy: str = "normal",
) -> float:
    """Volume of the true KC C-space of ``E_a`` in ``(1 + eps) E_a`` (paper eq. 5).

    ``integral over SO(n) of vol(E_b - R E_a) dR`` over the identity component (module
    docstring), in rad^r * length^n.

    Parameters
    ----------
    semi_axes : array_like, shape (n,)
    inflation : float
    measure : {"exponential", "haar"}
    accuracy : {"normal", "high"}
        "normal": relative error below about 1e-3 for the paper's shapes (measured
        against "high" and against Monte Carlo in the tests); "high" doubles every
        node count.
    """
    a = as_semi_axes(semi_axes)
    b = (1.0 + as_inflation(inflation)) * a
    if accuracy not in ("normal", "high"):
        raise ValueError(f"accuracy: expected 'normal' or 'high', got {accuracy!r}")
    scale = 2 if accuracy == "high" else 1
    if a.shape[0] == 2:
        quad = orientation_quadrature(a, b, radial_nodes=48 * scale, measure=measure)
        return quad.integrate(slice_volume(a, b, quad.omega, directions=16 * scale))
    quad = orientation_quadrature(
        a, b, radial_nodes=10 * scale, axis_nodes=12 * scale, measure=measure
    )
    return quad.integrate(slice_volume(a, b, quad.omega, directions=6 * scale))
