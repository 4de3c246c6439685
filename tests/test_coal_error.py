"""coal's distance error stays within the kernel's allowance (scripts/coal_distance_error.py).

The script compares ``World.body_distances`` with exact distances (by construction, each
checked by its dual certificate) for an ellipsoid robot against every obstacle kind.
"""

import json
import subprocess
import sys
from pathlib import Path

from kcplan._kernel import COAL_CLEARANCE_ATOL, COAL_CLEARANCE_RTOL

ROOT = Path(__file__).resolve().parent.parent


def run(*args: str) -> dict:
    proc = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "coal_distance_error.py"), *args],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_coal_error_within_allowance():
    out = run("--samples", "200", "--verify", "2")
    assert out["samples"] == 200 * 11
    assert out["max_rel_excess"] < COAL_CLEARANCE_RTOL  # far from obstacles
    assert out["max_scene_excess"] < COAL_CLEARANCE_ATOL  # near contact, per scene size
    assert out["max_allowance_use"] < 1 and out["violations"] == 0


def test_coal_error_within_allowance_in_small_units():
    """Near contact coal's error is absolute (1e-6 length units): the scene-relative part
    alone fails in a scene 0.2 wide, the kernel's floor covers it."""
    assert run("--samples", "200", "--scale", "0.01", "--floor", "0")["violations"] > 0
    assert run("--samples", "200", "--scale", "0.01")["violations"] == 0
