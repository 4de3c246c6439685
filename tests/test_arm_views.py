"""Views of arms (kcplan.views.arm, the arm parts of kcplan.views.html, kcplan.views.animation and
kcplan.views.plots, and their options on the command line): the page holds the expected frames and
meshes posed as Pinocchio poses them, its script poses them the same way, the GIF has the
expected frames, bad outputs are one line and exit 2 with no file left behind."""

import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yaml

from kcplan.arm.kinematics import body_frames
from kcplan.cli import main
from kcplan.scenarios import load_scenario
from kcplan.views.arm import arm_meshes, cover_meshes, decimate, joint_path, mesh_frames

ROOT = Path(__file__).resolve().parents[1]
PANDA = ROOT / "scenarios" / "arm" / "panda"
VISUAL = ROOT.parent / "shared" / "data" / "external" / "mbm" / "panda" / "meshes" / "visual"
GROUP = [f"panda_joint{i}" for i in range(1, 8)]
READY = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]
GOAL = [1.64, -0.18, -2.46, -0.78, 1.21, 1.28, 1.13]
PATH = [READY, [0.8, -0.5, -1.2, -1.6, 0.6, 1.4, 0.9], GOAL]

# the failed-save test drops an animation that never rendered; matplotlib warns when it goes
pytestmark = pytest.mark.filterwarnings("ignore:Animation was deleted without rendering")


@pytest.fixture(scope="module")
def reach(tmp_path_factory) -> Path:
    """A one-body-per-link Panda scenario (covers fit in about 2 s) with a box and a
    cylinder."""
    data = {
        "name": "reach",
        "robot": {"urdf": str(PANDA / "panda.urdf"), "srdf": str(PANDA / "panda.srdf"),
                  "joints": GROUP, "bodies_per_link": 1},
        "start": {"joints": READY},
        "goal": {"joints": GOAL},
        "obstacles": [
            {"box": {"center": [0.55, 0.0, 0.25], "size": [0.3, 0.6, 0.04]}},
            {"cylinder": {"center": [0.3, -0.45, 0.6], "radius": 0.05, "height": 0.3}},
        ],
    }  # fmt: skip
    path = tmp_path_factory.mktemp("arm") / "reach.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.fixture(scope="module")
def scenario(reach):
    return load_scenario(reach)


def _oMg(arm, state) -> list[np.ndarray]:
    """Pinocchio's world frames of the arm's collision geometries at ``state``."""
    data = arm.model.createData()
    geometry_data = pin.GeometryData(arm.geometry)
    pin.forwardKinematics(arm.model, data, arm.configuration(state))
    pin.updateGeometryPlacements(arm.model, data, arm.geometry, geometry_data)
    return [np.asarray(M.homogeneous) for M in geometry_data.oMg]


def _page_data(html: str) -> dict:
    found = re.search(r'<script type="application/json" id="kcplan-arm-data">(.*?)</script>',
                      html, re.S)  # fmt: skip
    assert found, "no data block"
    return json.loads(found.group(1))


def _frame(rows) -> np.ndarray:
    return np.vstack([np.reshape(rows, (3, 4)), [0.0, 0.0, 0.0, 1.0]])


def test_joint_path_keeps_the_waypoints_and_spreads_the_frames():
    dense = joint_path(PATH, 20)
    assert np.array_equal(dense[0], PATH[0]) and np.array_equal(dense[-1], PATH[-1])
    assert any(np.array_equal(row, PATH[1]) for row in dense)
    assert 21 <= len(dense) <= 23
    steps = np.linalg.norm(np.diff(dense, axis=0), axis=1)
    assert steps.max() < 2.0 * steps.min()  # even spacing along the two edges


def test_decimation_bounds_the_triangles_and_keeps_the_shape():
    import trimesh

    sphere = trimesh.creation.icosphere(5)  # 20480 triangles
    V, F, C = decimate(sphere.vertices, sphere.faces, 2000, np.ones((len(sphere.faces), 3)))
    assert 500 < len(F) <= 2000 and len(C) == len(F) and F.max() < len(V)
    assert np.abs(np.linalg.norm(V, axis=1) - 1.0).max() < 0.05
    same = decimate(sphere.vertices, sphere.faces, 30000)
    assert same[1].shape == sphere.faces.shape


