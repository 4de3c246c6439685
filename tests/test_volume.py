import numpy as np
import pytest

from kcplan.geometry import containment_margin
from kcplan.kc import ConvexLowerBound, GeometricLowerBound, kc_volume


def _monte_carlo(indicator, box, samples, seed):
    rng = np.random.default_rng(seed)
    hits = 0
    for _ in range(samples // 100_000):
        X = (rng.random((100_000, len(box))) * 2 - 1) * box
        hits += int(indicator(X).sum())
    p = hits / samples
    V = float(np.prod(2 * box))
    return p * V, V * np.sqrt(p * (1 - p) / samples)


def test_2d_kc_volume_agrees_with_monte_carlo():
    a, eps = np.array([5.0, 3.5]), 0.08
    box = np.array([0.25, 0.45, 0.35])
    mc, sd = _monte_carlo(lambda X: containment_margin(a, (1 + eps) * a, X) <= 1, box, 400_000, 0)
    v = kc_volume(a, eps)
    assert abs(v - mc) <= 4 * sd + 1e-3 * v
    # stated accuracy: 'normal' within 1e-3 of 'high' in 2D
    assert kc_volume(a, eps, accuracy="high") == pytest.approx(v, rel=1e-3)


def test_3d_kc_volume_agrees_with_monte_carlo_within_stated_accuracy():
    a, eps = np.array([4.0, 2.5, 2.0]), 0.1
    box = np.array([0.46, 0.46, 0.46, 0.4, 0.25, 0.2])
    mc, sd = _monte_carlo(lambda X: containment_margin(a, (1 + eps) * a, X) <= 1, box, 1_000_000, 1)
    v = kc_volume(a, eps)
    assert abs(v - mc) <= 4 * sd + 0.03 * v


def test_2d_geometric_volume_agrees_with_monte_carlo():
    a, eps = np.array([5.0, 3.5]), 0.08
    bound = GeometricLowerBound(a, eps)
    box = np.array([0.25, 0.45, 0.35])
    mc, sd = _monte_carlo(bound.contains, box, 400_000, 2)
    assert abs(bound.volume() - mc) <= 4 * sd + 1e-3 * mc


@pytest.mark.parametrize(("a", "eps"), [([5, 3.5], 0.08), ([5, 2], 0.2), ([4, 2.5, 2], 0.1)])
def test_bounds_are_below_the_true_volume(a, eps):
    v = kc_volume(a, eps)
    assert ConvexLowerBound(a, eps).volume() < v
    assert GeometricLowerBound(a, eps).volume() < v


def test_haar_measure_is_slightly_smaller_in_3d():
    a, eps = [4.0, 2.5, 2.0], 0.1
    exp_v = kc_volume(a, eps)
    haar_v = kc_volume(a, eps, measure="haar")
    # density 2(1 - cos t)/t^2 lies in [1 - t^2/12, 1] for the rotations involved (t < 0.5)
    assert 0.98 * exp_v < haar_v < exp_v
    with pytest.raises(ValueError, match="measure: expected one of"):
        kc_volume(a, eps, measure="lebesgue")
