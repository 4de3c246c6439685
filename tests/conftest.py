"""Shared hypothesis strategies for the geometry tests, a private cover cache, and the
suite's time budget per test file."""

import os
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings
from hypothesis import strategies as st

settings.register_profile("default", deadline=None, print_blob=True)
settings.load_profile("default")

# covers of mesh robots are cached per user; the tests keep theirs apart (and start cold),
# one cache per test run: pytest-xdist's workers share it (entries are written atomically)
_RUN = os.environ.get("PYTEST_XDIST_TESTRUNUID")
if _RUN:
    _CACHE = Path(tempfile.gettempdir()) / f"kcplan-test-cache-{_RUN}"
    _CACHE.mkdir(exist_ok=True)
    os.environ["KCPLAN_CACHE_DIR"] = str(_CACHE)
else:
    os.environ["KCPLAN_CACHE_DIR"] = tempfile.mkdtemp(prefix="kcplan-test-cache-")

FILE_BUDGET = 60.0
"""Seconds a test file's tests may take together (setup, call and teardown, summed over
workers) before the summary names it: with two workers the ten-minute suite holds about
twenty such files, so a file past it is where a new test should get smaller or become a
study (``@pytest.mark.study``, run apart by ``pytest -m study``)."""
FILE_BUDGETS = {"test_scripts.py": 240.0}
"""Files allowed more: every script in ``scripts/`` runs once, at its smallest arguments."""
_FILE_SECONDS: dict[str, float] = {}


def pytest_runtest_logreport(report):
    path = report.nodeid.split("::", 1)[0]
    _FILE_SECONDS[path] = _FILE_SECONDS.get(path, 0.0) + report.duration


def pytest_terminal_summary(terminalreporter):
    """The files past their budget (:data:`FILE_BUDGET`), and the five slowest files."""
    if not _FILE_SECONDS:
        return
    ranked = sorted(_FILE_SECONDS.items(), key=lambda item: -item[1])
    over = [(p, t) for p, t in ranked if t > FILE_BUDGETS.get(Path(p).name, FILE_BUDGET)]
    terminalreporter.section("time per test file")
    for path, seconds in ranked[:5]:
        terminalreporter.write_line(f"{seconds:7.1f} s  {path}")
    terminalreporter.write_line(f"{sum(_FILE_SECONDS.values()):7.1f} s  in all (every worker)")
    for path, seconds in over:
        budget = FILE_BUDGETS.get(Path(path).name, FILE_BUDGET)
        terminalreporter.write_line(f"over budget: {path}: {seconds:.1f} s (budget {budget:.0f} s)")


@st.composite
def semi_axes(draw, n: int, max_ratio: float = 5.0) -> np.ndarray:
    """Semi-axes with max/min ratio up to ``max_ratio``, largest axis in [0.5, 20]."""
    big = draw(st.floats(0.5, 20.0))
    ratios = [draw(st.floats(1.0, max_ratio)) for _ in range(n - 1)]
    return np.array(sorted([big] + [big / r for r in ratios], reverse=True))


inflations = st.floats(0.005, 1.0)


ARM_SCENE = [  # a shelf board in front of the Panda, the floor, a ball beside it
    {"box": {"center": [0.55, 0.0, 0.25], "size": [0.3, 0.6, 0.04]}},
    {"box": {"center": [0.0, 0.0, -0.16], "size": [2.0, 2.0, 0.02]}},
    {"sphere": {"center": [0.3, -0.45, 0.6], "radius": 0.08}},
]
"""The arm tests' scene (kcplan scenario obstacle specs, 3D)."""


def arm_obstacles(specs=ARM_SCENE):
    """Obstacles of a 3D scene from scenario obstacle specs (read by the rigid scenario
    loader, whose robot and bounds are placeholders)."""
    from kcplan.scenarios import parse_scenario

    data = {
        "name": "scene", "dimension": 3,
        "bounds": {"low": [-2.0, -2.0, -2.0], "high": [2.0, 2.0, 2.0]},
        "robot": {"semi_axes": [0.1, 0.1, 0.1]},
        "start": {"position": [0.0, 0.0, 0.0]}, "goal": {"position": [0.0, 0.0, 0.0]},
        "obstacles": specs,
    }  # fmt: skip
    return parse_scenario(data, check=False).obstacles


