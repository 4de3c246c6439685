"""Importers of public maps: superquadric bounds, HRM and Moving AI conversions."""

from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from kcplan.cli import main
from kcplan.geometry.pose import quaternion_matrix
from kcplan.maps.hrm import HRM_MAPS, _axis_angle_quaternion
from kcplan.maps.movingai import (
    free_square_sizes,
    merge_rectangles,
    narrowest_corridor,
    read_grid,
)
from kcplan.maps.superquadric import (
    bounding_polytopes,
    point_triangle_distance,
    superquadric_level,
    support_points,
    unit_normals,
)
from kcplan.planning.problem import plan
from kcplan.planning.verify import verify_path
from kcplan.scenarios import load_scenario
from kcplan.world import CollisionWorld

EXTERNAL = Path(__file__).resolve().parents[2] / "shared" / "data" / "external"
HRM = EXTERNAL / "hrm" / "resources"
MAPF = EXTERNAL / "hog2" / "maps" / "mapf"
SCEN = EXTERNAL / "hog2" / "scenarios" / "mapf" / "scen-even"
needs_hrm = pytest.mark.skipif(
    not HRM.is_dir(), reason=f"HRM maps not found at {HRM} (../shared/data/external)"
)
needs_mapf = pytest.mark.skipif(
    not MAPF.is_dir(), reason=f"Moving AI maps not found at {MAPF} (../shared/data/external)"
)
HRM_2D, HRM_3D = HRM_MAPS[2], HRM_MAPS[3]
SUITE_2D = ("ellipse_cluttered", "ellipse_maze", "superellipse_NAO_lab", "superellipse_maze2")
HRM_PROBLEMS = (
    # every 2D map with the single body: four in the suite, the others as studies
    [
        (m, 2, "single_body")
        if m in SUITE_2D
        else pytest.param(m, 2, "single_body", marks=pytest.mark.study)
        for m in HRM_2D
        if m != "superellipse_maze3"
    ]
    + [("superellipse_maze1", 2, "rabbit"), ("ellipse_sparse", 2, "S_shape")]
    + [("ellipsoid_cluttered", 3, "chair"), ("ellipsoid_maze", 3, "snake")]
    + [("ellipsoid_sparse", 3, "chair"), ("superquadrics_sparse", 3, "rabbit2")]
    + [pytest.param(f"superquadrics_{m}", 3, "rabbit", marks=pytest.mark.study)
       for m in ("narrow", "cluttered", "maze")]
    + [pytest.param("superquadrics_home", 3, "tree", marks=pytest.mark.study)]
)
"""Map and robot pairs whose start and goal are free (HRM's settings are per map, not per
robot: e.g. the rabbit's body sticks out of the arena at the start of superquadrics_sparse
in HRM's own geometry)."""
MAPF_MAPS = ["maze-32-32-2", "maze-32-32-4", "room-32-32-4", "random-32-32-10", "maze-128-128-10"]


# ---------------------------------------------------------------- superquadric bounds


@given(
    st.lists(st.floats(0.5, 50.0), min_size=2, max_size=3),
    st.floats(0.1, 1.9),
)
def test_support_points_lie_on_the_boundary_with_their_normal(axes, e):
    a = np.array(axes)
    normals = unit_normals(len(a), 64)
    points, values = support_points(normals, a, e)
    assert np.allclose(superquadric_level(points, a, e), 1.0, atol=1e-9)
    assert np.allclose((points * normals).sum(axis=1), values, rtol=1e-9)
    # the support value is the maximum of n . x over the shape (sampled boundary)
    rng = np.random.default_rng(0)
    u = rng.normal(size=(4000, len(a)))
    dense, _ = support_points(u / np.linalg.norm(u, axis=1, keepdims=True), a, e)
    assert np.all(dense @ normals.T <= values + 1e-9 * a.max())


@settings(max_examples=12)
@given(st.lists(st.floats(1.0, 60.0), min_size=2, max_size=2), st.floats(0.1, 1.5))
def test_2d_outer_polygon_contains_and_inner_polygon_is_inside(axes, e):
    _outer_polygon_contains_inner_is_inside(axes, e)


@pytest.mark.study
@given(st.lists(st.floats(1.0, 60.0), min_size=2, max_size=2), st.floats(0.1, 1.5))
def test_2d_outer_polygon_contains_and_inner_polygon_is_inside_study(axes, e):
    _outer_polygon_contains_inner_is_inside(axes, e)


