"""Scenario files: the suite, round trips, every documented error, and a loader fuzz."""

import copy
import glob
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from kcplan.cli import main
from kcplan.geometry.polygon import convex_pieces, polygon_area
from kcplan.scenarios import dump_scenario, load_scenario, parse_scenario
from kcplan.world import ScenarioError, scenario_to_dict

ROOT = Path(__file__).resolve().parent.parent
# the rigid suite (arm scenarios, scenarios/arm/, have tests of their own: test_arm_cli.py)
SUITE = sorted(p for p in glob.glob(str(ROOT / "scenarios" / "*" / "*.yaml")) if "/arm/" not in p)

VALID = {
    "name": "t",
    "dimension": 2,
    "bounds": {"low": [0, 0], "high": [100, 60]},
    "robot": {"semi_axes": [5.0, 3.5], "inflation": 0.08},
    "start": {"position": [10, 30], "yaw": 0.0},
    "goal": {"position": [90, 30], "yaw": 1.5708},
    "obstacles": [
        {"box": {"center": [50, 10], "size": [4, 20], "yaw": 0.3}},
        {"ellipse": {"center": [30, 50], "semi_axes": [6, 2]}},
        {"circle": {"center": [70, 50], "radius": 3}},
        {"polygon": {"vertices": [[40, 30], [60, 30], [60, 50], [55, 50], [55, 35], [40, 35]]}},
    ],
}


def test_suite_has_the_required_scenarios():
    names = {Path(p).stem for p in SUITE}
    assert len([p for p in SUITE if "/2d/" in p]) >= 8
    assert len([p for p in SUITE if "/3d/" in p]) >= 5
    assert {"narrow_corridor", "slanted_gap", "maze", "bug_trap", "random_clutter"} <= names
    assert {"window_wall", "box_field", "narrow_tunnel", "peg_in_hole"} <= names
    for path in SUITE:
        assert Path(path).with_suffix(".png").is_file(), f"no picture for {path}"


@pytest.mark.parametrize("path", SUITE, ids=lambda p: Path(p).stem)
def test_suite_round_trip(path, tmp_path):
    scenario = load_scenario(path)
    assert scenario.description
    data = scenario_to_dict(scenario)
    copy_path = Path(path).parent / f".roundtrip-{tmp_path.name}.yaml"
    try:
        dump_scenario(data, copy_path)
        again = load_scenario(copy_path)
    finally:
        copy_path.unlink(missing_ok=True)
    assert scenario_to_dict(again) == data
    assert np.array_equal(again.start, scenario.start) and np.array_equal(again.goal, scenario.goal)
    assert len(again.obstacles) == len(scenario.obstacles)