def test_the_page_holds_every_frame_and_mesh_posed_as_pinocchio_poses_them(scenario, tmp_path):
    from kcplan.views.html import write_scene_html

    out = tmp_path / "arm.html"
    source = write_scene_html(scenario, out, PATH)
    html = out.read_text()
    assert source.startswith("collision meshes")  # the bundled Panda has no visual meshes
    assert "<script src=" not in html and "plotly.js" in html.lower()  # self-contained
    assert out.stat().st_size < 5.5e6
    data = _page_data(html)
    dense = joint_path(PATH, 59)
    arm = scenario.arm
    assert len(data["joint_frames"]) == len(data["states"]) == len(dense) == len(data["labels"])
    assert np.allclose(data["states"], dense, atol=0, rtol=0)
    assert len(data["meshes"]) == len(arm.geometry.geometryObjects) == 11
    assert len(data["cover"]) == len(arm.bodies)
    for k, state in ((0, scenario.start), (-1, scenario.goal)):
        expected = _oMg(arm, state)
        for mesh, oMg in zip(data["meshes"], expected, strict=True):
            world = _frame(data["joint_frames"][k][mesh["joint"]]) @ _frame(mesh["placement"])
            assert np.abs(world - oMg).max() < 1e-9, (mesh["name"], k)
    bodies = body_frames(arm, scenario.goal)  # kcplan's own chain, for the cover
    for body, expected in zip(data["cover"], bodies, strict=True):
        world = _frame(data["joint_frames"][-1][body["joint"]]) @ _frame(body["placement"])
        assert np.abs(world - expected).max() < 1e-9, body["name"]
    starts = [_frame(r) for r in data["start_frames"]]
    assert np.abs(np.array(starts) - [_frame(r) for r in data["joint_frames"][0]]).max() < 1e-12
    assert data["labels"][0].endswith("(start)") and data["labels"][-1].endswith("(goal)")
    assert np.linalg.norm(np.asarray(data["path"][-1])) > 0.1  # the tip moved
    assert not data["cover"] or 'id="kc-cover" type="checkbox">' in html  # hidden at first


@pytest.mark.skipif(shutil.which("node") is None, reason="needs node to run the page's script")
def test_the_page_script_poses_the_meshes_like_python(scenario, tmp_path):
    """Run the page's own script in node (plotly stubbed) and compare what it hands to
    ``Plotly.restyle`` with the meshes posed in Python at the first frame."""
    from kcplan.views.html import _ARM_SCRIPT, arm_view_data

    data = arm_view_data(scenario, PATH, frames=5)
    data["traces"] = {"start": 0, "goal": 1, "arm": 2, "cover": 3}
    script = _ARM_SCRIPT.replace("{plot_id}", "plot")
    stub = """
var calls = [];
var elements = {};
function element(id) {
  if (!elements[id]) elements[id] = {id: id, value: 0, checked: id !== 'kc-cover',
    textContent: id === 'kcplan-arm-data' ? DATA : '', addEventListener: function () {}};
  return elements[id];
}
var document = {getElementById: element};
var window = {location: {hash: ''}};
var Plotly = {restyle: function (gd, update, traces) {
  calls.push({update: update, traces: traces}); return Promise.resolve(); }};
"""
    js = ("var DATA = " + json.dumps(json.dumps(data)) + ";\n" + stub + script
          + "\nsetTimeout(function () { console.log(JSON.stringify(calls)); }, 50);\n")  # fmt: skip
    (tmp_path / "page.js").write_text(js)
    run = subprocess.run(["node", str(tmp_path / "page.js")], capture_output=True, text=True,
                         timeout=60, check=True)  # fmt: skip
    calls = json.loads(run.stdout)
    arm = next(c for c in calls if c["traces"] == [2] and "i" in c["update"])
    xyz = np.column_stack([arm["update"][a][0] for a in "xyz"])
    meshes, _ = arm_meshes(scenario.arm)
    frames = np.array([[_frame(r) for r in data["joint_frames"][0]]])
    posed = []
    for mesh, T in zip(meshes, mesh_frames(meshes, frames)[0], strict=True):
        V = np.round(mesh.vertices, 6)
        posed.append(V @ T[:3, :3].T + T[:3, 3])
    assert np.abs(xyz - np.vstack(posed)).max() < 1e-9
    faces = np.column_stack([arm["update"][a][0] for a in "ijk"])
    assert len(faces) == sum(len(m.faces) for m in meshes) and faces.max() == len(xyz) - 1
    cover = next(c for c in calls if c["traces"] == [3] and "i" in c["update"])
    xyz = np.column_stack([cover["update"][a][0] for a in "xyz"])
    bodies = cover_meshes(scenario.arm)
    posed = [m.vertices @ T[:3, :3].T + T[:3, 3] for m, T in
             zip(bodies, mesh_frames(bodies, frames)[0], strict=True)]  # fmt: skip
    assert np.abs(xyz - np.vstack(posed)).max() < 1e-6  # the unit sphere is kept to 1e-6
    goal = next(c for c in calls if c["traces"] == [1])
    assert set(goal["update"]["facecolor"][0]) == {"#d62728"}