def _outer_polygon_contains_inner_is_inside(axes, e):
    a = np.array(axes)
    bp = bounding_polytopes(a, e, 256)
    rng = np.random.default_rng(1)
    # points of the shape (boundary and interior) are inside the outer polygon
    u = rng.normal(size=(3000, 2))
    boundary, _ = support_points(u / np.linalg.norm(u, axis=1, keepdims=True), a, e)
    pts = np.vstack([boundary, boundary * rng.uniform(0, 1, (3000, 1))])
    edges = np.roll(bp.outer, -1, axis=0) - bp.outer
    cross = edges[None, :, 0] * (pts[:, None, 1] - bp.outer[None, :, 1]) - edges[None, :, 1] * (
        pts[:, None, 0] - bp.outer[None, :, 0]
    )
    assert np.all(cross >= -1e-9 * a.max() ** 2)
    # the inner polygon's vertices and edge points are inside the shape
    t = rng.uniform(0, 1, 20)[None, :, None]
    nxt = np.roll(bp.inner, -1, axis=0)
    mids = (bp.inner[:, None, :] * t + nxt[:, None, :] * (1 - t)).reshape(-1, 2)
    assert np.all(superquadric_level(mids, a, e) <= 1 + 1e-9)
    # the stated error: every outer vertex is within it of the shape (boundary densely
    # sampled by the superellipse's own parametrisation)
    assert bp.error < 0.01 * a.max()
    th = np.linspace(0, 2 * np.pi, 40000, endpoint=False)
    c, s = np.cos(th), np.sin(th)
    curve = np.column_stack(
        [a[0] * np.sign(c) * np.abs(c) ** e, a[1] * np.sign(s) * np.abs(s) ** e]
    )
    spacing = np.linalg.norm(np.diff(curve, axis=0), axis=1).max()
    gap = np.array([np.linalg.norm(curve - v, axis=1).min() for v in bp.outer])
    assert np.all(gap <= bp.error + spacing)


def test_3d_polytopes_bound_the_superquadric():
    a, e = np.array([70.0, 40.0, 30.0]), 0.1
    bp = bounding_polytopes(a, e, 800)
    assert np.all(superquadric_level(bp.inner, a, e) <= 1 + 1e-9)
    assert np.all(superquadric_level(bp.outer, a, e) >= 1 - 1e-9)
    # outer faces: every sampled surface point is on the inner side of every face
    rng = np.random.default_rng(2)
    u = rng.normal(size=(5000, 3))
    surface, _ = support_points(u / np.linalg.norm(u, axis=1, keepdims=True), a, e)
    P, F = bp.outer, bp.outer_faces
    n = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    offset = np.einsum("fi,fi->f", n, P[F[:, 0]])
    assert np.all(surface @ n.T <= offset + 1e-7 * a.max())
    # the error bound: no surface point is farther than it from the inner hull
    tri = bp.inner[bp.inner_faces]
    assert np.all(point_triangle_distance(surface[:500], tri) <= bp.error + 1e-9)
    assert bp.error < 0.02 * a.max()


def test_point_triangle_distance_closed_forms():
    tri = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]])
    pts = np.array([[0.2, 0.2, 3.0], [2.0, 0.0, 0.0], [-1.0, -1.0, 0.0], [0.5, 0.5, 1.0]])
    d = point_triangle_distance(pts, tri)
    assert np.allclose(d, [3.0, 1.0, np.sqrt(2.0), 1.0])


# ---------------------------------------------------------------- HRM


