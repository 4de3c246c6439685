"""Fuzzing the real ``kcplan`` command line: random and malformed arguments and files.

Every subcommand is driven in-process through :func:`kcplan.cli.main` (an uncaught
exception fails the test with its traceback) with arguments drawn from its own options,
valid and broken scenario and path files, missing folders and nonsense values. Each call
must end with exit code 0, 1, 2 or 130, print one line per error, and leave no partial
or temporary file behind.
"""

import contextlib
import io
import json
import tempfile
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kcplan.cli import main

ROOT = Path(__file__).resolve().parent.parent
GOOD_2D = str(ROOT / "scenarios" / "2d" / "l_robot_door.yaml")
GOOD_3D = str(ROOT / "scenarios" / "3d" / "window_wall.yaml")

# options per subcommand, with a strategy for the value of each (None: a flag)
numbers = st.sampled_from(["0", "-1", "1", "0.01", "nan", "inf", "1e400", "x", "", "3"])
OPTIONS = {
    "bounds": {"--semi-axes": numbers, "--inflation": numbers, "--json": None, "--plot": "png"},
    "validate": {},
    "show": {"-o": "png"},
    "plan": {
        "--planner": st.sampled_from(["kc-rrtconnect", "rrtconnect", "kc-prm-paper", "x"]),
        "--time": st.sampled_from(["0.02", "0", "-1", "nan", "x"]),
        "--seed": numbers,
        "-o": "json",
        "--plot": "png",
        "--animate": "gif",
        "--guards": None,
        "--no-simplify": None,
    },
    "verify": {"--tolerance": numbers},
    "bench": {
        "--planners": st.sampled_from(["rrtconnect", "", "x,y", "kc-prm,,"]),
        "--runs": st.sampled_from(["0", "-2", "x", "1"]),
        "--time": st.sampled_from(["0.01", "0", "x"]),
        "--jobs": st.sampled_from(["1", "0", "x"]),
        "-o": "dir",
    },
    "pick-place": {
        "--sigma-deg": st.sampled_from(["-1", "x", "nan", "0.1"]),
        "--trials": st.sampled_from(["0", "1", "x"]),
        "--poses": st.sampled_from(["0", "2", "x"]),
        "-o": "dir",
    },
    "import": {},
}
POSITIONAL = {
    "bounds": 0,
    "validate": 1,
    "show": 1,
    "plan": 1,
    "verify": 2,
    "bench": 1,
    "pick-place": 0,
    "import": 0,
}
BROKEN = [
    "",
    "name: [",
    "- 1\n- 2",
    "name: x\ndimension: 2\nbounds: {low: [0, 0], high: [1, 1]}\nrobot: {bodies: []}\n",
    "\x00\x01binary",
    json.dumps({"states": [[0, 0]]}),
    json.dumps({"states": "no"}),
    "{}",
    "name: x\ndimension: 4\n",
]


@st.composite
def command_lines(draw, folder: Path) -> tuple[list[str], list[Path]]:
    """A command line and the output paths it names."""
    command = draw(st.sampled_from(sorted(OPTIONS)))
    argv, outputs = [command], []

    def a_file() -> str:
        kind = draw(st.sampled_from(["good2", "good3", "missing", "broken", "folder"]))
        if kind == "good2":
            return GOOD_2D
        if kind == "good3":
            return GOOD_3D
        if kind == "missing":
            return str(folder / "missing.yaml")
        if kind == "folder":
            return str(folder)
        path = folder / f"broken{draw(st.integers(0, 99))}.yaml"
        path.write_text(draw(st.sampled_from(BROKEN)), errors="surrogateescape")
        return str(path)

    def an_output(suffix: str) -> str:
        where = draw(st.sampled_from(["here", "nofolder", "wrongsuffix"]))
        base = folder / "out" if where == "here" else folder / "no" / "such"
        name = {"png": "x.png", "gif": "x.gif", "json": "x.json", "dir": "results"}[suffix]
        if where == "wrongsuffix" and suffix != "dir":
            name = "x.txt"
        path = base / name
        outputs.append(path)
        return str(path)

    if command == "import":
        source = draw(st.sampled_from(["hrm", "movingai", "nope"]))
        argv += [source, a_file()]
        if source == "hrm":
            argv += ["--map", draw(st.sampled_from(["maze", "x", ""]))]
            if draw(st.booleans()):
                argv += ["--robot", draw(st.sampled_from(["rabbit", "cat"]))]
        argv += ["-o", an_output("json" if draw(st.booleans()) else "png")]
        return argv, outputs
    argv += [a_file() for _ in range(POSITIONAL[command])]
    names = sorted(OPTIONS[command])
    for option in draw(st.lists(st.sampled_from(names), max_size=4)) if names else []:
        value = OPTIONS[command][option]
        argv.append(option)
        if isinstance(value, str):
            argv.append(an_output(value))
        elif value is not None:
            argv.append(draw(value))
    if command == "plan" and "--time" not in argv:
        argv += ["--time", "0.05"]
    if command == "pick-place":
        argv += ["--trials", "1", "--poses", "2", "--sigma-deg", "0.1"]
    if command == "bench":
        argv += ["--runs", "1", "--time", "0.01", "--planners", "rrtconnect"]
    if draw(st.integers(0, 9)) == 0:
        argv.append(draw(st.sampled_from(["--frobnicate", "-x", "--", "extra"])))
    return argv, outputs


@settings(
    max_examples=100,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_every_command_line_ends_cleanly(data, tmp_path):
    folder = Path(tempfile.mkdtemp(dir=tmp_path))  # a fresh folder per example
    (folder / "out").mkdir()
    argv, outputs = data.draw(command_lines(folder))
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exit_:  # --help / --version
            code = exit_.code
    assert code in (0, 1, 2, 130), (argv, code, err.getvalue())
    assert "Traceback" not in out.getvalue() + err.getvalue()
    if code == 2:
        message = err.getvalue().strip().splitlines()
        assert len(message) == 1, (argv, err.getvalue())
        for path in outputs:
            assert not path.is_file(), (argv, path)  # bad input writes nothing
    leftovers = [p for p in folder.rglob("*") if ".tmp" in p.name or p.name.startswith(".")]
    assert not leftovers, (argv, leftovers)
