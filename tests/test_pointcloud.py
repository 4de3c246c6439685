"""Point clouds and depth images as obstacles (kcplan.world.pointcloud and the scenario's
``pointcloud`` and ``depth`` kinds): every file format round-trips, depth pixels
unproject as computed by hand, the voxel filter keeps its distance guarantee, the self
filters remove exactly what is near the robot, and every malformed field is one line
with exit code 2 from ``kcplan validate``."""

import contextlib
import io
import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
import trimesh
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PIL import Image
from pypcd4 import Encoding, PointCloud
from scipy.spatial import ConvexHull, Delaunay, cKDTree
from trimesh.triangles import closest_point

from kcplan.cli import main
from kcplan.scenarios import dump_scenario, load_scenario
from kcplan.world import ScenarioError, scenario_to_dict
from kcplan.world import obstacles as obstacles_module
from kcplan.world.pointcloud import (
    CloudInfo,
    PointCloudError,
    crop_box_mask,
    crop_sphere_mask,
    drop_nonfinite,
    ellipsoid_self_filter_mask,
    hull_self_filter_mask,
    read_depth_image,
    read_point_file,
    sample_surface_points,
    unproject_depth,
    voxel_filter,
)

ROOT = Path(__file__).resolve().parents[1]
PANDA = ROOT / "scenarios" / "arm" / "panda"
POINTS = np.random.default_rng(7).uniform(-2.0, 2.0, size=(50, 3))
EIGHTHS = np.round(POINTS * 8) / 8  # exact in float32 and in 8 decimals (trimesh's PLY)


def _png16(path: Path, raw: np.ndarray) -> Path:
    Image.fromarray(np.asarray(raw, dtype=np.uint16)).save(path)
    return path


# ---------------------------------------------------------------- file formats


@pytest.mark.parametrize("encoding", ["ascii", "binary"])
def test_ply_round_trips(tmp_path, encoding):
    path = tmp_path / "c.ply"
    path.write_bytes(trimesh.PointCloud(EIGHTHS).export(file_type="ply", encoding=encoding))
    points = read_point_file(path)
    # trimesh writes PLY coordinates as float32, ASCII ones with 8 decimals
    assert points.dtype == np.float64 and points.shape == (50, 3)
    assert np.array_equal(points, EIGHTHS)


def test_a_ply_mesh_gives_every_vertex_as_written(tmp_path):
    path = tmp_path / "m.ply"
    path.write_text(
        "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 0\n5 5 5\n3 0 1 2\n"
    )  # a duplicated vertex and one no face uses: trimesh's processing would drop both
    assert read_point_file(path).tolist() == [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 0],
                                              [5, 5, 5]]  # fmt: skip


@pytest.mark.parametrize("encoding", [Encoding.ASCII, Encoding.BINARY, Encoding.BINARY_COMPRESSED])
def test_pcd_round_trips(tmp_path, encoding):
    # a grid: LZF compresses it (pypcd4 silently writes plain binary when it cannot)
    grid = np.stack(np.meshgrid(*[np.arange(8.0)] * 3, indexing="ij"), -1).reshape(-1, 3) * 0.25
    extra = np.column_stack([grid, np.arange(len(grid), dtype=float)])  # x y z intensity
    cloud = PointCloud.from_points(extra, ("x", "y", "z", "intensity"), (np.float64,) * 4)
    path = tmp_path / "c.pcd"
    cloud.save(path, encoding=encoding)
    assert f"DATA {encoding.value}\n".encode() in path.read_bytes()[:300]
    assert np.array_equal(read_point_file(path), grid)


def test_pcd_float32_and_nan(tmp_path):
    points = POINTS.copy()
    points[3] = np.nan
    path = tmp_path / "c.pcd"
    PointCloud.from_xyz_points(points).save(path, encoding=Encoding.BINARY)
    read = read_point_file(path)
    assert np.isnan(read[3]).all()
    assert np.array_equal(np.delete(read, 3, 0), np.delete(points, 3, 0).astype(np.float32))


@pytest.mark.parametrize("separator", [" ", ",", "\t", ", "])
def test_xyz_round_trips(tmp_path, separator):
    rows = [separator.join(f"{x!r}" for x in row) + f"{separator}7" for row in POINTS.tolist()]
    path = tmp_path / "c.xyz"
    path.write_text("# x y z intensity\n" + "\n".join(rows) + "\n\n")
    assert np.array_equal(read_point_file(path), POINTS)


def test_npy_round_trips(tmp_path):
    np.save(tmp_path / "a.npy", POINTS)
    np.save(tmp_path / "b.npy", np.column_stack([POINTS, np.ones(50)]).astype(np.float32))
    record = np.zeros(50, dtype=[("x", "f8"), ("y", "f8"), ("z", "f8"), ("i", "u1")])
    record["x"], record["y"], record["z"] = POINTS.T
    np.save(tmp_path / "c.npy", record)
    np.save(tmp_path / "d.npy", np.arange(12, dtype=np.int16).reshape(4, 3))
    assert np.array_equal(read_point_file(tmp_path / "a.npy"), POINTS)
    assert np.array_equal(read_point_file(tmp_path / "b.npy"), POINTS.astype(np.float32))
    assert np.array_equal(read_point_file(tmp_path / "c.npy"), POINTS)
    assert read_point_file(tmp_path / "d.npy").tolist()[1] == [3.0, 4.0, 5.0]