@needs_hrm
@pytest.mark.parametrize("name, dimension, robot", HRM_PROBLEMS)
def test_every_hrm_map_converts_and_validates(name, dimension, robot, tmp_path, capsys):
    out = tmp_path / f"{name}.yaml"
    args = ["--map", name, "--dimension", str(dimension), "--robot", robot, "-o", str(out)]
    code = main(["import", "hrm", str(HRM), *args])
    assert code == 0, capsys.readouterr().err
    assert main(["validate", str(out)]) == 0
    scenario = load_scenario(out)
    assert scenario.dimension == dimension
    assert "within" in scenario.description
    data = yaml.safe_load(out.read_text())
    obstacles = np.loadtxt(
        HRM / f"{dimension}D" / f"env_{name}_{dimension}D_obstacle.csv", delimiter=",", ndmin=2
    )
    world = CollisionWorld(scenario)
    rng = np.random.default_rng(3)
    # outer approximation: points of every true obstacle are inside the converted map's
    # obstacles (a point robot there collides)
    for row in obstacles:
        if dimension == 2:
            a, e, c, theta = row[:2], row[2], row[3:5], row[5]
            u = rng.normal(size=(60, 2))
            local, _ = support_points(u / np.linalg.norm(u, axis=1, keepdims=True), a, e)
            local *= rng.uniform(0.2, 1.0, (60, 1)) ** 0.5
            R = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
            pts = local @ R.T + c
            tiny = CollisionWorld(scenario, [1e-6, 1e-6])
            assert all(tiny.in_collision(np.array([x, y, 0.0])) for x, y in pts)
        else:
            a, e, c = row[:3], tuple(row[3:5]), row[5:8]
            u = rng.normal(size=(60, 3))
            local, _ = support_points(u / np.linalg.norm(u, axis=1, keepdims=True), a, e)
            local *= rng.uniform(0.2, 1.0, (60, 1)) ** 0.5
            R = quaternion_matrix(_axis_angle_quaternion(row[8:11], row[11]))
            tiny = CollisionWorld(scenario, [1e-6] * 3)
            unit = [0.0, 0.0, 0.0, 1.0]
            assert all(tiny.in_collision(np.array([*p, *unit])) for p in local @ R.T + c)
    assert len(robot_rows(HRM / f"{dimension}D" / f"robot_{robot}_{dimension}D.csv")) == len(
        scenario.robot
    )
    assert len(data["obstacles"]) >= len(obstacles)
    del world


@needs_hrm
def test_hrm_arena_keeps_the_robot_inside(tmp_path):
    out = tmp_path / "sparse.yaml"
    assert main(["import", "hrm", str(HRM), "--map", "ellipse_sparse", "-o", str(out)]) == 0
    scenario = load_scenario(out)
    tiny = CollisionWorld(scenario, [1e-6, 1e-6])
    a, e = np.array([50.0, 40.0]), 0.1
    rng = np.random.default_rng(4)
    pts = rng.uniform([-60, -50], [60, 50], (3000, 2))
    level = superquadric_level(pts, a, e)
    hits = np.array([tiny.in_collision(np.array([x, y, 0.0])) for x, y in pts])
    assert np.all(hits[level > 1.0])  # outside the arena is always blocked
    # and only a thin band inside it is lost (the stated error)
    assert np.mean(hits[level < 0.9]) < 0.2  # obstacles of the map itself


@needs_hrm
@pytest.mark.parametrize(
    "name, dimension, robot",
    [
        ("ellipse_maze", 2, "single_body"),
        ("superellipse_sparse", 2, "rabbit"),
        ("superquadrics_cluttered", 3, "rabbit"),
    ],
)
def test_plan_on_converted_hrm_maps(name, dimension, robot, tmp_path):
    out = tmp_path / f"{name}.yaml"
    assert (
        main(
            [
                "import",
                "hrm",
                str(HRM),
                "--map",
                name,
                "--dimension",
                str(dimension),
                "--robot",
                robot,
                "-o",
                str(out),
            ]
        )
        == 0
    )
    scenario = load_scenario(out)
    result = plan(scenario, "kc-rrtconnect", 20.0, seed=1)
    assert result.solved
    assert not verify_path(CollisionWorld(scenario), result.states).collides


def robot_rows(path):
    return np.loadtxt(path, delimiter=",", ndmin=2)


