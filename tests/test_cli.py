import json
import math
import os
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from kcplan.cli import main


def test_bounds_2d_prints_counts_and_ratios(capsys):
    assert main(["bounds", "--semi-axes", "5", "3.5", "--inflation", "0.08", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["convex_vertices"] == 18
    assert 0 < report["ratio_convex"] < report["ratio_geometric"] < 1
    assert report["volume_kc"] == pytest.approx(0.0862, rel=2e-3)


def test_bounds_plot_is_written(tmp_path, capsys):
    out = tmp_path / "b.png"
    assert (
        main(["bounds", "--semi-axes", "5", "3.5", "--inflation", "0.08", "--plot", str(out)]) == 0
    )
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "convex / true" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["bounds", "--semi-axes", "5", "-3", "--inflation", "0.1"],
            "semi_axes: expected 2 or 3 positive",
        ),
        (["bounds", "--semi-axes", "5", "3", "--inflation", "0"], "inflation: expected a positive"),
        (
            ["bounds", "--semi-axes", "5", "--inflation", "0.1"],
            "--semi-axes: expected 2 or 3 numbers, got 1",
        ),
        (["bounds", "--semi-axes", "5", "x", "--inflation", "0.1"], "expected a number, got 'x'"),
        (["bounds", "--semi-axes", "5", "3", "--inflation", "inf"], "expected a finite number"),
        (["frobnicate"], "invalid choice"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(argv, message):
    proc = subprocess.run(
        [sys.executable, "-m", "kcplan.cli", *argv], capture_output=True, text=True
    )
    assert proc.returncode == 2
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr


def test_version_is_printed():
    proc = subprocess.run(
        [sys.executable, "-m", "kcplan.cli", "--version"], capture_output=True, text=True
    )
    from kcplan import __version__

    assert proc.returncode == 0 and proc.stdout.strip() == f"kcplan {__version__}"


OPEN_FIELD = str(Path(__file__).resolve().parents[1] / "scenarios" / "2d" / "open_field.yaml")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["plan", OPEN_FIELD, "-o", "/nonexistent/dir/x.json"],
            "-o: expected a file in an existing folder",
        ),
        (["plan", OPEN_FIELD, "--plot", "/nonexistent/dir/x.png"], "--plot: expected a file in"),
        (["plan", OPEN_FIELD, "--plot", "x.jpg"], "--plot: expected a .png file name"),
        (["show", OPEN_FIELD, "-o", "/nonexistent/x.png"], "-o: expected a file in an existing"),
    ],
)
def test_output_paths_are_checked_before_any_work(argv, message, capsys):
    """A missing output folder is refused with one line and exit 2 before planning, so
    no plan is lost to a traceback at the end."""
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == ""  # nothing planned or drawn
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], captured.err


@pytest.mark.parametrize("yaw", [math.pi, 3.1416, -math.pi, 7.0])
def test_start_yaw_is_normalised_for_ompl(yaw, tmp_path, capsys):
    """OMPL's SO(2) holds [-pi, pi]: a yaw outside was an invalid start and 'not solved'."""
    from kcplan.scenarios import load_scenario

    text = Path(OPEN_FIELD).read_text()
    data = __import__("yaml").safe_load(text)
    data["start"]["yaw"] = yaw
    path = tmp_path / "s.yaml"
    path.write_text(json.dumps(data))
    scenario = load_scenario(path)
    assert -math.pi <= scenario.start[2] < math.pi
    assert math.isclose(math.cos(scenario.start[2]), math.cos(yaw), abs_tol=1e-12)
    assert main(["plan", str(path), "--seed", "1", "--time", "2"]) == 0
    assert "solved by kc-rrtconnect" in capsys.readouterr().out