def _bad_files(folder: Path) -> dict:
    """Unreadable point files and the start of their message."""
    np.save(folder / "shape.npy", np.zeros((4, 2)))
    np.save(folder / "flat.npy", np.zeros(6))
    np.save(folder / "objects.npy", np.array([{"a": 1}], dtype=object), allow_pickle=True)
    np.save(folder / "strings.npy", np.array([["a", "b", "c"]]))
    (folder / "garbage.npy").write_bytes(b"\x93NUMPY garbage")
    (folder / "garbage.ply").write_text("not a ply")
    (folder / "short.ply").write_bytes(
        trimesh.PointCloud(POINTS).export(file_type="ply", encoding="binary")[:-7]
    )
    (folder / "garbage.pcd").write_text("garbage\n")
    PointCloud.from_points(POINTS, ("a", "b", "c"), (np.float32,) * 3).save(folder / "abc.pcd")
    (folder / "two.xyz").write_text("1 2\n3 4\n")
    (folder / "words.xyz").write_text("x y z\n1 2 3\n")
    (folder / "c.txt").write_text("1 2 3\n")
    return {
        "shape.npy": "expected an N x 3 array, got shape (4, 2)",
        "flat.npy": "expected an N x 3 array, got shape (6,)",
        "objects.npy": "expected a numeric array, got Python objects",
        "strings.npy": "expected an array of real numbers, got dtype <U1",
        "garbage.npy": "expected a valid NPY file, got ValueError",
        "garbage.ply": "expected a PLY file (starting with 'ply'), got 'not a ply'",
        "short.ply": "expected a valid PLY file, got ValueError: PLY is unexpected length",
        "garbage.pcd": "expected a PCD header with FIELDS, SIZE",
        "abc.pcd": "expected PCD fields x, y and z, got a b c",
        "two.xyz": "expected rows of at least 3 numbers, got invalid column index 2",
        "words.xyz": "expected rows of at least 3 numbers, got could not convert string 'x'",
        "c.txt": "expected a .ply, .pcd, .xyz or .npy file, got '.txt'",
        "missing.ply": "expected a readable file, got No such file or directory",
    }


def test_unreadable_point_files_say_why_in_one_line(tmp_path):
    for name, message in _bad_files(tmp_path).items():
        with pytest.raises(PointCloudError) as err:
            read_point_file(tmp_path / name)
        assert str(err.value).startswith(message), (name, str(err.value))
        assert "\n" not in str(err.value) and str(tmp_path) not in str(err.value)


def test_empty_files_give_no_points(tmp_path):
    (tmp_path / "e.xyz").write_text("# nothing\n")
    np.save(tmp_path / "e.npy", np.zeros((0, 3)))
    (tmp_path / "e.ply").write_text(
        "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n"
    )
    for name in ("e.xyz", "e.npy", "e.ply"):
        assert read_point_file(tmp_path / name).shape == (0, 3), name


# ---------------------------------------------------------------- depth images


def test_depth_png_is_scaled_to_metres(tmp_path):
    raw = np.array([[0, 1000, 2500], [65535, 1, 7]])
    depth = read_depth_image(_png16(tmp_path / "d.png", raw), 0.001)
    assert depth.dtype == np.float64 and np.array_equal(depth, raw * 0.001)
    assert np.array_equal(read_depth_image(tmp_path / "d.png", 0.5), raw * 0.5)


def test_depth_npy_is_in_metres(tmp_path):
    depth = np.array([[0.5, np.nan], [np.inf, 2.0]], dtype=np.float32)
    np.save(tmp_path / "d.npy", depth)
    read = read_depth_image(tmp_path / "d.npy", 123.0)  # the scale is for PNGs only
    assert np.array_equal(read, depth.astype(np.float64), equal_nan=True)


def test_bad_depth_images_name_the_problem(tmp_path):
    Image.fromarray(np.full((4, 4), 9, dtype=np.uint8)).save(tmp_path / "gray8.png")
    Image.fromarray(np.zeros((4, 4, 3), dtype=np.uint8)).save(tmp_path / "rgb.png")
    Image.fromarray(np.zeros((4, 4), dtype=np.uint16)).save(tmp_path / "tiff.png", format="TIFF")
    np.save(tmp_path / "int.npy", np.ones((4, 4), dtype=np.uint16))
    np.save(tmp_path / "cube.npy", np.ones((2, 2, 2)))
    (tmp_path / "bad.png").write_bytes(b"\x89PNG\r\n\x1a\n garbage")
    (tmp_path / "d.jpg").write_bytes(b"")
    cases = {
        "gray8.png": "expected a 16-bit grayscale PNG (mode I;16), got mode L (8-bit grayscale)",
        "rgb.png": "expected a 16-bit grayscale PNG (mode I;16), got mode RGB (8-bit colour)",
        "tiff.png": "expected a PNG image, got a TIFF image",
        "int.npy": "expected a 2-D float array of depths in metres, got shape (4, 4) of dtype",
        "cube.npy": "expected a 2-D float array of depths in metres, got shape (2, 2, 2)",
        "bad.png": "expected a valid 16-bit PNG, got OSError: Truncated File Read",
        "d.jpg": "expected a 16-bit .png or a .npy depth image, got '.jpg'",
    }
    for name, message in cases.items():
        with pytest.raises(PointCloudError) as err:
            read_depth_image(tmp_path / name, 0.001)
        assert str(err.value).startswith(message), (name, str(err.value))
        assert "\n" not in str(err.value)


