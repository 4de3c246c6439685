"""The curvature measure of a part and its quantiles (kcplan.cover.features): exact on a
box, free of the triangulation, and the cover of a part made two ways alike (issue 41)."""

import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from kcplan.cover import fit_cover, read_solid, union_volume
from kcplan.cover.features import clip_segments, feature_segments, quantiles_along
from kcplan.cover.profiles import PROFILES

LEVELS = (0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875)


def _solid(mesh: trimesh.Trimesh, path):
    mesh.export(path)
    return read_solid(path)


def test_a_unit_box_puts_a_third_of_its_curvature_on_each_end_and_a_third_between(tmp_path):
    """Along x, the box's 12 right-angled edges of length 1: the 4 on x = 0 and the 4 on
    x = 1 are steps of a third each, the 4 along x a third spread evenly."""
    box = trimesh.creation.box((1, 1, 1))
    box.apply_translation((0.5, 0.5, 0.5))
    segments, weights = feature_segments(_solid(box, tmp_path / "box.stl"))
    total = (weights * np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1)).sum()
    assert math.isclose(total, 12 * math.pi / 2, rel_tol=1e-12)
    x = quantiles_along(segments, np.array([1.0, 0.0, 0.0]), LEVELS, weights)
    # 1/8 and 1/4 in the step at 0; 3/8 -> 1/8 of the way; 1/2 -> the middle; ...
    np.testing.assert_allclose(x, [0.0, 0.0, 0.125, 0.5, 0.875, 1.0, 1.0], atol=1e-9)


def test_a_triangles_area_spreads_as_a_tent():
    """A right triangle (0,0), (1,0), (0,1) in the plane z = 0: the area below x = t is
    (1 - (1 - t)^2) / 2, so the median is 1 - sqrt(1/2)."""
    T = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float)
    x = quantiles_along(T, np.array([1.0, 0, 0]), [0.5])
    assert math.isclose(x[0], 1 - math.sqrt(0.5), abs_tol=1e-9)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from(["u_channel", "t_profile", "ring"]))
def test_splitting_triangles_moves_no_quantile(seed, name):
    """A triangle split at an inside point into three, and an edge split at its middle,
    keep both measures' quantiles along a random direction (the vertex quantiles the fit
    used before move)."""
    rng = np.random.default_rng(seed)
    mesh = PROFILES[name]()
    split = trimesh.Trimesh(*trimesh.remesh.subdivide(mesh.vertices, mesh.faces), process=False)
    V, F = [*split.vertices], [*split.faces]
    for f in rng.choice(len(F), size=len(F) // 3, replace=False):  # a point inside
        a, b, c = F[f]
        w = rng.dirichlet((1, 1, 1))
        V.append(w @ np.array([V[a], V[b], V[c]]))
        F[f] = [a, b, len(V) - 1]
        F += [[b, c, len(V) - 1], [c, a, len(V) - 1]]
    split = trimesh.Trimesh(np.array(V), np.array(F), process=False)
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    for m in (mesh, split):
        assert m.is_watertight
    area = [quantiles_along(m.vertices[m.faces], direction, LEVELS) for m in (mesh, split)]
    np.testing.assert_allclose(area[0], area[1], atol=1e-9)

    class Part:  # what feature_segments reads of a Solid
        dimension = 3

        def __init__(self, m):
            self.vertices, self.faces = m.vertices, m.faces

    curvature = [
        quantiles_along(*_pair(feature_segments(Part(m)), direction)) for m in (mesh, split)
    ]
    np.testing.assert_allclose(curvature[0], curvature[1], atol=1e-7)


def _pair(features, direction):
    segments, weights = features
    measures = weights * np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1)
    return segments, direction, LEVELS, measures


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from([2, 3]))
def test_clipped_segments_keep_their_measure_on_the_two_sides_of_a_plane(seed, n):
    rng = np.random.default_rng(seed)
    segments = rng.normal(size=(40, 2, n))
    segments[::5, 1] = segments[::5, 0]  # points
    weights = rng.uniform(0.1, 2.0, size=40)
    normal = rng.normal(size=n)
    offset = float(rng.normal())
    if seed % 3 == 0:  # corners exactly on the plane
        segments[:, 0] -= np.outer(segments[:, 0] @ normal - offset, normal) / (normal @ normal)
    below = clip_segments(segments, weights, np.append(normal, -offset)[None])
    above = clip_segments(segments, weights, np.append(-normal, offset)[None])
    length = np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1)
    total = np.where(length > 0, weights * length, 0.0).sum()
    on_plane = np.abs(segments[:, 0] @ normal - offset) < 1e-12
    points = (length == 0) & ~on_plane
    both = sum(m[np.linalg.norm(s[:, 1] - s[:, 0], axis=1) > 0].sum() for s, m in (below, above))
    assert math.isclose(both, total, rel_tol=1e-9)
    assert math.isclose(
        sum(m[np.linalg.norm(s[:, 1] - s[:, 0], axis=1) == 0].sum() for s, m in (below, above)),
        weights[points].sum() + 2 * weights[(length == 0) & on_plane].sum(),
        rel_tol=1e-9,
        abs_tol=1e-9,  # a segment that only touches the plane leaves a point of measure 0
    )
    assert (below[0].reshape(-1, n) @ normal <= offset + 1e-9).all()
    assert (above[0].reshape(-1, n) @ normal >= offset - 1e-9).all()


