import numpy as np
import pytest
from conftest import inflations, semi_axes
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

from kcplan.geometry import containment_margin, radial_extent
from kcplan.kc import GeometricLowerBound


def _rotations(n, k, scale, rng):
    return rng.normal(size=(k, 1 if n == 2 else 3)) * scale


@settings(max_examples=40)
@given(n=st.sampled_from([2, 3]), data=st.data(), seed=st.integers(0, 2**32 - 1))
def test_eq19_vertices_lie_on_the_exact_boundary(n, data, seed):
    # The closed form d_i* (eq. 19, critical radius eq. 28) equals the exact radial
    # function of the Minkowski difference: every vertex has exact margin 1.
    a = data.draw(semi_axes(n))
    eps = data.draw(inflations)
    bound = GeometricLowerBound(a, eps)
    rng = np.random.default_rng(seed)
    for omega in _rotations(n, 5, 0.3 * eps, rng):
        d = bound.extreme_distances(omega)
        if np.any(d == 0):
            continue
        V = bound.vertices_at(omega)
        xi = np.hstack([np.tile(omega, (len(V), 1)), V])
        np.testing.assert_allclose(containment_margin(a, (1 + eps) * a, xi), 1.0, atol=1e-9)
        L = np.linalg.norm(V, axis=1)
        rho = radial_extent(a, (1 + eps) * a, omega[None], V / L[:, None])[0]
        np.testing.assert_allclose(rho, L, rtol=1e-9)


@settings(max_examples=40)
@given(n=st.sampled_from([2, 3]), data=st.data(), seed=st.integers(0, 2**32 - 1))
def test_points_inside_are_exact_containments(n, data, seed):
    a = data.draw(semi_axes(n))
    eps = data.draw(inflations)
    bound = GeometricLowerBound(a, eps)
    rng = np.random.default_rng(seed)
    k = 400
    omega = _rotations(n, k, 0.5 * eps, rng)
    tau = rng.normal(size=(k, n)) * eps * a
    xi = np.hstack([omega, tau])
    inside = bound.contains(xi)
    if inside.any():
        assert containment_margin(a, (1 + eps) * a, xi[inside]).max() <= 1 + 1e-9


def test_cross_polytope_volume_formula():
    bound = GeometricLowerBound([4, 2.5, 2], 0.1)
    omega = np.array([0.05, -0.02, 0.08])
    assert bound.volume_at(omega) == pytest.approx(
        ConvexHull(bound.vertices_at(omega)).volume, rel=1e-9
    )
    bound2 = GeometricLowerBound([5, 3.5], 0.08)
    assert bound2.volume_at([0.1]) == pytest.approx(
        ConvexHull(bound2.vertices_at([0.1])).volume, rel=1e-9
    )


def test_empty_beyond_the_extreme_rotation():
    bound = GeometricLowerBound([5, 3], 0.1)
    assert bound.volume_at([0.17]) > 0
    assert bound.volume_at([0.19]) == 0.0
    assert bound.contains([0.19, 0.0, 0.0]) is False
    assert bound.contains([0.0, 0.0, 0.0]) is True


def test_contains_scales_across_the_boundary():
    bound = GeometricLowerBound([5, 3.5], 0.08)
    V = bound.vertices_at([0.05])
    xi_in = np.hstack([np.full((4, 1), 0.05), 0.999 * V])
    xi_out = np.hstack([np.full((4, 1), 0.05), 1.001 * V])
    assert bound.contains(xi_in).all()
    assert not bound.contains(xi_out).any()