def write(tmp_path, data, name="x.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data) if not isinstance(data, str) else data)
    return path


def mutated(path_to_value):
    data = copy.deepcopy(VALID)
    for keys, value in path_to_value:
        target = data
        for k in keys[:-1]:
            target = target[k]
        if value is KeyError:
            del target[keys[-1]]
        else:
            target[keys[-1]] = value
    return data


BAD = [
    (
        [(("obstacles", 0, "box", "size"), [4, -1])],
        "obstacles[0].box.size: expected 2 positive numbers, got [4, -1]",
    ),
    ([(("obstacles", 0, "box", "colour"), "red")], "obstacles[0].box: unknown key 'colour'"),
    ([(("name",), KeyError)], "top level: missing required key 'name'"),
    ([(("extra",), 1)], "top level: unknown key 'extra'"),
    ([(("dimension",), 4)], "dimension: expected 2 or 3, got 4"),
    ([(("bounds", "low"), [0, 70])], "bounds: expected low < high"),
    ([(("robot", "semi_axes"), [5, 0])], "robot.semi_axes: expected 2 positive numbers"),
    ([(("robot", "inflation"), -0.1)], "robot.inflation: expected a positive number, got -0.1"),
    ([(("start", "position"), [200, 30])], "start.position: expected a point inside bounds"),
    ([(("goal", "yaw"), float("nan"))], "goal.yaw: expected a finite number, got nan"),
    ([(("goal", "position"), [50, 10])], "goal: the robot collides with obstacles[0] (box)"),
    (
        [(("obstacles", 1), {"ellipsoid": {"center": [1, 2, 3], "semi_axes": [1, 1, 1]}})],
        "obstacles[1]: unknown obstacle type 'ellipsoid' ('ellipsoid' is a 3D obstacle)",
    ),
    (
        [(("obstacles", 2, "circle", "radius"), float("inf"))],
        "obstacles[2].circle.radius: expected a positive number",
    ),
    (
        [(("obstacles", 3, "polygon", "vertices"), [[0, 0], [1, 1], [2, 2]])],
        "obstacles[3].polygon.vertices: expected a polygon with at least 3 non-collinear vertices",
    ),
    (
        [(("obstacles", 3, "polygon", "vertices"), [[0, 0], [2, 2], [2, 0], [0, 2]])],
        "obstacles[3].polygon.vertices: expected a simple polygon, "
        "got edges 0 and 2 that intersect",
    ),
    (
        [(("obstacles", 3), {"box": {}, "circle": {}})],
        "obstacles[3]: expected a mapping with one key",
    ),
    ([(("obstacles",), {"box": 1})], "obstacles: expected a list of obstacles"),
    ([(("start", "position"), [10, True])], "start.position: expected 2 finite numbers"),
    (
        [(("obstacles", 0, "box", "size"), [1e300, 1])],  # FCL segfaults on such values
        "obstacles[0].box.size: expected 2 positive numbers (magnitude 1e-09 to 1e+09), "
        "got [1e+300, 1]",
    ),
]


@pytest.mark.parametrize("changes, message", BAD, ids=[m.split(":")[0] for _, m in BAD])
def test_invalid_fields_are_named(tmp_path, changes, message):
    path = write(tmp_path, mutated(changes))
    with pytest.raises(ScenarioError) as err:
        load_scenario(path)
    assert str(err.value) == f"{path}: {message}" or str(err.value).startswith(f"{path}: {message}")
    assert "\n" not in str(err.value)


def test_3d_fields(tmp_path):
    base = {
        "name": "t3",
        "dimension": 3,
        "bounds": {"low": [0, 0, 0], "high": [10, 10, 10]},
        "robot": {"semi_axes": [1, 0.5, 0.4]},
        "start": {"position": [1, 1, 1], "quaternion": [0, 0, 0, 1.004]},  # near unit: normalised
        "goal": {"position": [9, 9, 9]},
        "obstacles": [{"sphere": {"center": [5, 5, 5], "radius": 1}}],
    }
    s = load_scenario(write(tmp_path, base))
    assert np.linalg.norm(s.start[3:]) == pytest.approx(1.0) and s.goal[6] == 1.0
    bad = copy.deepcopy(base)
    bad["start"]["quaternion"] = [0, 0, 0, 2]
    with pytest.raises(
        ScenarioError, match=r"start.quaternion: expected a unit quaternion .* norm 2"
    ):
        load_scenario(write(tmp_path, bad))
    bad = copy.deepcopy(base)
    bad["start"]["yaw"] = 0.0
    with pytest.raises(
        ScenarioError, match="start: unknown key 'yaw'; expected one of position, quaternion"
    ):
        load_scenario(write(tmp_path, bad))
    bad = copy.deepcopy(base)
    bad["obstacles"] = [{"mesh": {"file": "nowhere/part.stl"}}]
    with pytest.raises(
        ScenarioError, match=r"obstacles\[0\].mesh.file: expected an existing mesh file"
    ):
        load_scenario(write(tmp_path, bad))
    (tmp_path / "junk.stl").write_bytes(b"\x00\x01binary junk")
    bad["obstacles"] = [{"mesh": {"file": "junk.stl"}}]
    with pytest.raises(
        ScenarioError, match=r"obstacles\[0\].mesh.file: expected a binary or ASCII STL"
    ):
        load_scenario(write(tmp_path, bad))


def test_file_level_errors(tmp_path):
    with pytest.raises(ScenarioError, match=r"x.yaml: line 2, column 6: YAML syntax error"):
        load_scenario(write(tmp_path, "name: x\n  bad: [\n"))
    with pytest.raises(ScenarioError, match="expected a UTF-8 YAML text file, got binary data"):
        path = tmp_path / "b.yaml"
        path.write_bytes(bytes(range(256)))
        load_scenario(path)
    with pytest.raises(ScenarioError, match="top level: expected a mapping"):
        load_scenario(write(tmp_path, "just a sentence\n"))
    with pytest.raises(ScenarioError, match="cannot read the file"):
        load_scenario(tmp_path / "missing.yaml")
    big = tmp_path / "big.yaml"
    big.write_bytes(b"#" * (16 * 2**20 + 1))
    with pytest.raises(ScenarioError, match="expected a scenario file of at most 16777216 bytes"):
        load_scenario(big)
    # a billion-laughs style alias bomb stays small in memory and fails on the schema
    bomb = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
        for p, c in zip("abcdefgh", "bcdefghi", strict=True)
    )
    with pytest.raises(ScenarioError, match="top level: unknown key"):
        load_scenario(write(tmp_path, bomb))