def test_unprojection_of_a_plane_at_one_metre():
    depth = np.ones((3, 4))  # rows v = 0..2, columns u = 0..3
    points = unproject_depth(depth, fx=2.0, fy=4.0, cx=1.5, cy=1.0, max_range=5.0)
    expected = [
        [(u - 1.5) / 2.0, (v - 1.0) / 4.0, 1.0] for v in range(3) for u in range(4)
    ]  # row-major: x right (columns), y down (rows), z forward
    assert np.allclose(points, expected, rtol=0, atol=1e-15)
    assert points[0].tolist() == [-0.75, -0.25, 1.0] and points[-1].tolist() == [0.75, 0.25, 1.0]
    far = unproject_depth(2.0 * depth, 2.0, 4.0, 1.5, 1.0, 5.0)
    assert np.array_equal(far, 2.0 * points)  # a ray's points scale with their depth


def test_pixels_without_depth_are_skipped():
    depth = np.array([[1.0, 0.0, np.nan], [np.inf, 3.0, 3.5], [-1.0, 2.0, 3.0]])
    points = unproject_depth(depth, 1.0, 1.0, 0.0, 0.0, max_range=3.0)
    # kept: (u, v) = (0, 0) z=1, (1, 1) z=3, (1, 2) z=2, (2, 2) z=3 (exactly max_range)
    assert points.tolist() == [[0, 0, 1], [3, 3, 3], [2, 4, 2], [6, 6, 3]]


# ---------------------------------------------------------------- filters


def test_nonfinite_points_are_dropped_and_counted():
    points = POINTS[:6].copy()
    points[1, 0], points[4, 2], points[5] = np.nan, -np.inf, np.inf
    kept, dropped = drop_nonfinite(points)
    assert dropped == 3 and np.array_equal(kept, POINTS[[0, 2, 3]])
    kept, dropped = drop_nonfinite(POINTS)
    assert dropped == 0 and np.array_equal(kept, POINTS)


def test_crop_masks():
    points = np.array([[0.0, 0, 0], [1, 1, 1], [1.0001, 0, 0], [-1, -1, -1], [0.5, 0.5, 0.5]])
    box = crop_box_mask(points, [-1, -1, -1], [1, 1, 1])
    ball = crop_sphere_mask(points, [0, 0, 0], 1.0)
    assert box.tolist() == [True, True, False, True, True]
    assert ball.tolist() == [True, False, False, False, True]


@st.composite
def clouds(draw):
    """Random clouds: spread, clustered, with duplicates, at an offset and a scale."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    n = draw(st.integers(1, 400))
    scale = 10.0 ** draw(st.floats(-3, 3))
    offset = 10.0 ** draw(st.floats(-3, 4)) * rng.normal(size=3)
    kind = draw(st.sampled_from(["uniform", "clusters", "duplicates", "plane"]))
    points = rng.uniform(-1, 1, size=(n, 3))
    if kind == "clusters":
        points = rng.normal(size=(4, 3))[rng.integers(0, 4, n)] + 0.01 * rng.normal(size=(n, 3))
    elif kind == "duplicates":
        points = points[rng.integers(0, max(1, n // 3), n)]
    elif kind == "plane":
        points[:, 2] = 0.0
    spacing = scale * 10.0 ** draw(st.floats(-2.5, 0.5))
    return offset + scale * points, spacing


@settings(max_examples=150, deadline=None)
@given(clouds())
def test_voxel_filter_keeps_every_point_within_spacing(case):
    points, spacing = case
    kept = voxel_filter(points, spacing)
    assert kept.dtype == np.float64 and kept.flags.c_contiguous and 1 <= len(kept) <= len(points)
    distance, _ = cKDTree(kept).query(points)
    assert distance.max() <= spacing, (distance.max(), spacing)
    # the kept points are input points, in input order, none twice
    index = {tuple(p): i for i, p in reversed(list(enumerate(points.tolist())))}
    order = [index[tuple(p)] for p in kept.tolist()]
    assert order == sorted(set(order))


def test_voxel_filter_thins_and_keeps_originals():
    rng = np.random.default_rng(3)
    points = rng.uniform(0, 1, size=(20_000, 3))
    kept = voxel_filter(points, 0.1)
    # cells of side 0.1 / sqrt(3): about 1 / 0.0577^3 = 5,200 in the unit cube
    assert 4_000 < len(kept) < 6_500
    assert cKDTree(kept).query(points)[0].max() <= 0.1
    assert np.isin(kept.view([("", float)] * 3), points.view([("", float)] * 3)).all()
    assert voxel_filter(points[:1], 0.1).tolist() == points[:1].tolist()
    with pytest.raises(ValueError, match="positive spacing"):
        voxel_filter(points, 0.0)


def _triangle_distances(points: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Brute force: each point's distance to the nearest of all triangles."""
    n, t = len(points), len(corners)
    closest = closest_point(np.tile(corners, (n, 1, 1)), np.repeat(points, t, axis=0))
    gaps = np.linalg.norm(np.repeat(points, t, axis=0) - closest, axis=1)
    return gaps.reshape(n, t).min(axis=1)