def test_the_page_renders_the_arm_moving_in_a_headless_browser(scenario, tmp_path):
    """Chromium (headless, offline) renders the page at its first and last frame (the
    ``#frame=N`` address): the see-through goal arm (red) shows at the first, the start arm
    (green) once the arm has left it, and the picture changes (without the page's script
    neither arm is drawn: under 1e-5 of the pixels)."""
    import os

    from PIL import Image

    from kcplan.views.html import write_scene_html

    browser = shutil.which("chromium")
    if browser is None:
        if os.environ.get("CI"):
            pytest.fail("CI installs Debian's chromium for this test (.ci/run)")
        pytest.skip("no chromium (apt-get install chromium)")
    page = tmp_path / "arm.html"
    write_scene_html(scenario, page, PATH)
    shots = []
    for frame in (0, 10_000):  # the page clamps the frame to its last one
        shot = tmp_path / f"shot{frame}.png"
        subprocess.run(
            [browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
             "--window-size=900,700", "--virtual-time-budget=10000", f"--screenshot={shot}",
             f"{page.as_uri()}#frame={frame}"],
            capture_output=True, timeout=120, check=True,
        )  # fmt: skip
        shots.append(np.asarray(Image.open(shot).convert("RGB")).astype(int))
    red, green = [], []
    for image in shots:
        r, g, b = image[..., 0], image[..., 1], image[..., 2]
        red.append(((r - g > 30) & (r - b > 30)).mean())
        green.append(((g - r > 25) & (g - b > 15)).mean())
    assert red[0] > 0.002 and green[1] > 0.002 and green[1] > 5 * green[0], (red, green)
    moved = np.abs(shots[0] - shots[1]).sum(axis=2) > 60
    assert moved.mean() > 0.01, moved.mean()


def test_the_gif_has_the_expected_frames_and_size(scenario, tmp_path):
    from PIL import Image

    from kcplan.views.animation import animate_arm

    out = tmp_path / "arm.gif"
    count = animate_arm(scenario, PATH, out, frames=6, dpi=30, max_faces=100)
    assert count == len(joint_path(PATH, 5))
    with Image.open(out) as gif:
        assert gif.n_frames == count and gif.size == (240, 210)


