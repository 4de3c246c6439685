"""Views of sensed obstacles (kcplan.views.clouds and its users in kcplan.views.plots,
kcplan.views.animation and kcplan.views.html): a ``pointcloud`` or ``depth`` obstacle is
drawn as its points, thinned for display to at most MAX_DRAWN_POINTS (the same points
every time), named by how many of how many are drawn, with the axes grown to show them;
``kcplan show`` writes the picture and the page of a rigid and of an arm scene with
clouds."""

from pathlib import Path

import matplotlib
import numpy as np
import plotly.graph_objects as go
import pytest
import yaml
from PIL import Image

from kcplan.cli import main
from kcplan.scenarios import load_scenario
from kcplan.views.clouds import (
    MAX_DRAWN_POINTS,
    cloud_points_for_display,
    drawn_extent,
    obstacle_centre,
    sensor_triad,
)

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
PANDA = ROOT / "scenarios" / "arm" / "panda"
WALL = 30_000  # points of the rigid scene's large cloud: more than MAX_DRAWN_POINTS
HELIX = 40  # points of its inline cloud, reaching above the bounds (z up to 62)
DEPTH = (200, 150)  # the arm scene's depth image (width, height): 30,000 points

pytestmark = pytest.mark.filterwarnings("ignore:Animation was deleted without rendering")


def _scatters(ax) -> list:
    """The cloud scatters of 3D axes (their label says how many points are drawn)."""
    return [c for c in ax.collections if str(c.get_label()).startswith("cloud: ")]


@pytest.fixture(scope="module")
def rigid(tmp_path_factory) -> Path:
    """scenarios/3d/open_space.yaml with a wall of 30,000 points (a .npy) and an inline
    helix of 40 points that rises above the bounds."""
    folder = tmp_path_factory.mktemp("rigid")
    data = yaml.safe_load((ROOT / "scenarios" / "3d" / "open_space.yaml").read_text())
    for ob in data["obstacles"]:
        if "mesh" in ob:
            ob["mesh"]["file"] = str(ROOT / "scenarios" / "3d" / ob["mesh"]["file"])
    rng = np.random.default_rng(1)
    u = rng.uniform(0.0, 1.0, (WALL, 2))
    across = 45 + 0.5 * rng.standard_normal(WALL)
    wall = np.column_stack([60 + 20 * u[:, 0], across, 5 + 35 * u[:, 1]])
    np.save(folder / "wall.npy", wall)
    t = np.linspace(0.0, 6.0, HELIX)
    helix = np.column_stack([50 + 5 * np.cos(t), 80 + 5 * np.sin(t), 20 + 7 * t])
    data["obstacles"] += [
        {"pointcloud": {"file": "wall.npy", "point_radius": 0.3}},
        {"pointcloud": {"points": helix.tolist(), "point_radius": 0.01}},
    ]
    path = folder / "rigid.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def arm(tmp_path_factory) -> Path:
    """scenarios/arm/box_1.yaml (the Panda in a shelf) with an inline cloud of 625 points
    behind the shelf's back and a depth camera of 200 x 150 pixels looking at it."""
    folder = tmp_path_factory.mktemp("arm")
    data = yaml.safe_load((ROOT / "scenarios" / "arm" / "box_1.yaml").read_text())
    data["robot"]["urdf"] = str(PANDA / "panda.urdf")
    data["robot"]["srdf"] = str(PANDA / "panda.srdf")
    y, z = np.meshgrid(np.linspace(-0.2, 0.6, 25), np.linspace(-0.5, 0.3, 25), indexing="ij")
    wall = np.column_stack([np.full(y.size, 1.0), y.ravel(), z.ravel()])
    (folder / "scans").mkdir()
    width, height = DEPTH
    Image.fromarray(np.full((height, width), 500, dtype=np.uint16)).save(folder / "scans" / "d.png")
    data["obstacles"] += [
        {"pointcloud": {"points": wall.tolist(), "point_radius": 0.01}},
        # the optical axis (z) along the world's -x, the image's y down
        {"depth": {"image": "scans/d.png", "max_range": 2.0, "point_radius": 0.005,
                   "intrinsics": {"fx": 200, "fy": 200, "cx": 99.5, "cy": 74.5},
                   "position": [1.6, 0.15, 0.0], "quaternion": [0.5, 0.5, -0.5, -0.5]}},
    ]  # fmt: skip
    path = folder / "arm.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def rigid_scenario(rigid):
    return load_scenario(rigid)


@pytest.fixture(scope="module")
def arm_scenario(arm):
    return load_scenario(arm)


# ---------------------------------------------------------------- the points drawn