@st.composite
def hulls_and_points(draw):
    """A few convex hulls (some flat), points around them and a padding."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    scale = 10.0 ** draw(st.floats(-2, 2))
    hulls, distances = [], []
    centres = []
    for _ in range(draw(st.integers(1, 3))):
        centre = scale * rng.normal(size=3)
        local = rng.normal(size=(draw(st.integers(4, 25)), 3)) * rng.uniform(0.2, 1, size=3)
        if draw(st.integers(0, 4)) == 0:  # flat: a polygon in a tilted plane
            local[:, 2] = 0.0
            outline = ConvexHull(local[:, :2]).vertices
            fan = zip(outline[1:-1], outline[2:], strict=True)
            triangles = np.array([[outline[0], a, b] for a, b in fan])
        else:
            triangles = ConvexHull(local).simplices  # not oriented
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        vertices = centre + scale * local @ q.T
        hulls.append((vertices, triangles))
        centres.append(centre)
    points = np.concatenate(
        [c + 1.6 * scale * rng.normal(size=(150, 3)) for c in centres]
    )
    for vertices, triangles in hulls:
        d = _triangle_distances(points, vertices[triangles])
        flat = np.ptp(vertices @ np.linalg.svd(vertices - vertices.mean(0))[2][2]) < 1e-9 * scale
        if not flat:
            d[Delaunay(vertices).find_simplex(points) >= 0] = 0.0
        distances.append(d)
    padding = scale * draw(st.sampled_from([0.0, 0.01, 0.1, 0.3, 1.0]))
    return points, hulls, np.min(distances, axis=0), padding


@settings(max_examples=60, deadline=None)
@given(hulls_and_points())
def test_hull_self_filter_matches_brute_force_distances(case):
    points, hulls, distance, padding = case
    removed = hull_self_filter_mask(points, hulls, padding)
    assert removed.shape == (len(points),) and removed.dtype == bool
    assert (distance[removed] <= padding * (1 + 1e-9) + 1e-12).all()  # never a farther point
    assert removed[distance <= padding * (1 - 1e-9)].all()  # every point within padding


def test_hull_self_filter_on_a_box():
    box = trimesh.creation.box(extents=[2.0, 2.0, 2.0])  # |x|, |y|, |z| <= 1
    points = np.array([
        [0.0, 0, 0], [1.05, 0, 0], [1.11, 0, 0], [1.07, 1.07, 0], [1.08, 1.08, 0],
        [1.05, 1.05, 1.05], [1.06, 1.06, 1.06], [5, 5, 5],
    ])  # fmt: skip
    # distances 0, 0.05, 0.11, 0.099, 0.113, 0.0866, 0.104, 6.9
    mask = hull_self_filter_mask(points, [(box.vertices, box.faces)], 0.1)
    assert mask.tolist() == [True, True, False, True, False, True, False, False]
    assert not hull_self_filter_mask(points, [], 0.1).any()


def test_hull_self_filter_on_a_flat_square():
    """A flat hull (a square in z = 0, triangulated on one side) has no inside: points
    in its plane are at their distance to the square, points off it at their height."""
    square = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    points = np.array([
        [0.5, 0.5, 0.0], [0.5, 0.5, 0.05], [0.5, 0.5, -0.2], [1.05, 0.5, 0.0],
        [1.5, 0.5, 0.0], [1.06, 1.06, 0.0], [1.08, 1.08, 0.0], [-0.06, 0.5, 0.07],
    ])  # fmt: skip
    # distances 0, 0.05, 0.2, 0.05, 0.5, 0.085, 0.113, 0.092
    mask = hull_self_filter_mask(points, [(square, [[0, 1, 2], [0, 2, 3]])], 0.1)
    assert mask.tolist() == [True, True, False, True, False, True, False, True]


def _ellipsoid_distance(local: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """Distance from points (in the ellipsoid's frame) to the solid ellipsoid, by
    bisection on the Lagrange multiplier of the nearest point ``a^2 y / (a^2 + t)``."""
    outside = np.square(local / axes).sum(axis=1) > 1.0
    lo = np.zeros(len(local))
    hi = axes.max() * np.linalg.norm(local, axis=1) + 1.0
    for _ in range(200):
        t = 0.5 * (lo + hi)
        f = np.square(axes * local / (axes**2 + t[:, None])).sum(axis=1) - 1.0
        lo, hi = np.where(f > 0, t, lo), np.where(f > 0, hi, t)
    nearest = axes**2 * local / (axes**2 + hi[:, None])
    return np.where(outside, np.linalg.norm(local - nearest, axis=1), 0.0)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 3), st.floats(0.0, 2.0))
def test_ellipsoid_self_filter_removes_only_points_within_padding(seed, k, padding):
    rng = np.random.default_rng(seed)
    centres = rng.normal(size=(k, 3)) * 3
    rotations = np.array([np.linalg.qr(rng.normal(size=(3, 3)))[0] for _ in range(k)])
    axes = rng.uniform(0.1, 2.0, size=(k, 3))
    points = np.concatenate([c + 2.5 * rng.normal(size=(300, 3)) for c in centres])
    removed = ellipsoid_self_filter_mask(points, centres, rotations, axes, padding)
    ellipsoids = zip(centres, rotations, axes, strict=True)
    distance = np.min([_ellipsoid_distance((points - c) @ R, a) for c, R, a in ellipsoids], axis=0)
    assert (distance[removed] <= padding * (1 + 1e-9) + 1e-12).all()
    assert removed[distance == 0.0].all()
    # along an axis the grown ellipsoid reaches exactly padding beyond the surface
    tip = centres[0] + rotations[0][:, 1] * (0.999 * (axes[0, 1] + padding))
    assert ellipsoid_self_filter_mask(tip[None], centres[:1], rotations[:1], axes[:1], padding)[0]


def test_surface_samples_lie_on_the_mesh_and_repeat_with_the_seed():
    box = trimesh.creation.box(extents=[2.0, 4.0, 6.0])
    points = sample_surface_points(box.vertices, box.faces, 10_000, seed=5)
    assert points.shape == (10_000, 3)
    on_face = np.isclose(np.abs(points), [1.0, 2.0, 3.0]).any(axis=1)
    assert on_face.all() and (np.abs(points) <= [1 + 1e-12, 2 + 1e-12, 3 + 1e-12]).all()
    again = sample_surface_points(box.vertices, box.faces, 10_000, seed=5)
    assert np.array_equal(points, again)
    # by area: the two 4 x 6 faces (x = +-1) hold 48 / 88 of the points
    share = np.isclose(np.abs(points[:, 0]), 1.0).mean()
    assert abs(share - 48 / 88) < 0.02


def test_cloud_summary():
    info = CloudInfo(
        source="scan.ply", points_read=120_000, nonfinite=3, cropped=0, filtered=39_997,
        point_radius=0.0025, spacing=0.01, radius=0.0125, read_seconds=0.1,
        filter_seconds=0.2,
    )  # fmt: skip
    assert info.kept == 80_000
    assert info.summary() == (
        "scan.ply: 120,000 points read, 3 non-finite dropped, 80,000 kept after a 0.01 "
        "voxel filter (planned with radius 0.0125 = point radius 0.0025 + spacing 0.01)"
    )
    plain = CloudInfo(
        source="inline", points_read=2, nonfinite=0, cropped=1, filtered=0, self_filtered=0,
        point_radius=0.5, spacing=0.0, radius=0.5, read_seconds=0.0, filter_seconds=0.0,
    )  # fmt: skip
    assert plain.summary() == (
        "inline: 2 points read, 1 cropped, 1 kept (planned with radius 0.5, the point radius)"
    )


# ---------------------------------------------------------------- scenarios

QUARTER_TURN = [0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)]  # about z


def _rigid(folder: Path, obstacles: list, name: str = "s.yaml") -> Path:
    """A small rigid 3D scenario (in the style of scenarios/3d/open_space.yaml)."""
    data = {
        "name": "clouds",
        "description": "sensed obstacles",
        "dimension": 3,
        "bounds": {"low": [0, 0, 0], "high": [10, 10, 5]},
        "robot": {"semi_axes": [0.4, 0.25, 0.2], "inflation": 0.1},
        "start": {"position": [1.0, 1.0, 2.5], "quaternion": [0.0, 0.0, 0.0, 1.0]},
        "goal": {"position": [9.0, 9.0, 2.5], "quaternion": [0.0, 0.0, 0.0, 1.0]},
        "obstacles": [{"sphere": {"center": [5, 5, 1], "radius": 0.5}}, *obstacles],
    }
    path = folder / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _depth_png(folder: Path) -> Path:
    raw = np.full((4, 6), 1000)  # 1 m
    raw[0, 0] = 0  # no return
    raw[3, 5] = 5000  # 5 m: beyond max_range
    raw[2, 1] = 2000
    return _png16(folder / "d.png", raw)


def test_pointcloud_and_depth_obstacles_are_read(tmp_path):
    (tmp_path / "scans").mkdir()
    local = np.array([[1.0, 0, 0], [0, 2, 0], [np.nan, 0, 0], [1.01, 0.0, 0.0], [0, 0, 30]])
    np.save(tmp_path / "scans" / "c.npy", local)
    _depth_png(tmp_path)
    path = _rigid(tmp_path, [
        {"pointcloud": {"file": "scans/c.npy", "point_radius": 0.05, "position": [5, 5, 2],
                        "quaternion": QUARTER_TURN, "spacing": 0.1,
                        "crop": {"min": [0, 0, 0], "max": [10, 10, 5]}, "self_filter": 0.02}},
        {"pointcloud": {"points": [[1, 2, 3], [4, 5, 4.5]], "point_radius": 0.1}},
        {"depth": {"image": "d.png", "intrinsics": {"fx": 2.0, "fy": 4.0, "cx": 2.5, "cy": 1.5},
                   "max_range": 3.0, "point_radius": 0.01, "position": [2, 8, 1]}},
    ])  # fmt: skip
    scenario = load_scenario(path, check=False)
    cloud, inline, depth = scenario.obstacles[1:]
    # the quarter turn takes local x to world y, local y to world -x
    assert cloud.kind == "pointcloud" and cloud.triangles is None
    assert np.allclose(cloud.vertices, [[5, 6, 2], [3, 5, 2]], rtol=0, atol=1e-12)
    assert cloud.vertices.dtype == np.float64 and cloud.vertices.flags.c_contiguous
    assert cloud.center.tolist() == [5, 5, 2]
    assert cloud.extents.tolist() == pytest.approx([0.15] * 3)
    assert cloud.rotation == pytest.approx(np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]]))
    info = cloud.cloud
    assert (info.source, info.points_read, info.nonfinite, info.cropped, info.filtered) == (
        "scans/c.npy", 5, 1, 1, 1)  # fmt: skip
    assert (info.spacing, info.self_filter, info.kept) == (0.1, 0.02, 2)
    assert info.radius == 0.05 + 0.1 and info.point_radius == 0.05
    assert info.summary().startswith("scans/c.npy: 5 points read, 1 non-finite dropped, 1 cropped")
    assert inline.vertices.tolist() == [[1, 2, 3], [4, 5, 4.5]] and inline.cloud.source == "inline"
    assert inline.extents.tolist() == [0.1] * 3 and inline.cloud.self_filter is None
    expected = [
        [2 + (u - 2.5) * z / 2.0, 8 + (v - 1.5) * z / 4.0, 1 + z]
        for v in range(4) for u in range(6)
        if (u, v) not in ((0, 0), (5, 3))
        for z in [2.0 if (u, v) == (1, 2) else 1.0]
    ]  # fmt: skip
    assert depth.kind == "depth" and np.allclose(depth.vertices, expected, rtol=0, atol=1e-12)
    assert depth.cloud.source == "d.png (6x4 depth image)" and depth.cloud.points_read == 22
    assert depth.extents.tolist() == [0.01] * 3 and depth.center.tolist() == [2, 8, 1]


def test_a_scenario_with_clouds_round_trips(tmp_path):
    np.save(tmp_path / "c.npy", POINTS + 5.0)
    _depth_png(tmp_path)
    path = _rigid(tmp_path, [
        {"pointcloud": {"file": "c.npy", "point_radius": 0.05, "spacing": 0.5,
                        "crop": {"center": [5, 5, 5], "radius": 2.0}}},
        {"depth": {"image": "d.png", "intrinsics": {"fx": 2, "fy": 2, "cx": 3, "cy": 2},
                   "max_range": 3, "depth_scale": 0.002, "point_radius": 0.01}},
    ])  # fmt: skip
    scenario = load_scenario(path, check=False)
    data = scenario_to_dict(scenario)
    assert data["obstacles"][1] == {"pointcloud": yaml.safe_load(path.read_text())["obstacles"][1]
                                    ["pointcloud"]}  # fmt: skip
    copy = tmp_path / "copy.yaml"  # the same folder: file paths stay relative to it
    dump_scenario(data, copy)
    again = load_scenario(copy, check=False)
    assert scenario_to_dict(again) == data
    for a, b in zip(scenario.obstacles, again.obstacles, strict=True):
        assert np.array_equal(a.vertices, b.vertices) if a.vertices is not None else True
    assert again.obstacles[2].vertices[:, 2].max() == pytest.approx(2.0)  # 1000 x 0.002 m


def test_validate_checks_the_start_against_the_points(tmp_path, capsys):
    np.save(tmp_path / "c.npy", POINTS * 0.2)  # within 0.4 of the position
    free = _rigid(tmp_path, [{"pointcloud": {"file": "c.npy", "point_radius": 0.05,
                                             "position": [5, 8, 2.5]}}])  # fmt: skip
    assert main(["validate", str(free)]) == 0
    assert "clouds, 3D, 2 obstacles" in capsys.readouterr().out
    hit = _rigid(tmp_path, [{"pointcloud": {"file": "c.npy", "point_radius": 0.05,
                                            "position": [1, 1, 2.5]}}], "hit.yaml")  # fmt: skip
    assert main(["validate", str(hit)]) == 2
    assert f"INVALID {hit}: start: the robot collides with obstacles[1] (pointcloud)" in (
        capsys.readouterr().out
    )


def test_an_arm_scenario_reads_clouds(tmp_path):
    data = yaml.safe_load((ROOT / "scenarios" / "arm" / "box_1.yaml").read_text())
    data["robot"]["urdf"] = str(PANDA / "panda.urdf")
    data["robot"]["srdf"] = str(PANDA / "panda.srdf")
    (tmp_path / "scans").mkdir()
    np.save(tmp_path / "scans" / "shelf.npy", POINTS * 0.1)
    _depth_png(tmp_path / "scans")
    data["obstacles"] += [
        {"pointcloud": {"file": "scans/shelf.npy", "point_radius": 0.005, "spacing": 0.01,
                        "position": [0.5, 0.0, 0.4], "self_filter": 0.005}},
        {"depth": {"image": "scans/d.png", "intrinsics": {"fx": 5, "fy": 5, "cx": 3, "cy": 2},
                   "max_range": 2.0, "point_radius": 0.01, "position": [1.5, 0, 1],
                   "quaternion": [0.5, -0.5, 0.5, -0.5]}},
    ]  # fmt: skip
    path = tmp_path / "arm.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    scenario = load_scenario(path, check=False)
    cloud, depth = scenario.obstacles[-2:]
    assert cloud.kind == "pointcloud" and depth.kind == "depth"
    assert cloud.vertices == pytest.approx(POINTS * 0.1 + [0.5, 0.0, 0.4])  # none closer than 0.01
    assert cloud.extents.tolist() == pytest.approx([0.015] * 3) and cloud.cloud.self_filter == 0.005
    assert len(depth.vertices) == 22
    dumped = tmp_path / "again.yaml"
    dump_scenario(scenario, dumped)
    again = load_scenario(dumped, check=False)
    assert np.array_equal(again.obstacles[-2].vertices, cloud.vertices)


@pytest.mark.parametrize("kind", ["pointcloud", "depth"])
def test_a_2d_scenario_refuses_clouds(tmp_path, kind):
    data = {
        "name": "flat", "dimension": 2, "bounds": {"low": [0, 0], "high": [10, 10]},
        "robot": {"semi_axes": [1, 0.5]}, "start": {"position": [1, 1]},
        "goal": {"position": [9, 9]}, "obstacles": [{kind: {"points": [[1, 2, 3]]}}],
    }  # fmt: skip
    path = tmp_path / "flat.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ScenarioError) as err:
        load_scenario(path)
    assert str(err.value) == (
        f"{path}: obstacles[0]: unknown obstacle type {kind!r} ({kind!r} is a 3D obstacle); "
        "expected one of box, ellipse, circle, polygon in 2D"
    )


def test_too_many_points_are_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(obstacles_module, "MAX_CLOUD_POINTS", 20)
    np.save(tmp_path / "c.npy", POINTS)
    path = _rigid(tmp_path, [{"pointcloud": {"file": "c.npy", "point_radius": 0.1}}])
    with pytest.raises(ScenarioError) as err:
        load_scenario(path, check=False)
    assert str(err.value) == (
        f"{path}: obstacles[1].pointcloud.file: expected at most 20 points after cropping "
        "and filtering, got 50 (a larger spacing thins the cloud)"
    )
    thinned = _rigid(tmp_path, [{"pointcloud": {"file": "c.npy", "point_radius": 0.1,
                                                "spacing": 5.0}}], "thin.yaml")  # fmt: skip
    assert len(load_scenario(thinned, check=False).obstacles[1].vertices) <= 20


# ---------------------------------------------------------------- malformed fields

GOOD = {
    "pointcloud": {"file": "good.npy", "point_radius": 0.05, "position": [5, 5, 2]},
    "depth": {"image": "d.png", "intrinsics": {"fx": 2, "fy": 2, "cx": 3, "cy": 2},
              "max_range": 3, "point_radius": 0.01, "position": [2, 8, 1]},
}  # fmt: skip
NOT_NUMBERS = ["x", True, None, [], {}, [1.0], float("nan"), float("inf")]
NOT_POSITIVE = [*NOT_NUMBERS, 0, -1, -0.5, 1e300]
NOT_VECTORS = ["x", 1, None, [1, 2], [1, 2, 3, 4], [float("nan"), 0, 0], [True, 0, 0], {}]
CROPS = [
    [],
    "box",
    {"min": [0, 0, 0]},
    {"min": [1, 1, 1], "max": [0, 0, 0]},
    {"center": [0, 0, 0], "radius": -1},
    {"center": [0, 0, 0], "radius": 1, "min": [0, 0, 0]},
    {"min": [100, 100, 100], "max": [101, 101, 101]},  # keeps no point
    {"center": [0, 0, 0], "radius": 0.1},  # keeps no point
    {"side": 1},
]
COMMON = {
    "point_radius": NOT_POSITIVE + [KeyError],
    "spacing": NOT_POSITIVE,
    "self_filter": ["x", True, None, [], -1, -1e-3, float("nan"), float("-inf")],
    "position": NOT_VECTORS,
    "quaternion": [[0, 0, 0, 2], [1, 2], "q", [0, 0, 0, float("nan")]],
    "crop": CROPS,
    "colour": ["red"],
}
BAD_POINT_FILES = [
    "missing.npy", "nan.npy", "empty.npy", "shape.npy", "garbage.ply", "abc.pcd",
    "two.xyz", "c.txt", "huge.npy", "scans", 3, "", None,
]  # fmt: skip
FIELDS = {
    "pointcloud": COMMON | {
        "file": BAD_POINT_FILES,
        "points": [[], [[1, 2]], [[1, 2, float("nan")]], "x", [[1, 2, 3], [True, 1, 2]]],
    },
    "depth": COMMON | {
        "image": ["gray8.png", "rgb.png", "int.npy", "cube.npy", "zeros.png", "far.png",
                  "missing.png", "d.jpg", 3, KeyError],
        "intrinsics": [{"fx": 0, "fy": 2, "cx": 3, "cy": 2}, {"fx": 2, "fy": -1, "cx": 3, "cy": 2},
                       {"fx": 2, "fy": 2, "cx": 3}, {"fx": 2, "fy": 2, "cx": 3, "cy": "x"},
                       {"fx": 2, "fy": 2, "cx": 3, "cy": 2, "k1": 0}, [2, 2, 3, 2], KeyError],
        "max_range": NOT_POSITIVE + [KeyError],
        "depth_scale": NOT_POSITIVE,
    },
}  # fmt: skip


def _broken_folder(folder: Path) -> None:
    """The files the malformed scenarios name (and the good ones)."""
    _bad_files(folder)
    np.save(folder / "good.npy", POINTS)
    np.save(folder / "nan.npy", np.full((7, 3), np.nan))
    np.save(folder / "empty.npy", np.zeros((0, 3)))
    np.save(folder / "huge.npy", np.array([[1e12, 0, 0], [0, 0, 0]]))
    np.save(folder / "wide.npy", np.array([[1e9, 0, 0], [0, 0, 0]]))
    (folder / "scans").mkdir()
    _depth_png(folder)
    Image.fromarray(np.full((4, 4), 9, dtype=np.uint8)).save(folder / "gray8.png")
    Image.fromarray(np.zeros((4, 4, 3), dtype=np.uint8)).save(folder / "rgb.png")
    np.save(folder / "int.npy", np.ones((4, 4), dtype=np.uint16))
    np.save(folder / "cube.npy", np.ones((2, 2, 2)))
    _png16(folder / "zeros.png", np.zeros((4, 4)))
    _png16(folder / "far.png", np.full((4, 4), 9000))  # 9 m, beyond max_range
    (folder / "d.jpg").write_bytes(b"")


@pytest.fixture(scope="module")
def broken_folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("broken")
    _broken_folder(folder)
    return folder


@settings(
    max_examples=120,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_every_malformed_cloud_field_is_one_line_and_exit_2(data, broken_folder):
    kind = data.draw(st.sampled_from(sorted(FIELDS)))
    field = data.draw(st.sampled_from(sorted(FIELDS[kind])))
    value = data.draw(st.sampled_from(FIELDS[kind][field]))
    spec = dict(GOOD[kind])
    if value is KeyError:
        del spec[field]
    else:
        spec[field] = value
    if kind == "pointcloud" and field == "points":
        del spec["file"]  # points instead of the file
    elif kind == "pointcloud" and field == "file" and data.draw(st.booleans()):
        spec["points"] = [[1, 2, 3]]  # both
        spec["file"] = "good.npy"
    if field == "depth_scale" and data.draw(st.booleans()):
        spec |= {"image": "good.npy", "depth_scale": 0.001}  # a scale for an .npy image
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", dir=broken_folder, delete=False) as f:
        path = Path(f.name)
    _rigid(broken_folder, [{kind: spec}], path.name)
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["validate", str(path)])
    path.unlink()
    lines = out.getvalue().splitlines()
    assert code == 2, (spec, out.getvalue(), err.getvalue())
    assert len(lines) == 1 and len(err.getvalue().splitlines()) == 1, (spec, lines)
    assert lines[0].startswith(f"INVALID {path}: obstacles[1]"), (spec, lines)
    assert "Traceback" not in out.getvalue() + err.getvalue()


@pytest.mark.parametrize(
    "kind, changes, message",
    [
        ("pointcloud", {"file": "nan.npy"},
         "pointcloud.file: expected at least one finite point, got 7 points, all NaN or infinite"),
        ("pointcloud", {"file": "empty.npy"},
         "pointcloud.file: expected a cloud of at least one point, got an empty cloud"),
        ("pointcloud", {"file": "missing.npy"},
         "pointcloud.file: expected an existing point-cloud file (relative to the scenario), got "
         "'missing.npy', which does not exist at"),
        ("pointcloud", {"file": "shape.npy"},
         "pointcloud.file: expected an N x 3 array, got shape (4, 2)"),
        ("pointcloud", {"points": [[1, 2, 3]]},
         "pointcloud: expected exactly one of file and points, got both"),
        ("pointcloud", {"file": KeyError}, "pointcloud: expected exactly one of file and points, "
         "got neither"),
        ("pointcloud", {"point_radius": -1},
         "pointcloud.point_radius: expected a positive number, got -1"),
        ("pointcloud", {"crop": {"center": [0, 0, 0], "radius": 0.1}},
         "pointcloud.crop: expected a region that keeps at least one point, got {'center': [0, 0, "
         "0], 'radius': 0.1}, outside which all 50 points lie"),
        ("pointcloud", {"file": "wide.npy", "spacing": 1e-9},
         "pointcloud.spacing: expected a spacing of at least 8.88178e-07 for a cloud of extent "
         "1e+09, got 1e-09"),
        ("pointcloud", {"file": "huge.npy"},
         "pointcloud.file: expected coordinates of magnitude at most 1e+09, got 1e+12"),
        ("pointcloud", {"self_filter": -0.1},
         "pointcloud.self_filter: expected a padding of at least 0, got -0.1"),
        ("depth", {"image": "gray8.png"}, "depth.image: expected a 16-bit grayscale PNG (mode "
         "I;16), got mode L (8-bit grayscale)"),
        ("depth", {"image": "zeros.png"}, "depth.image: expected a pixel with a depth in (0, "
         "max_range 3], got none of its 4x4 pixels"),
        ("depth", {"intrinsics": {"fx": 0, "fy": 2, "cx": 3, "cy": 2}},
         "depth.intrinsics.fx: expected a positive number, got 0"),
        ("depth", {"image": "good.npy", "depth_scale": 0.001},
         "depth.depth_scale: only allowed with a 16-bit PNG image (a .npy image is in metres)"),
    ],
)  # fmt: skip
def test_cloud_errors_name_the_field(broken_folder, kind, changes, message):
    spec = dict(GOOD[kind])
    for key, value in changes.items():
        if value is KeyError:
            del spec[key]
        else:
            spec[key] = value
    path = _rigid(broken_folder, [{kind: spec}], f"named-{kind}.yaml")
    with pytest.raises(ScenarioError) as err:
        load_scenario(path)
    assert str(err.value).startswith(f"{path}: obstacles[1].{message}"), str(err.value)
    assert "\n" not in str(err.value)