@needs_hrm
@pytest.mark.parametrize(
    "name, dimension, robot, field",
    [
        ("superquadrics_sparse", 3, "rabbit", "start"),
        ("superquadrics_home", 3, "chair", "start"),
        ("superellipse_maze3", 2, "single_body", "goal"),
    ],
)
def test_hrm_settings_in_collision_are_refused(name, dimension, robot, field, tmp_path, capsys):
    """HRM's own settings put these robots in collision (checked independently with the
    exact superquadric level in the closing note of issue 13): one line, exit 2, no file."""
    out = tmp_path / "x.yaml"
    args = ["--map", name, "--dimension", str(dimension), "--robot", robot, "-o", str(out)]
    assert main(["import", "hrm", str(HRM), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert f"{field}: the robot collides with obstacles[" in err and "\n" not in err
    assert not out.exists()


@needs_hrm
def test_hrm_import_errors(tmp_path, capsys):
    out = str(tmp_path / "x.yaml")
    assert main(["import", "hrm", str(HRM), "--map", "cluttered", "-o", out]) == 2
    err = capsys.readouterr().err
    assert "ambiguous" in err and "ellipse_cluttered" in err and len(err.strip().splitlines()) == 1
    assert main(["import", "hrm", str(tmp_path), "--map", "maze", "-o", out]) == 2
    assert "unknown map" in capsys.readouterr().err
    assert (
        main(["import", "hrm", str(HRM), "--map", "ellipse_maze", "--robot", "cat", "-o", out]) == 2
    )
    err = capsys.readouterr().err
    assert "--robot: unknown robot 'cat' for dimension 2; expected one of NAO_silhouette" in err
    assert not Path(out).exists()


# ---------------------------------------------------------------- Moving AI


def test_rectangles_tile_exactly_the_blocked_cells():
    rng = np.random.default_rng(5)
    for _ in range(30):
        grid = rng.random((int(rng.integers(1, 20)), int(rng.integers(1, 20)))) < 0.4
        cover = np.zeros(grid.shape, dtype=int)
        for r, c, h, w in merge_rectangles(grid):
            cover[r : r + h, c : c + w] += 1
        assert np.array_equal(cover, grid.astype(int))


def test_free_squares_and_corridor_width_by_hand():
    grid = np.array(
        [
            [c == "@" for c in row]
            for row in [
                "@@@@@@",
                "@..@..",
                "@..@..",
                "@.....",
            ]
        ]
    )
    sizes = free_square_sizes(grid)
    assert sizes[1, 1] == 2 and sizes[3, 4] == 2 and sizes[0, 0] == 0
    assert sizes[3, 3] == 1  # the cell under the wall's end fits only a 1 x 1 square
    assert narrowest_corridor(grid, quantile=0) == 1
    corridor = np.array([[c == "@" for c in row] for row in ["@@@@@", "@...@", "@...@", "@@@@@"]])
    assert narrowest_corridor(corridor, quantile=0) == 2


@needs_mapf
@pytest.mark.parametrize("name", MAPF_MAPS)
def test_every_moving_ai_map_converts_and_validates(name, tmp_path, capsys):
    out = tmp_path / f"{name}.yaml"
    assert main(["import", "movingai", str(MAPF / f"{name}.map"), "-o", str(out)]) == 0
    assert main(["validate", str(out)]) == 0
    scenario = load_scenario(out)
    grid = read_grid(MAPF / f"{name}.map")
    H, W = grid.shape
    # every blocked cell centre is inside an obstacle, every free cell centre is not
    tiny = CollisionWorld(scenario, [1e-6, 1e-6])
    for r in range(0, H, max(1, H // 32)):
        for c in range(0, W, max(1, W // 32)):
            pose = np.array([c + 0.5, H - r - 0.5, 0.0])
            assert tiny.in_collision(pose) == grid[r, c]
    # the robot: its minor diameter fits the narrowest corridor, its major one does not
    w = narrowest_corridor(grid)
    a1, a2 = scenario.semi_axes
    assert 2 * a2 < w < 2 * a1
    assert "Moving AI" in scenario.description and "MIT" in scenario.description


@needs_mapf
def test_moving_ai_scen_rows_and_planning(tmp_path, capsys):
    out = tmp_path / "m4.yaml"

    def convert(index: str) -> int:
        return main(
            [
                "import",
                "movingai",
                str(MAPF / "maze-32-32-4.map"),
                "--scen",
                str(SCEN / "maze-32-32-4-even-1.scen"),
                "--index",
                index,
                "-o",
                str(out),
            ]
        )

    assert convert("1") == 0
    scenario = load_scenario(out)
    assert "row 1" in scenario.description
    result = plan(scenario, "kc-rrtconnect", 30.0, seed=2)
    assert result.solved
    assert not verify_path(CollisionWorld(scenario), result.states).collides
    assert convert("999") == 2
    err = capsys.readouterr().err
    assert "--index" in err and len(err.strip().splitlines()) == 1


def test_moving_ai_bad_map_is_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.map"
    bad.write_text("type octile\nheight 2\nwidth 3\nmap\n...\n..\n")
    assert main(["import", "movingai", str(bad), "-o", str(tmp_path / "o.yaml")]) == 2
    err = capsys.readouterr().err.strip()
    assert str(bad) in err and "expected 2 rows of 3 cells" in err
    assert not (tmp_path / "o.yaml").exists()
