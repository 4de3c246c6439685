import json
import subprocess
import sys

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