PANDA = Path(__file__).resolve().parents[1] / "scenarios" / "arm" / "panda"
"""The bundled MBM Panda (URDF, SRDF, collision meshes)."""
PANDA_GROUP = [f"panda_joint{i}" for i in range(1, 8)]


def _examples_installed() -> bool:
    from kcplan.arm import ArmError
    from kcplan.arm.examples import example_folder

    try:
        example_folder()
    except ArmError:
        return False
    return True


needs_examples = pytest.mark.skipif(
    not _examples_installed(), reason="example-robot-data not installed (kcplan[robots])"
)
"""Skips a test of example-robot-data's robots where the optional extra is missing."""


def panda_arm(bodies_per_link: int | None):
    """The bundled Panda's 7-joint group, ``bodies_per_link`` ellipsoids per link, fitted
    in the tests' private cover cache (once per test session and count); None: each link
    its own convex hull (kcplan's default representation)."""
    from kcplan.arm import load_arm

    return load_arm(
        PANDA / "panda.urdf", PANDA_GROUP, srdf=PANDA / "panda.srdf",
        bodies_per_link=bodies_per_link,
    )  # fmt: skip


@pytest.fixture(scope="module")
def panda(request):
    """The bundled Panda for an arm test module: its ``BODIES_PER_LINK`` (default 2)
    ellipsoids per link, or its links' hulls where the module sets it to None
    (:func:`panda_arm`)."""
    return panda_arm(getattr(request.module, "BODIES_PER_LINK", 2))


@pytest.fixture(scope="module")
def states(panda):
    """300 random joint vectors of ``panda`` within its limits (seed 7)."""
    return np.random.default_rng(7).uniform(panda.lower, panda.upper, size=(300, panda.dof))


@pytest.fixture(scope="module")
def world(panda, request):
    """``panda`` in the arm tests' scene (:data:`ARM_SCENE`) and the module's
    ``EXTRA_OBSTACLES``, if any."""
    from kcplan.arm import ArmWorld

    return ArmWorld(panda, (*arm_obstacles(), *getattr(request.module, "EXTRA_OBSTACLES", ())))


# two of the Panda's covering ellipsoids (K = 4) at a state of box_1, frames [R | t] and
# semi-axes, where python-fcl's distance is 7.6 % too large (RESULTS 11.2)
FRAME_A = [
    [-0.258527440075, -0.782940024823, 0.56583432227, -0.231000054592],
    [-0.790483528887, 0.508143301405, 0.341944696983, 0.005782809322],
    [-0.555247110111, -0.358880624676, -0.750270180632, 0.29465356976],
]
FRAME_B = [
    [-0.469978999907, 0.527399294467, -0.707792147344, -0.409912721165],
    [-0.818900442519, 0.038745536239, 0.572626273116, 0.015912278893],
    [0.329426478729, 0.848733625832, 0.413677927251, 0.21608404707],
]
AXES_A = [0.037072799508, 0.065385681018, 0.082023441791]
AXES_B = [0.007962846033, 0.016329866169, 0.028091109846]


def assert_planner_refused(scenario, name: str, line: str, why: str, tmp_path, capsys) -> None:
    """The planner ``name`` refused on ``scenario`` everywhere a user can ask for it:
    `kcplan plan` prints exactly ``line`` and exits 2, `kcplan bench` exits 2 naming it
    (``--planners: NAME: WHY``) and writes nothing, and ``plan()`` raises a ValueError
    that starts ``planner: NAME: WHY``."""
    import re

    from kcplan.cli import main
    from kcplan.planning.problem import plan

    assert main(["plan", str(scenario), "--planner", name, "--time", "0.05"]) == 2
    assert capsys.readouterr().err.strip() == line
    argv = ["bench", str(scenario), "--planners", f"kc-rrtconnect,{name}", "--runs", "1",
            "-o", str(tmp_path / "bench")]  # fmt: skip
    assert main(argv) == 2
    assert f"--planners: {name}: {why}" in capsys.readouterr().err
    assert not (tmp_path / "bench").exists()
    with pytest.raises(ValueError, match=f"^{re.escape(f'planner: {name}: {why}')}"):
        plan(scenario, name, time_limit=0.05)


def sphere_points(n: int) -> np.ndarray:
    """n nearly even unit vectors (a Fibonacci lattice), shape (n, 3)."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = np.pi * (1.0 + 5**0.5) * i
    r = np.sqrt(1.0 - z * z)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])