def test_a_large_cloud_is_thinned_the_same_way_every_time(rigid_scenario):
    wall, helix = rigid_scenario.obstacles[-2:]
    points, label = cloud_points_for_display(wall)
    assert points.shape == (MAX_DRAWN_POINTS, 3)
    assert label == f"cloud: 20,000 of 30,000 points (obstacles[{wall.index}]: wall.npy)"
    assert np.array_equal(points, cloud_points_for_display(wall)[0])
    # drawn points are planned points, in their order, none twice
    rows = {tuple(p): k for k, p in enumerate(wall.vertices.tolist())}
    order = [rows[tuple(p)] for p in points.tolist()]
    assert len(set(order)) == MAX_DRAWN_POINTS and order == sorted(order)
    assert len(wall.vertices) == WALL  # planning keeps them all
    small, label = cloud_points_for_display(helix)
    assert np.array_equal(small, helix.vertices)
    assert label == f"cloud: 40 of 40 points (obstacles[{helix.index}]: inline)"
    few, label = cloud_points_for_display(wall, limit=7)
    assert len(few) == 7 and label.startswith("cloud: 7 of 30,000 points")


def test_only_clouds_have_display_points_and_a_depth_camera_a_triad(rigid_scenario, arm_scenario):
    from kcplan.views.arm import obstacle_mesh

    sphere, wall = rigid_scenario.obstacles[0], rigid_scenario.obstacles[-2]
    with pytest.raises(ValueError, match=r"obstacles\[0\] \(sphere\): expected a pointcloud"):
        cloud_points_for_display(sphere)
    with pytest.raises(ValueError, match="a cloud is drawn as points, not as a mesh"):
        obstacle_mesh(wall)
    assert sensor_triad(wall) is None and sensor_triad(sphere) is None
    depth = arm_scenario.obstacles[-1]
    segments, colours = sensor_triad(depth, size=0.2)
    assert np.allclose(segments[:, 0], [1.6, 0.15, 0.0])
    assert np.allclose(segments[2, 1] - segments[2, 0], [-0.2, 0.0, 0.0])  # the optical axis
    assert colours.tolist() == np.eye(3).tolist()
    # a viewpoint looks at a cloud's points, not at its sensor
    assert np.allclose(obstacle_centre(depth), depth.vertices.mean(axis=0))
    assert np.allclose(obstacle_centre(sphere), sphere.center)
    low, high = drawn_extent(arm_scenario.obstacles)
    assert high[0] == pytest.approx(1.6) and low[0] == pytest.approx(1.0)  # camera, wall
    assert drawn_extent(arm_scenario.obstacles, sensors=False)[1, 0] == pytest.approx(1.1)
    assert drawn_extent(rigid_scenario.obstacles[:5]) is None


# ---------------------------------------------------------------- rigid scenes


def test_the_3d_plot_draws_the_clouds_as_points_within_its_limits(rigid_scenario):
    from kcplan.views.plots import draw_scenario, scenario_axes

    fig, ax = scenario_axes(rigid_scenario)
    try:
        draw_scenario(ax, rigid_scenario)
        wall, helix = _scatters(ax)
        assert len(wall.get_offsets()) == MAX_DRAWN_POINTS
        assert wall.get_label() == "cloud: 20,000 of 30,000 points (obstacles[6]: wall.npy)"
        assert len(helix.get_offsets()) == HELIX
        assert np.ptp(wall.get_array()) > 30  # coloured by height
        legend = [t.get_text() for t in ax.get_legend().get_texts()]
        assert legend == [wall.get_label(), helix.get_label()]
        assert ax.get_zlim() == pytest.approx((0.0, 62.0))  # the bounds' 50 and the helix's 62
        assert ax.get_xlim() == pytest.approx((0.0, 100.0))
        # no obstacle drawn at the sensor (the origin: no position given)
        assert all(np.ptp(np.asarray(c.get_offsets()), axis=0).max() > 0 for c in _scatters(ax))
    finally:
        plt.close(fig)


def test_the_page_draws_the_clouds_as_thinned_markers(rigid_scenario):
    from kcplan.views.html import scene_figure

    figure = scene_figure(rigid_scenario, [rigid_scenario.start, rigid_scenario.goal], frames=3)
    clouds = [t for t in figure.data if isinstance(t, go.Scatter3d) and t.mode == "markers"]
    assert [len(t.x) for t in clouds] == [MAX_DRAWN_POINTS, HELIX]
    assert clouds[0].name == "cloud: 20,000 of 30,000 points (obstacles[6]: wall.npy)"
    assert clouds[0].marker.size == 2 and clouds[0].marker.colorscale is not None
    assert np.array_equal(clouds[0].marker.color, clouds[0].z)
    assert not any("pointcloud" in (t.name or "") for t in figure.data if isinstance(t, go.Mesh3d))
    assert clouds[0].name in figure.layout.title.text  # the legend is off
    # the animation still moves the robot's traces, not the clouds
    moving = set(figure.frames[0].traces)
    assert all(figure.data[k].name == "robot" for k in moving)