def test_the_u_channel_is_covered_alike_whatever_its_triangulation(tmp_path):
    """Issue 41: the union of three boxes got 3.48 times its volume from 4 bodies when
    cuts sat at quantiles of its vertices, the grid's faces 2.38. Both at most 2.5 now,
    held with three standard errors to spare."""
    grid, union = PROFILES["u_channel"](), PROFILES["u_channel_union"]()
    assert math.isclose(grid.volume, union.volume, rel_tol=1e-6)  # manifold3d: float32
    assert len(grid.faces) != len(union.faces)  # not the same triangles
    ratios = []
    for name, mesh in (("grid", grid), ("union", union)):
        solid = _solid(mesh, tmp_path / f"{name}.stl")
        cover = fit_cover(solid, bodies=4)
        volume, error = union_volume(cover.bodies, 200_000)
        assert (volume + 3 * error) / solid.volume <= 2.5, name
        ratios.append(volume / solid.volume)
    assert ratios[0] == pytest.approx(ratios[1], rel=0.02)


@pytest.mark.study  # a slow study: .ci/run runs it (pytest -m study)
def test_the_vertices_trees_make_the_ur5_upper_arm_tighter_and_never_looser(monkeypatch):
    """Issue 41, "no mesh worse": cuts at the curvature's quantiles alone left the UR5's
    upper arm at 1.511 times its volume from 4 bodies, where the vertices' quantiles had
    1.456. With the vertices' trees grown beside the curvature's (`VERTEX_CUTS`), the
    cover is the smaller of the two, here beyond three standard errors, and sound."""
    from kcplan.arm.examples import example_folder
    from kcplan.arm.model import ArmError
    from kcplan.cover import fit as cover_fit

    try:
        mesh = example_folder() / "ur_description" / "meshes" / "ur5" / "collision"
    except ArmError:
        pytest.skip("example-robot-data not installed")
    solid = read_solid(mesh / "upperarm.stl")
    ratios = {}
    for vertex_cuts in (False, True):
        monkeypatch.setattr(cover_fit, "VERTEX_CUTS", vertex_cuts)
        cover = fit_cover(solid, bodies=4)
        assert cover.worst <= 1.0
        assert cover_fit.check_cover(solid, cover.tree, cover.bodies) <= 1.0
        volume, error = union_volume(cover.bodies, 200_000)
        ratios[vertex_cuts] = (volume / solid.volume, error / solid.volume)
    (alone, e0), (both, e1) = ratios[False], ratios[True]
    assert alone == pytest.approx(1.511, abs=0.02)
    assert both + 3 * e1 < alone - 3 * e0
    assert both == pytest.approx(1.456, abs=0.02)
