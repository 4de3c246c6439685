import numpy as np
import pytest
from conftest import inflations, semi_axes
from hypothesis import given, settings
from hypothesis import strategies as st

from kcplan.geometry import (
    containment_margin,
    exp_rotation,
    first_order_margin,
    linearised_margin,
    log_rotation,
    max_affine_norm,
)


def _sphere(m: int) -> np.ndarray:
    ph, th = np.meshgrid(np.linspace(0, np.pi, m), np.linspace(0, 2 * np.pi, 2 * m))
    return np.stack([np.sin(ph) * np.cos(th), np.sin(ph) * np.sin(th), np.cos(ph)], -1).reshape(
        -1, 3
    )


CIRCLE = np.stack([np.cos(t := np.linspace(0, 2 * np.pi, 20001)), np.sin(t)], 1)
SPHERE = _sphere(300)


def _sampled_margin(a, b, xi):
    n = len(a)
    U = CIRCLE if n == 2 else SPHERE
    R = exp_rotation(xi[: n * (n - 1) // 2], n)
    pts = U * a @ R.T + xi[n * (n - 1) // 2 :]
    return np.linalg.norm(pts / b, axis=1).max()


@settings(max_examples=60)
@given(n=st.sampled_from([2, 3]), data=st.data())
def test_margin_matches_dense_boundary_sampling(n, data):
    a = data.draw(semi_axes(n))
    eps = data.draw(inflations)
    b = (1 + eps) * a
    d = 3 if n == 2 else 6
    scale = np.r_[np.full(d - n, 0.5), 0.5 * a]
    xi = np.array([data.draw(st.floats(-1, 1)) for _ in range(d)]) * scale
    exact = containment_margin(a, b, xi)
    sampled = _sampled_margin(a, b, xi)
    # The exact maximum is never below a sample, and dense samples come close to it.
    assert exact >= sampled - 1e-12
    tol = 2e-7 if n == 2 else 2e-4
    assert exact <= sampled * (1 + tol) + 1e-12


def test_hard_case_of_the_secular_equation():
    # c orthogonal to the top singular vector: the maximiser is not unique.
    M, c = np.diag([2.0, 1.0]), np.array([0.0, 0.3])
    expected = np.linalg.norm(CIRCLE @ M.T + c, axis=1).max()
    assert max_affine_norm(M, c) == pytest.approx(expected, rel=1e-9)
    # and the analytic value: lam = 4, value^2 = 4 + 4 * 0.09 / 3
    assert max_affine_norm(M, c) == pytest.approx(np.sqrt(4 + 0.12), rel=1e-12)


def test_pure_translation_has_closed_form():
    a = np.array([5.0, 3.5])
    b = 1.08 * a
    tau = np.array([0.1, -0.2])
    # b is a uniform scaling of a, so the margin is 1/1.08 + |tau / b|.
    expected = 1 / 1.08 + np.linalg.norm(tau / b)
    assert containment_margin(a, b, np.r_[0.0, tau]) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(
    ("a", "eps", "expected"), [((5, 3), 0.1, 0.17995), ((17.5, 12.5), 0.1, 0.28214)]
)
def test_extreme_rotation_matches_closed_form_and_hrm_fixture(a, eps, expected):
    a = np.array(a, float)
    b = (1 + eps) * a
    # Exact extreme rotation (see scripts/reproduce_paper.py, eq. 38 discussion).
    s = ((1 + eps) ** 2 - 1) / ((1 + eps) * (a[0] / a[1] - a[1] / a[0]))
    theta = np.arcsin(s)
    assert theta == pytest.approx(expected, abs=1e-5)  # value quoted by the HRM data's SOURCE.md
    assert containment_margin(a, b, [theta, 0, 0]) == pytest.approx(1.0, abs=1e-12)
    assert containment_margin(a, b, [theta * 1.001, 0, 0]) > 1.0


@settings(max_examples=40)
@given(
    a=semi_axes(2),
    eps=inflations,
    theta=st.floats(-1.2, 1.2),
    x=st.floats(-1, 1),
    y=st.floats(-1, 1),
)
def test_2d_margin_is_homogeneous_linearised_margin(a, eps, theta, x, y):
    # exp(hat theta) = cos(theta) I + sin(theta) J exactly in 2D, and G is 1-homogeneous.
    b = (1 + eps) * a
    tau = np.array([x, y]) * a
    exact = containment_margin(a, b, np.r_[theta, tau])
    via_g = linearised_margin(a, b, np.cos(theta), np.r_[np.sin(theta), tau])
    assert exact == pytest.approx(via_g, rel=1e-10)
    assert first_order_margin(a, b, np.r_[theta, tau]) == pytest.approx(
        linearised_margin(a, b, 1.0, np.r_[theta, tau]), rel=1e-14
    )


@pytest.mark.parametrize("n", [2, 3])
def test_vectorised_and_scalar_calls_agree(n):
    rng = np.random.default_rng(3)
    a = np.array([4.0, 2.5, 2.0][:n])
    b = 1.1 * a
    X = rng.normal(size=(50, 3 if n == 2 else 6)) * 0.2
    batch = containment_margin(a, b, X)
    single = np.array([containment_margin(a, b, x) for x in X])
    assert isinstance(containment_margin(a, b, X[0]), float)
    np.testing.assert_allclose(batch, single, rtol=1e-13)


@pytest.mark.parametrize("n", [2, 3])
def test_log_inverts_exp(n):
    rng = np.random.default_rng(4)
    w = rng.normal(size=(200, 1 if n == 2 else 3))
    w *= np.minimum(1.0, 3.0 / np.linalg.norm(w, axis=1))[:, None]
    np.testing.assert_allclose(log_rotation(exp_rotation(w, n)), w, atol=1e-9)


@pytest.mark.parametrize(
    ("a", "b", "xi", "message"),
    [
        ([5, -1], [6, 2], [0, 0, 0], "a: expected 2 or 3 positive finite numbers"),
        ([5, 1], [6, np.inf], [0, 0, 0], "b: expected 2 or 3 positive finite numbers"),
        ([5, 1], [6, 2, 1], [0, 0, 0], "b: expected 2 numbers like a"),
        ([5, 1], [6, 2], [0, 0], r"xi: expected shape \(3,\) or \(k, 3\)"),
        ([5, 1, 1, 1], [6, 2, 1, 1], [0] * 10, "a: expected 2 or 3 positive numbers"),
    ],
)
def test_bad_input_names_the_argument(a, b, xi, message):
    with pytest.raises(ValueError, match=message):
        containment_margin(a, b, xi)