def test_show_writes_a_rigid_scenes_picture_and_page(rigid, tmp_path, capsys):
    png, html = tmp_path / "s.png", tmp_path / "s.html"
    assert main(["show", str(rigid), "-o", str(png), "--html", str(html)]) == 0
    assert "picture written to" in capsys.readouterr().out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    page = html.read_text()
    assert "cloud: 20,000 of 30,000 points (obstacles[6]: wall.npy)" in page
    assert "cloud: 40 of 40 points (obstacles[7]: inline)" in page


def test_the_gif_of_a_rigid_path_draws_the_clouds(rigid_scenario, tmp_path):
    from kcplan.views.animation import animate_path

    out = tmp_path / "p.gif"
    count = animate_path(rigid_scenario, [rigid_scenario.start, rigid_scenario.goal], out,
                         frames=3, dpi=30)  # fmt: skip
    with Image.open(out) as gif:
        assert gif.n_frames == count


# ---------------------------------------------------------------- arms


def test_the_arm_picture_draws_the_clouds_and_the_camera(arm_scenario, tmp_path, monkeypatch):
    from kcplan.views import plots

    kept = []
    monkeypatch.setattr(plots, "save_figure", lambda fig, path, dpi=120: kept.append(fig))
    plots.plot_arm(arm_scenario, tmp_path / "a.png", max_faces=100)
    (fig,) = kept
    try:
        for k, ax in enumerate(fig.axes):
            wall, depth = _scatters(ax)
            assert len(wall.get_offsets()) == 625
            assert len(depth.get_offsets()) == MAX_DRAWN_POINTS
            assert depth.get_label() == (
                "cloud: 20,000 of 30,000 points (obstacles[8]: scans/d.png (200x150 depth image))"
            )
            assert (ax.get_legend() is not None) == (k == 0)  # one legend for both views
            assert ax.get_xlim()[1] > 1.6  # the camera is in the picture
            triad = [line for line in ax.lines if len(line.get_xdata()) == 2]
            assert len(triad) == 3
    finally:
        plt.close(fig)


def test_the_arm_page_draws_the_clouds_and_keeps_its_traces(arm_scenario):
    from kcplan.views.html import arm_figure, arm_view_data

    data = arm_view_data(arm_scenario, max_faces=100)
    figure = arm_figure(arm_scenario, data)
    clouds = [t for t in figure.data if isinstance(t, go.Scatter3d) and t.mode == "markers"]
    assert [len(t.x) for t in clouds] == [625, MAX_DRAWN_POINTS]
    assert [t.name for t in figure.data if getattr(t, "mode", None) == "lines"] == [
        "obstacles[8]: depth camera x axis", "obstacles[8]: depth camera y axis",
        "obstacles[8]: depth camera z axis"]  # fmt: skip
    assert sum(bool(t.showlegend) for t in figure.data if t.name == "obstacles") == 1
    # the page's script fills the traces it names
    names = {role: figure.data[k].name for role, k in data["traces"].items()}
    assert names["start"] == "start" and names["goal"] == "goal"
    assert names["cover"] == "covering ellipsoids" and names["arm"].startswith("arm (")


def test_show_writes_an_arm_scenes_picture_and_page(arm, tmp_path, capsys):
    png, html = tmp_path / "a.png", tmp_path / "a.html"
    assert main(["show", str(arm), "-o", str(png), "--html", str(html)]) == 0
    assert "picture written to" in capsys.readouterr().out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    page = html.read_text().replace("\\u002f", "/")  # plotly's JSON escapes every "/"
    assert "cloud: 625 of 625 points (obstacles[7]: inline)" in page
    depth = "cloud: 20,000 of 30,000 points (obstacles[8]: scans/d.png (200x150 depth image))"
    assert depth in page


def test_the_arm_gif_draws_the_clouds(arm_scenario, tmp_path):
    from kcplan.views.animation import animate_arm

    out = tmp_path / "a.gif"
    count = animate_arm(arm_scenario, [arm_scenario.start, arm_scenario.goal], out, frames=3,
                        dpi=30, max_faces=50)  # fmt: skip
    with Image.open(out) as gif:
        assert gif.n_frames == count