def test_plan_animate_writes_a_small_gif_of_every_body(tmp_path, capsys):
    from PIL import Image

    root = Path(__file__).resolve().parents[1]
    scenario = str(root / "scenarios" / "2d" / "l_robot_door.yaml")
    out = tmp_path / "door.gif"
    assert main(["plan", scenario, "--seed", "1", "--animate", str(out)]) == 0
    assert "animation written to" in capsys.readouterr().out
    assert out.read_bytes()[:6] == b"GIF89a" and out.stat().st_size < 5 * 2**20
    with Image.open(out) as gif:
        assert gif.n_frames >= 30
    assert [p.name for p in tmp_path.iterdir()] == ["door.gif"]  # no temporary file left
    # a wrong suffix or a missing folder is refused before any planning
    assert main(["plan", scenario, "--animate", str(tmp_path / "door.png")]) == 2
    assert main(["plan", scenario, "--animate", str(tmp_path / "no" / "d.gif")]) == 2
    assert "--animate: expected a .gif file name" in capsys.readouterr().err


def test_html_view_renders_the_scene_in_a_headless_browser(tmp_path, capsys):
    """`kcplan plan --html` writes one self-contained file; Chromium (headless) renders it
    offline and the screenshot shows the scene, not a blank page."""
    import os
    import shutil

    from PIL import Image

    browser = shutil.which("chromium")
    if browser is None:
        if os.environ.get("CI"):
            pytest.fail("CI installs Debian's chromium for this test (.ci/run)")
        pytest.skip("no chromium (apt-get install chromium)")
    root = Path(__file__).resolve().parents[1]
    page = tmp_path / "door.html"
    scenario = str(root / "scenarios" / "2d" / "l_robot_door.yaml")
    assert main(["plan", scenario, "--seed", "1", "--html", str(page)]) == 0
    html = page.read_text()
    assert "<script" in html and "cdn." not in html.split("<body>")[0].lower()  # embedded
    shot = tmp_path / "shot.png"
    subprocess.run(
        [browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
         "--window-size=1000,750", "--virtual-time-budget=8000", f"--screenshot={shot}",
         page.as_uri()],
        capture_output=True, timeout=120, check=True,
    )  # fmt: skip
    image = np.asarray(Image.open(shot).convert("RGB")).reshape(-1, 3)
    grey = np.all(np.abs(image.astype(int) - [150, 150, 150]) < 20, axis=1).mean()
    red = np.mean((image[:, 0] > 150) & (image[:, 1] < 90) & (image[:, 2] < 90))
    blue = np.mean((image[:, 2] > 140) & (image[:, 0] < 80) & (image[:, 1] < 150))
    # obstacles (grey), the goal (red) and the robot on its path (blue) are on the page
    assert grey > 0.005 and red > 0.0002 and blue > 0.0002, (grey, red, blue)
    assert main(["show", scenario, "--html", str(tmp_path / "x.txt")]) == 2


def test_output_files_honour_the_umask_and_keep_a_replaced_files_mode(tmp_path, capsys):
    """mkstemp alone gave every output 0600: unreadable in a shared or served folder."""
    out, png = tmp_path / "open.json", tmp_path / "open.png"
    argv = ["plan", OPEN_FIELD, "--seed", "1", "--time", "2", "-o", str(out), "--plot", str(png)]
    old = os.umask(0o022)
    try:
        assert main(argv) == 0
        assert stat.S_IMODE(out.stat().st_mode) == 0o644
        assert stat.S_IMODE(png.stat().st_mode) == 0o644
        os.umask(0o077)  # a new file follows the umask ...
        assert main([*argv[:-4], "-o", str(tmp_path / "private.json")]) == 0
        assert stat.S_IMODE((tmp_path / "private.json").stat().st_mode) == 0o600
        out.chmod(0o640)  # ... a replaced one keeps its own mode
        assert main(argv) == 0
        assert stat.S_IMODE(out.stat().st_mode) == 0o640
        assert stat.S_IMODE(png.stat().st_mode) == 0o644
    finally:
        os.umask(old)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["open.json", "open.png", "private.json"]