def test_cli_validate_and_show(tmp_path, capsys):
    assert main(["validate", *SUITE]) == 0
    out = capsys.readouterr().out
    assert out.count("ok ") == len(SUITE)
    bad = write(tmp_path, mutated([(("robot", "semi_axes"), [5, -1])]))
    assert main(["validate", SUITE[0], str(bad)]) == 2
    out, err = capsys.readouterr()
    assert f"INVALID {bad}: robot.semi_axes: expected 2 positive numbers, got [5, -1]" in out
    assert main(["show", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "robot.semi_axes" in err
    png = tmp_path / "s.png"
    assert main(["show", SUITE[0], "-o", str(png)]) == 0
    assert png.stat().st_size > 10_000


# ---------------------------------------------------------------- fuzz

leaves = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**6), 10**6),
    st.floats(allow_nan=True),
    st.text(max_size=8),
    st.just([]),
    st.just({}),
)
yamlish = st.recursive(
    leaves,
    lambda inner: st.one_of(
        st.lists(inner, max_size=5), st.dictionaries(st.text(max_size=10), inner, max_size=5)
    ),
    max_leaves=20,
)


def paths(data, prefix=()):
    yield prefix
    if isinstance(data, dict):
        for k, v in data.items():
            yield from paths(v, (*prefix, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield from paths(v, (*prefix, i))


ALL_PATHS = [p for p in paths(VALID) if p]


@settings(max_examples=300)
@given(st.sampled_from(ALL_PATHS), yamlish)
def test_fuzz_replaced_fields_give_scenario_errors(path, value):
    data = copy.deepcopy(VALID)
    target = data
    for k in path[:-1]:
        target = target[k]
    target[path[-1]] = value
    try:
        parse_scenario(data, "fuzz.yaml")
    except ScenarioError as err:
        assert str(err).startswith("fuzz.yaml: ") and "\n" not in str(err)


@settings(max_examples=200)
@given(st.text(max_size=200))
def test_fuzz_random_text_gives_scenario_errors(tmp_path_factory, text):
    path = tmp_path_factory.mktemp("fuzz") / "f.yaml"
    path.write_text(text)
    with pytest.raises(ScenarioError):
        load_scenario(path)


# ---------------------------------------------------------------- polygons


@st.composite
def star_polygons(draw):
    k = draw(st.integers(3, 20))
    gaps = [draw(st.floats(0.1, 1.0)) for _ in range(k)]
    angles = np.cumsum(gaps) / sum(gaps) * 2 * np.pi
    if np.max(np.diff(np.append(0.0, angles))) >= np.pi * 0.98:
        angles = np.arange(k) * 2 * np.pi / k
    radii = np.array([draw(st.floats(0.2, 1.0)) for _ in range(k)]) * draw(st.floats(0.1, 100))
    return np.column_stack([np.cos(angles), np.sin(angles)]) * radii[:, None]


@settings(max_examples=200)
@given(star_polygons())
def test_convex_pieces_cover_the_polygon(V):
    try:
        pieces = convex_pieces(V)
    except ValueError as err:
        assert "expected" in str(err)
        return
    total = sum(polygon_area(p) for p in pieces)
    assert total == pytest.approx(abs(polygon_area(V)), rel=1e-9)
    for p in pieces:
        e1, e2 = np.roll(p, -1, 0) - p, np.roll(p, -2, 0) - np.roll(p, -1, 0)
        turn = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
        assert (turn >= -1e-9 * np.ptp(V) ** 2).all()  # convex, counter-clockwise
    if len(V) > 3:
        assert len(pieces) <= len(V) - 2  # no more pieces than a triangulation


def test_c_shape_decomposes_into_few_pieces():
    c_shape = [
        [35, 20],
        [65, 20],
        [65, 60],
        [35, 60],
        [35, 46],
        [39, 46],
        [39, 56],
        [61, 56],
        [61, 24],
        [39, 24],
        [39, 34],
        [35, 34],
    ]
    pieces = convex_pieces(c_shape)
    assert 3 <= len(pieces) <= 6
    assert sum(polygon_area(p) for p in pieces) == pytest.approx(30 * 40 - 22 * 32 - 4 * 12)
    assert math.isclose(polygon_area(c_shape[::-1]), -polygon_area(c_shape))
