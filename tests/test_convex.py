import numpy as np
import pytest
from conftest import inflations, semi_axes
from hypothesis import given, settings
from hypothesis import strategies as st

from kcplan.geometry import containment_margin, first_order_margin
from kcplan.kc import ConvexLowerBound


def _points_inside(bound: ConvexLowerBound, k: int, rng) -> np.ndarray:
    """Random points of the polytope, many of them on or near its boundary."""
    V = bound.vertices
    interior = rng.dirichlet(np.full(len(V), 0.3), size=k) @ V
    # Push points out along rays to the boundary using the gauge (exact facet hits).
    rays = rng.normal(size=(k, V.shape[1])) * V.std(axis=0)
    boundary = bound.reach(rays)[:, None] * rays * (1 - 1e-12)
    # Points on edges between random vertex pairs.
    i, j = rng.integers(len(V), size=(2, k))
    t = rng.random((k, 1))
    edges = t * V[i] + (1 - t) * V[j]
    return np.vstack([interior, boundary, edges, V])


@settings(max_examples=40)
@given(a=semi_axes(2), eps=inflations, seed=st.integers(0, 2**32 - 1))
def test_2d_polytope_is_inside_the_exact_kc_set(a, eps, seed):
    bound = ConvexLowerBound(a, eps)
    X = _points_inside(bound, 3000, np.random.default_rng(seed))
    assert np.all(bound.contains(X[: -len(bound.vertices)] * (1 - 1e-9)))
    assert containment_margin(a, (1 + eps) * a, X).max() <= 1 + 1e-9


@settings(max_examples=12)
@given(a=semi_axes(3), eps=inflations, seed=st.integers(0, 2**32 - 1))
def test_3d_polytope_is_inside_the_exact_kc_set(a, eps, seed):
    bound = ConvexLowerBound(a, eps, max_nonzero=1)
    X = _points_inside(bound, 3000, np.random.default_rng(seed))
    assert containment_margin(a, (1 + eps) * a, X).max() <= 1 + 1e-9


def test_3d_default_polytope_on_the_paper_shape_is_sound():
    a = np.array([4.0, 2.5, 2.0])
    bound = ConvexLowerBound(a, 0.1)
    X = _points_inside(bound, 20000, np.random.default_rng(0))
    assert containment_margin(a, 1.1 * a, X).max() <= 1 + 1e-9


def test_paper_rule_is_not_sound_in_3d_but_the_sound_rule_is():
    # A vertex of the paper's first-order polytope (on the boundary of F) whose exact
    # margin exceeds 1 (1.016): F is not inside the KC set in 3D.
    a = np.array([10.0, 2.0, 1.0])
    eps = 0.5
    paper = ConvexLowerBound(a, eps, max_nonzero=2, sound=False)
    exact = containment_margin(a, (1 + eps) * a, paper.vertices)
    assert exact.max() > 1.0 + 1e-4
    assert first_order_margin(a, (1 + eps) * a, paper.vertices).max() <= 1.0 + 1e-9
    sound = ConvexLowerBound(a, eps, max_nonzero=2)
    assert containment_margin(a, (1 + eps) * a, sound.vertices).max() <= 1.0


@pytest.mark.parametrize(("a", "vertices"), [([5, 3.5], 18), ([4, 2.5, 2], 72)])
def test_documented_vertex_counts(a, vertices):
    bound = ConvexLowerBound(a, 0.08)
    assert bound.n_vertices == vertices
    A, c = bound.halfspaces
    np.testing.assert_allclose(np.linalg.norm(A, axis=1), 1.0, rtol=1e-12)
    assert np.all(c > 0)


def test_2d_sound_polytope_equals_the_papers():
    # In 2D the rule costs nothing: the alpha = gamma = 1 corner is the binding one.
    sound = ConvexLowerBound([5, 3.5], 0.08)
    paper = ConvexLowerBound([5, 3.5], 0.08, sound=False)
    assert sound.volume() == pytest.approx(paper.volume(), rel=1e-6)


def test_reach_is_the_gauge_of_the_polytope():
    bound = ConvexLowerBound([5, 3.5], 0.08)
    rng = np.random.default_rng(1)
    V = rng.normal(size=(500, 3)) * [0.2, 0.3, 0.3]
    lam = bound.reach(V)
    assert np.all(bound.contains(V * lam[:, None] * (1 - 1e-9)))
    assert not np.any(bound.contains(V * lam[:, None] * (1 + 1e-6)))
    assert bound.reach(np.zeros(3)) == np.inf


def test_contains_scalar_and_batch():
    bound = ConvexLowerBound([5, 3.5], 0.08)
    assert bound.contains([0.0, 0.0, 0.0]) is True
    assert bound.contains([0.0, 1.0, 0.0]) is False
    assert bound.contains(np.zeros((4, 3))).tolist() == [True] * 4


def test_translation_axis_vertices_are_eps_times_a():
    a = np.array([5.0, 3.5])
    bound = ConvexLowerBound(a, 0.08, max_nonzero=1)
    along_x = bound.vertices[np.abs(bound.vertices[:, 1]) > 0]
    # the 1e-10 safety on the level moves the vertex inwards by ~1e-9 relative
    np.testing.assert_allclose(np.sort(np.abs(along_x[:, 1])), [0.4, 0.4], rtol=1e-8)
    assert np.all(np.abs(along_x[:, 1]) < 0.4)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (([5, 0], 0.1), "semi_axes: expected 2 or 3 positive finite numbers"),
        (([5, 3], -0.1), "inflation: expected a positive finite number"),
        (([5, 3], float("nan")), "inflation: expected a positive finite number"),
        (([5, 3, 2, 1], 0.1), "semi_axes: expected 2 or 3 positive numbers"),
    ],
)
def test_bad_input(args, message):
    with pytest.raises(ValueError, match=message):
        ConvexLowerBound(*args)