def test_the_public_views_take_arms(scenario, reach, tmp_path):
    from kcplan.views.html import scene_figure
    from kcplan.views.plots import plot_path, plot_scenario

    plot_path(scenario, PATH, tmp_path / "path.png")
    plot_scenario(reach, tmp_path / "scene.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["path.png", "scene.png"]
    with pytest.raises(ValueError, match="guards: expected none for an arm"):
        plot_path(scenario, PATH, tmp_path / "g.png", guards=[(None, 0.1)])
    with pytest.raises(TypeError, match="an arm's page is made by write_scene_html"):
        scene_figure(scenario)


def test_a_failed_gif_leaves_no_file(scenario, tmp_path, monkeypatch):
    from matplotlib.animation import FuncAnimation

    from kcplan.views.animation import animate_arm

    def broken(self, filename, *args, **kwargs):
        Path(filename).write_bytes(b"GIF89a half")
        raise RuntimeError("disk full")

    monkeypatch.setattr(FuncAnimation, "save", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        animate_arm(scenario, PATH, tmp_path / "arm.gif", frames=3, dpi=20, max_faces=50)
    assert list(tmp_path.iterdir()) == []


def test_plan_and_show_draw_arms_and_refuse_bad_outputs(reach, tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    argv = ["plan", str(reach), "--seed", "1", "--time", "5", "--no-simplify", "--plot",
            str(out / "p.png"), "--html", str(out / "p.html"), "--show-cover"]  # fmt: skip
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "plot written to" in printed and "interactive view written to" in printed
    assert "(links: collision meshes" in printed
    assert 'id="kc-cover" type="checkbox" checked>' in (out / "p.html").read_text()
    assert main(["show", str(reach), "-o", str(out / "s.png")]) == 0
    assert "picture written to" in capsys.readouterr().out
    for name in ("p.png", "s.png"):
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    before = sorted(p.name for p in out.iterdir())
    bad = [
        (["plan", str(reach), "--html", str(tmp_path / "none" / "v.html")],
         "--html: expected a file in an existing folder"),
        (["plan", str(reach), "--animate", str(out / "v.png")], "--animate: expected a .gif"),
        (["plan", str(reach), "--plot", str(out / "p.png"), "--guards"],
         "--guards: not available for arms"),
        (["show", str(ROOT / "scenarios" / "2d" / "l_turn.yaml"), "--show-cover"],
         "--show-cover: only for arms"),
        (["show", str(reach), "--meshes", "visual", "-o", str(out / "v.png")],
         "--meshes visual: Mesh package://meshes/visual/link1.obj"),  # none bundled
    ]  # fmt: skip
    for argv, message in bad:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err.strip()
        assert message in err and len(err.splitlines()) == 1, err
    assert sorted(p.name for p in out.iterdir()) == before


@pytest.mark.skipif(not VISUAL.is_dir(), reason="the Panda's visual meshes are not here")
def test_visual_meshes_are_placed_as_pinocchio_reduces_them(scenario, tmp_path):
    """The Panda's visual meshes (MBM's, beside a copy of the URDF): coloured, decimated,
    and carried to the reduced model where ``pinocchio.buildReducedModel`` puts them."""
    import dataclasses

    (tmp_path / "meshes").mkdir()
    shutil.copy(PANDA / "panda.urdf", tmp_path)
    (tmp_path / "meshes" / "visual").symlink_to(VISUAL)
    (tmp_path / "meshes" / "collision").symlink_to(PANDA / "meshes" / "collision")
    urdf = str(tmp_path / "panda.urdf")
    arm = dataclasses.replace(scenario.arm, urdf=urdf)
    meshes, source = arm_meshes(arm, "visual", max_faces=1500)
    assert source == "visual meshes" and len(meshes) == 11
    assert all(len(m.faces) <= 1500 for m in meshes)
    assert any(len(np.unique(m.colors, axis=0)) > 1 for m in meshes)  # the materials' colours
    full = pin.buildModelFromUrdf(urdf)
    visual = pin.buildGeomFromUrdf(full, urdf, pin.GeometryType.VISUAL,
                                   package_dirs=[str(tmp_path)])  # fmt: skip
    locked = [full.getJointId(n) for n in full.names[1:] if n not in GROUP]
    _, reduced = pin.buildReducedModel(full, visual, locked, pin.neutral(full))
    for mesh, obj in zip(meshes, reduced.geometryObjects, strict=True):
        assert mesh.joint == obj.parentJoint
        assert np.abs(mesh.placement - obj.placement.homogeneous).max() < 1e-12
