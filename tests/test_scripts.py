"""Every script in ``scripts/`` runs, with its smallest arguments, and prints what it should.

The scripts are not imported by the package or its tests otherwise, so a renamed method
would only break them when someone next runs them; here each is run in a subprocess
(``sys.executable``, from the repository root) and its output checked. A new script
without a case here fails :func:`test_every_script_has_a_case`.
"""

from __future__ import annotations

import functools
import importlib.util
import json
import os
import re
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from kcplan.certification.certifier import CERTIFICATE_SETS

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = ROOT / "scripts"
HRM = ROOT.parent / "shared" / "data" / "external" / "hrm" / "resources"
CORRIDOR = "scenarios/2d/narrow_corridor.yaml"
NUMBER = r"-?\d+(?:\.\d+)?"
HAVE_VAMP = importlib.util.find_spec("vamp") is not None  # an optional peer (issue 25)


@dataclass(frozen=True)
class Case:
    """One run of a script: its arguments (``{tmp}``: a fresh folder, ``{hrm}``: the HRM
    data), regular expressions its standard output must match, and files it must write."""

    script: str
    args: tuple[str, ...] = ()
    expect: tuple[str, ...] = ()
    files: tuple[str, ...] = ()
    hrm: bool = False  # needs the HRM data (run with --help alone when it is absent)
    check: Callable[[str, Path], None] | None = field(default=None, compare=False)


def _same_suite(_out: str, tmp: Path) -> None:
    """make_scenarios is deterministic: it writes the committed suite again (the sensed
    scenes, ``*_cloud.yaml``, are make_cloud_scenarios.py's)."""
    committed = sorted(
        p.relative_to(ROOT / "scenarios")
        for p in ROOT.glob("scenarios/[23]d/*.yaml")
        if not p.stem.endswith("_cloud")
    )
    written = sorted(p.relative_to(tmp) for p in tmp.glob("[23]d/*.yaml"))
    assert written == committed
    for rel in committed:
        assert (tmp / rel).read_text() == (ROOT / "scenarios" / rel).read_text(), rel


def _same_covers(out: str, _tmp: Path) -> None:
    """Khachiyan's rank-one updates and the kernel's iteration take the textbook
    iteration's steps: the same covers."""
    rows = re.findall(r"^\| (\S+) \| \d+ \| .* \| ([\d.]+) \| ([\d.]+) \| ([\d.]+) \|$", out, re.M)
    assert rows and all(len(set(volumes)) == 1 for _, *volumes in rows), rows


def _never_looser(out: str, _tmp: Path) -> None:
    """The vertices' trees only add trees to choose from: never a looser cover than the
    curvature's alone, beyond the Monte Carlo's 95 % intervals."""
    rows = re.findall(
        r"^\| \S+ \| \d+ \| ([\d.]+) \+- ([\d.]+) \| ([\d.]+) \+- ([\d.]+) \|", out, re.M
    )
    assert rows, out
    for alone, e0, both, e1 in (map(float, row) for row in rows):
        assert both <= alone + e0 + e1, (alone, both)


def _no_violation(out: str, _tmp: Path, names=tuple(CERTIFICATE_SETS)) -> None:
    rows = re.findall(r"^\| ([23]D) \| ([\w-]+) \| 50 \| (\d+) \| (\d+) \| (\d+) \|$", out, re.M)
    assert {(n, name) for n, name, *_ in rows} == {
        (n, name) for n in ("2D", "3D") for name in names
    }
    assert all(int(violations) == 0 for *_, violations, _ in rows), rows


def _coal_report(out: str, _tmp: Path) -> None:
    report = json.loads(out.strip().splitlines()[-1])
    assert report["samples"] > 0 and report["violations"] == 0, report


PAPER_FILES = (
    "table1_confusion.csv",
    "eq38_extreme_rotation.csv",
    *(
        f"{name}.{ext}"
        for name in (
            "fig7_volumes_2d_inflation",
            "fig8_volumes_2d_aspect",
            "fig9_volumes_3d_inflation",
            "fig10_volumes_3d_aspect",
        )
        for ext in ("csv", "png")
    ),
)

CASES = [
    Case(
        "bench_queries.py",
        (CORRIDOR, "--poses", "50", "--blocks", "1"),
        (
            r"kernel collision us\s+kernel distance us\s+kernel region us",
            rf"narrow_corridor\s+2\s+{NUMBER}\s+{NUMBER}\s+{NUMBER}\s+{NUMBER}"
            rf"\s+{NUMBER}\s+{NUMBER}$",
        ),
    ),
    *(
        Case(
            "bisection_cost.py",
            (CORRIDOR, "--edges", "30", "--plot", "{tmp}/cost.png", "--backend", backend),
            (
                r"\| scenario \| edge length / extent",
                r"\| narrow_corridor \| 0\.2 \| \[[\d.]+, [\d.inf]+\) \| \d+ \| \d+% "
                r"\| \d+ \| \d+ \|",
                r"plot written to",
            ),
            ("cost.png",),
        )
        for backend in ("kernel", "python")
    ),
    Case(
        "coal_distance_error.py",
        ("--samples", "200"),
        (r"\| halfspace aligned 3D \|",),
        check=_coal_report,
    ),
    Case(
        "cover_tightness.py",
        ("--meshes", "scenarios/3d/meshes/l_bracket.stl", "--bodies", "1,2", "--samples")
        + ("20000", "--timing", "1", "--timing-mesh", "scenarios/3d/meshes/rock.stl")
        + ("--profiles", "u_channel", "--out", "{tmp}"),
        (
            rf"^\| meshes/l_bracket\.stl \| 20 \| 2 \| {NUMBER} \+- {NUMBER} \| {NUMBER} "
            rf"\+- {NUMBER} \| {NUMBER} \| {NUMBER} \|$",
            rf"^\| generated/u_channel\.stl \| 44 \| 2 \| {NUMBER} \+- {NUMBER} ",
            rf"^\| meshes/rock\.stl x16 \| 320 \| 1 \| {NUMBER} \|$",
        ),
        ("cover.md", "cover.csv", "cover.png"),
    ),
    Case(
        "fit_time.py",
        ("--meshes", "scenarios/3d/meshes/l_bracket.stl", "--profiles", "", "--bodies", "2"),
        (
            rf"^\| meshes/l_bracket\.stl \| 2 \| {NUMBER} \| {NUMBER} \| {NUMBER} "
            rf"\| {NUMBER} \| {NUMBER} \| {NUMBER} \| {NUMBER} \| {NUMBER} \|$",
            rf"^\| all \| \| {NUMBER} \| {NUMBER} \| {NUMBER} \| {NUMBER} \| {NUMBER} \| \| \| \|$",
        ),
        check=_same_covers,
    ),
    Case(
        "vertex_cuts.py",
        ("--meshes", "scenarios/3d/meshes/l_bracket.stl", "--profiles", "", "--bodies", "2"),
        (
            rf"^\| meshes/l_bracket\.stl \| 2 \| {NUMBER} \+- {NUMBER} \| {NUMBER} \+- {NUMBER} "
            rf"\| {NUMBER} \| {NUMBER} \| {NUMBER} \|$",
            rf"^\| all \| \| \| \| {NUMBER} \| {NUMBER} \| {NUMBER} \|$",
        ),
        check=_never_looser,
    ),
    Case(
        "mbm_validity.py",
        ("--per-class", "1", "--hulls", "--bodies", "1", "--offsets"),
        (
            r"^700 problems read in ",
            r"^\| hulls \| box \| 1 \| 1 / 1 \| 1 / 1 \| 0 \|$",
            r"^\| panda_hand_0 \| [1-9]\d* \|$",
            r"^\| 1 \| box \| 1 \| [01] / 1 \| [01] / 1 \| [012] \|$",
            r"^\| 1 \| all \| 7 \| \d / 7 \| \d / 7 \| \d+ \|$",
        ),
    ),
    Case(
        "arm_soundness.py",
        ("--edges", "14", "--per-class", "1", "--bodies", "1", "--twin", "4")
        + ("--free-check", "1"),
        (
            r"^\| robot \| backend \| edges \| accepted \| violations \| rejected: end state ",
            r"^\| panda \| kernel \| 14 \| \d+ \| 0 \| \d+ / \d+ / \d+ / \d+ \| ",
            r"^\| panda \| python \| 4 \| \d+ \| 0 \| ",
            r"KC inflation 0.2: \d+ KC guards asked, \d+ took a body farther than its ball; "
            r"planes: \d+ took a body farther$",
            rf"mesh verification {NUMBER} ms per edge",
        ),
    ),
    Case(  # on hulls, holding a part between the fingers
        "arm_soundness.py",
        ("--edges", "8", "--per-class", "1", "--representation", "hulls", "--attach", "cylinder")
        + ("--twin", "3"),
        (
            r"^\| panda \| kernel \| 8 \| \d+ \| 0 \| ",
            r"^\| panda \| python \| 3 \| \d+ \| 0 \| ",
            r"arm of 7 joints, 12 bodies",
            r"; planes: \d+ took a body farther$",
        ),
    ),
    Case(  # a base that drives (issue 57): the scenes of scenarios, the PR2's doorway
        "arm_soundness.py",
        ("--robot", "pr2", "--scenarios", str(ROOT / "scenarios/arm/example_pr2_doorway.yaml"))
        + ("--edges", "6", "--representation", "hulls", "--graze", "0.5"),
        (
            r"^\| pr2 \| kernel \| 6 \| \d+ \| 0 \| ",
            r"1 problems \(scenarios example_pr2_doorway\.yaml\), arm of 11 joints, 70 bodies ",
        ),
    ),
    Case(  # against point clouds (issue 55): filtered for the certifier, re-checked raw
        "arm_soundness.py",
        ("--edges", "14", "--per-class", "1", "--representation", "hulls", "--cloud", "100")
        + ("--spacing", "0.02", "--graze", "0.5", "--no-probes", "--cloud-tolerance", "0.5"),
        (
            r"^\| panda \| kernel \| 14 \| \d+ \| 0 \| ",
            r"^- grazing \(--graze 0.5\): \d+ edges cut short to end near an invalid state, ",
            rf"^- smallest distance the mesh re-check measured on an accepted edge: {NUMBER}",
            r"^\| robot \| scenes \| points per scene \| filter \| kept for the certifier \| ",
            rf"^\| panda \| 7 \| [\d,]+ \([\d,]+-[\d,]+\) \| voxel 0.02 \| [\d,]+ \({NUMBER} %\) "
            rf"\| 0.0225 / 0.0025 \| 14 \| ([1-9]\d*) \| \1 \| 0 \| {NUMBER}(?:e-\d+)? "
            r"\| \d+ / \d+ \|$",
            r"^- 100 surface points per object, seed 1; every accepted edge re-checked on the ",
            r"; planes: \d+ took a body farther; no probes \(the lazy compiled planner's path ",
            r" within a relative tolerance of 0\.5$",
        ),
    ),
    Case(
        "edge_outcomes.py",
        (CORRIDOR, "kc-rrtconnect", "1,2", "--probes", "1", "--time", "5"),
        (
            r"^seed 1: solved True in ",
            rf"^\| certified after guards \| [1-9]\d* \| {NUMBER} \| {NUMBER} \| [1-9]\d* \|",
            rf"^\| rejected_end_state \| [1-9]\d* \| {NUMBER} \| {NUMBER} \| 0 \| [1-9]\d* \|$",
        ),
    ),
    Case(
        "compare_validators.py",
        (CORRIDOR, "--runs", "1", "--time", "2"),
        tuple(
            rf"\| narrow_corridor \| {name} \| 1/1 \| {NUMBER} \| \d+ \| 0 \|"
            for name in ("kc-rrtconnect", "kc-prm")  # solved, and no colliding path
        )
        + (r"\| narrow_corridor \| rrtconnect \|", r"\| narrow_corridor \| prm \|"),
    ),
    *(
        Case(
            "edge_cost.py",
            (CORRIDOR, planner, "1", "--poses", "200", "--time", "5"),
            (
                rf"^\| narrow_corridor \| {planner} \| 1 \| {NUMBER} \| [1-9]\d* \| [1-9]\d* "
                rf"\| {NUMBER} \| {NUMBER} \| ({NUMBER}|-) \|$",
            ),
        )
        for planner in ("kc-rrtconnect", "kc-rrtconnect-py")
    ),
    Case(
        "arm_edge_cost.py",
        ("scenarios/arm/table_pick_1.yaml", "--seed", "1", "--time", "5"),
        (
            r"^table_pick_1, kc-rrtconnect, seed 1: solved in ",
            rf"^\| certified \| [1-9]\d* \| {NUMBER} \| {NUMBER} \| \d+% \|$",
            rf"^\| state \| [1-9]\d* \| {NUMBER} \| {NUMBER} \| \d+% \|$",
            r"^guards per edge [\d.]+, probes per edge [\d.]+, ",
        ),
    ),
    Case(
        "arm_edge_cost.py",
        ("scenarios/arm/box_1.yaml", "--seed", "2", "--time", "5", "--planner")
        + ("kc-rrtconnect-lazy",),
        (
            r"^box_1, kc-rrtconnect-lazy, seed 2: solved in ",
            rf"^\| screened \| [1-9]\d* \| {NUMBER} \| {NUMBER} \| \d+% \|$",
        ),
    ),
    Case(
        "hrm_settings_check.py",
        ("--hrm", "{hrm}"),
        (r"\| map \| robot \|", r"\| sparse \| \w+ \| [^|]+ \| [^|]+ \| (yes|no) \|"),
        hrm=True,
    ),
    Case(
        "import_real_maps.py",
        ("--hrm", "{hrm}", "--out", "{tmp}", "--maps", "hrm_ellipse_sparse_2d"),
        (r"hrm_ellipse_sparse_2d\.yaml: .*2D, \d+ obstacles",),
        ("hrm_ellipse_sparse_2d.yaml",),
        hrm=True,
    ),
    Case(
        "make_scenarios.py",
        ("--out", "{tmp}", "--no-pictures"),
        (r"2d/narrow_corridor\.yaml: \d+ obstacles", r"3d/box_field\.yaml: \d+ obstacles"),
        ("3d/meshes/rock.stl",),
        check=_same_suite,
    ),
    *(
        Case(
            "map_scaling.py",
            ("--counts", "10", "--edges", "50", "--runs", "1", "--time", "5", "--backend", b),
            (
                rf"\| map \| FCL objects \| .* \| {certified} \[s\] \| {stock} \[s\] \|",
                rf"\| clutter 10 \| 10 \| {NUMBER} \| \d+ \| {NUMBER} \|",
                r"\| movingai maze-128 \| \d+ \|",
            ),
        )
        for b, certified, stock in (
            ("kernel", "kc-rrtconnect", "rrtconnect"),
            ("python", "kc-rrtconnect-py", "rrtconnect-fcl"),
        )
    ),
    Case(
        "mesh_robot_paths.py",
        ("--runs", "1", "--time", "5", "--planners", "kc-rrtconnect"),
        (
            r"4 ellipsoids covering panda_hand\.stl",
            rf"^\| kc-rrtconnect \| 1/1 \| {NUMBER} "
            rf"\| {NUMBER} \| 0 \| 0 \| {NUMBER} \|$",
        ),  # fmt: skip
    ),
    Case(
        "own_setup_example.py",
        (),
        (r"solved: \d+ states", r"verified: free", r"validator counters"),
    ),
    Case(
        "planner_settings.py",
        (CORRIDOR, "--runs", "1", "--ranges", "0.2", "--neighbors", "10", "--time", "2"),
        (
            rf"\| narrow_corridor \| kc-rrtconnect \| range 0\.2 \| 1/1 \| {NUMBER} \| \d+ \|",
            rf"\| narrow_corridor \| kc-prm \| k = 10 \| 1/1 \| {NUMBER} \| \d+ \|",
            r"\| narrow_corridor \| rrtconnect \| range 0\.2 \|",
        ),
    ),
    Case(
        "planner_table.py",
        ("--runs", "1", "--time", "2", "--jobs", "1", "--maps", CORRIDOR)
        + ("--planners", "rrtconnect"),
        (
            r"\| planner \| narrow_corridor: solved, median s \|",
            rf"\| `kc-rrtconnect` \| 1/1, {NUMBER} \|",  # no "(1 colliding)"
            r"\| `rrtconnect` \| \d/1, ",
        ),
    ),
    Case(
        "reproduce_paper.py",
        ("--out", "{tmp}", "--points", "1", "--samples", "1000"),
        files=PAPER_FILES,
    ),
    *(
        Case(
            "soundness_study.py",
            ("--edges", "50", "--backend", backend, *extra),
            (r"\| dimension \| certificates \| edges \|",),
            check=_no_violation,
        )
        for backend, extra in (
            ("kernel", ()),
            ("python", ()),
            ("kernel", ("--arena",)),  # 3D worlds inside a convex mesh
        )
    ),
    Case(  # robots of 3 offset bodies: the arc rule; no paper polytope for them
        "soundness_study.py",
        ("--edges", "50", "--bodies", "3"),
        (r"\| dimension \| certificates \| edges \|",),
        check=functools.partial(
            _no_violation, names=[k for k, v in CERTIFICATE_SETS.items() if "polytope" not in v]
        ),
    ),
]


def _vamp_problems(out: str, _tmp: Path) -> None:
    """vamp_mbm.py --step read: the first problem of each MBM class, as plain data."""
    problems = json.loads(out)
    assert [(p["class"], p["index"]) for p in problems] == [
        (c, 1) for c in ("table_pick", "table_under_pick", "box", "bookshelf_small",
                         "bookshelf_tall", "bookshelf_thin", "cage")
    ]  # fmt: skip
    assert all(len(p["start"]) == len(p["goal"]) == 7 and p["obstacles"] for p in problems)
    assert {o["kind"] for p in problems for o in p["obstacles"]} == {"box", "cylinder"}


CASES.append(
    Case(
        "vamp_mbm.py",
        ("--per-class", "1", "--calls", "1"),
        (r"^\| all \| 7 \| \d \| \d \| [\d.]+ \| [\d.]+ \| \d of \d \|$",),
    )
    if HAVE_VAMP  # VAMP built into this environment: the whole run
    else Case("vamp_mbm.py", ("--step", "read", "--per-class", "1"), check=_vamp_problems)
)

CASES.append(
    Case(  # needs example-robot-data (the dev extra has it)
        "make_example_arm_scenarios.py",
        ("--arms", "ur3", "-o", "{tmp}"),
        (r"example_ur3\.yaml: reach 0\.7\d+ m, solved in ",),
        ("example_ur3.yaml",),
    )
)

CASES.append(
    Case(  # needs example-robot-data (the dev extra has it)
        "make_whole_body_problems.py",
        (str(ROOT / "scenarios" / "arm" / "example_pr2_doorway.yaml"), "--problems", "1",
         "--across", "world_joint/x", "-o", "{tmp}"),  # fmt: skip
        (r"pr2_doorway_1\.yaml$",),
        ("pr2_doorway_1.yaml",),
    )
)

CASES.append(
    Case(
        "bench_totals.py",
        (str(ROOT / "benchmarks" / "whole-body" / "pr2-bench" / "summary.csv"),),
        (r"^\| kc-rrtconnect-lazy-native \| 10 \| 50 / 50 \| [\d.]+ \| 0 \|$",
         r"^\| rrtconnect-32 \| 10 \| 50 / 50 \| [\d.]+ \| \d+ \|$"),  # fmt: skip
    )
)

CASES.append(
    Case(
        "pair_proofs.py",
        ("--robot", "panda", "--max-boxes", "400"),
        (
            r"^\| robot \| links \| pairs \(no SRDF\) \| proven apart \| touch \| unknown ",
            r"^\| panda \| 11 \| 40 \| \d+ \| \d+ \| \d+ \| 21 \| 0 \| 19 \| [01] \| [\d.]+ \|$",
        ),
    )
)

CASES.append(
    Case(  # the default representation (the links' hulls), as the bundled scenarios'
        "mbm_bench.py",
        ("--per-class", "1", "--classes", "table_pick", "--padding", "0.005")
        + ("--planners", "kc-rrtconnect-native,rrtconnect", "--time", "2", "-o", "{tmp}"),
        (  # every path verified at least 5 mm from the objects (robot.padding)
            r"^\| class \| problems \| invalid for the cover or nearer than 0\.005 m \| "
            r"kc-rrtconnect-native solved \| ",
            rf"^\| table_pick \| 1 \| 0 \| 1 / 1 \| {NUMBER} \| 0 \| 1 / 1 \| {NUMBER} \| 0 \|$",
            rf"^\| all \| 1 \| 0 \| 1 / 1 \| {NUMBER} \| 0 \| 1 / 1 \| {NUMBER} \| 0 \|$",
        ),
        ("mbm_table.md", "bench/summary.csv", "scenarios/table_pick_1.yaml"),
    )
)


CASES.append(
    Case(  # one problem, one random corner: the table and a blend re-checked on the meshes
        "trajectory_bench.py",
        ("--per-class", "1", "--classes", "box", "--corners", "1", "--time", "5") + ("-o", "{tmp}"),
        (
            r"^\| class \| solved / valid \| plan, median s \| smooth \+ time, median s \| ",
            rf"^\| box \| 1 / 1 \| {NUMBER} \| {NUMBER} \| 0\.\d\d \| (0\.\d+|1\.000000), "
            rf"(0\.\d+|1\.000000) \| 0 \| 1, 0, [01] \|$",
        ),
        ("trajectory_table.md", "rows.json", "scenarios/box_1.yaml"),
    )
)


CASES.append(
    Case(  # one table_pick problem: reach, carry the can, return; the view of all three
        "pick_place_mbm.py",
        ("--problems", "1", "--time", "5", "--html", "{tmp}/sequence.html", "-o", "{tmp}"),
        (
            r"^\| problem \| turn \(rad\) \| reach: solved, s \| carry: solved, s \| ",
            rf"^\| table_pick_1 \| [+-]\d\.\d \| yes, {NUMBER} \| yes, {NUMBER} \| yes, "
            rf"{NUMBER} \| 0 \|$",
            r"^\| \*\*all\*\* \| 1 of 1 with a place \| sequences solved 1 / 1 \| ",
        ),
        ("pick_place_table.md", "sequence.html", "scenarios/table_pick_1_carry.yaml"),
    )
)


CASES.append(
    Case(  # the sensed scenes, sparser: each planned and its path verified on the points
        "make_cloud_scenarios.py",
        ("--points", "1500", "-o", "{tmp}"),
        (
            r"^box_1_cloud\.yaml: solved in .* 10,500 points read, 10,500 kept \(planned with "
            r"radius 0\.0025, the point radius\)$",
            r"^table_pick_1_depth\.yaml: solved in .*\(320x240 depth image\): [\d,]+ points read, "
            r"[\d,]+ on the robot dropped, [\d,]+ kept",
            r"^box_field_cloud\.yaml: solved in .* 6,000 points read, 6,000 kept",
        ),
        ("arm/box_1_cloud.yaml", "arm/clouds/table_pick_1_depth.png", "3d/clouds/box_field.ply"),
    )
)


CASES.append(
    Case(  # KC vs the clearance ball on one scene and its cloud, each path verified
        "cloud_kc_ablation.py",
        ("--scenes", "peg_in_hole", "--hrm-maps", "--runs", "1", "--time", "5")
        + ("--spacing", "1", "--work", "{tmp}"),
        (
            r"^\| scene \| obstacles \(primitives / points\) \| primitives: kc solved, ",
            rf"^\| peg_in_hole \| 5 \(5 box\) / [\d,]+ \| 1/1, {NUMBER}(?:e-\d+)? s, [\d,]+ \| "
            rf"1/1, {NUMBER}(?:e-\d+)? s, [\d,]+ \| {NUMBER} \| 1/1, .* \| {NUMBER} \|$",
            r"^- colliding paths: 0 of 4 returned paths, .* failed runs: 0 of 4$",
        ),
        ("runs.jsonl", "peg_in_hole_points.yaml", "clouds/peg_in_hole.ply"),
    )
)


CASES.append(
    Case(  # one seed on the depth scene: every setting solves, the bare tree measures more
        "cloud_bounds.py",
        ("--seeds", "1", "scenarios/arm/table_pick_1_depth.yaml"),
        (
            r"^\| scenario \| bounds \| solved \| solve, median ms \| ",
            rf"^\| table_pick_1_depth \| all \| 1 / 1 \| {NUMBER} \| {NUMBER} \| ",
            rf"^\| table_pick_1_depth \| none \| 1 / 1 \| {NUMBER} \| {NUMBER} \| ",
        ),
    )
)


TIMES = rf"{NUMBER} \| {NUMBER} \| {NUMBER}"  # solve, shortcuts, planning (ms)
CASES.append(
    Case(  # the cloud's distance exact and at a tolerance, and the primitives: all solve
        "cloud_tolerance.py",
        ("--problems", "table_pick:1", "--seeds", "1", "--tolerances", "0,0.25")
        + ("--json", "{tmp}/tolerance.json"),
        (
            r"^\| setting \| solved \| solve ms \| shortcuts ms \| planning ms \| ",
            rf"^\| cloud, tolerance 0 \| 1/1 \| {TIMES} \| \d+ \| \d+ \| 1\.00 \| ",
            rf"^\| cloud, tolerance 0\.25 \| 1/1 \| {TIMES} \| \d+ \| \d+ \| ",
            rf"^\| primitives \| 1/1 \| {TIMES} \| 0 \| 0 \| {NUMBER} \| 1\.00 \|$",
        ),
        ("tolerance.json",),
    )
)


CASES.append(
    Case(  # the cloud tree's two orders: both build, both plan the same problem
        "cloud_tree_order.py",
        ("--sizes", "1000", "--repeats", "1", "--per-class", "1", "--classes", "table_pick")
        + ("--seeds", "1"),
        (
            rf"^\| 1,000 \| {NUMBER} / {NUMBER} \| {NUMBER} / {NUMBER} \|$",
            rf"^\| table_pick 1 \| 120,000 \| morton \| 1 / 1 \| {NUMBER} \| ",
            rf"^\| table_pick 1 \| 120,000 \| median \| 1 / 1 \| {NUMBER} \| ",
        ),
    )
)


CASES.append(
    Case(  # kcplan's half on one small MBM cloud (VAMP's needs its own build): planned on
        # the cloud and on the primitives, every path verified on the meshes
        "cloud_mbm.py",
        ("--per-class", "1", "--classes", "table_pick", "--points-per-object", "300")
        + ("--no-vamp", "--time", "5", "--json", "{tmp}/cloud_mbm.json"),
        (
            rf"^\| table_pick \| 1 \| 3600 \| 1 / - \| {NUMBER} \| {NUMBER} \| {NUMBER} \| ",
            r"\| 0/1 / - \| 0/1 / - \|$",
            r"^- every problem solved, no colliding path$",
        ),
        ("cloud_mbm.json",),
    )
)


@pytest.mark.skipif(HAVE_VAMP, reason="VAMP is installed here")
def test_vamp_mbm_without_vamp_says_how_to_build_it():
    proc = subprocess.run(
        [sys.executable, str(SCRIPTS / "vamp_mbm.py"), "--per-class", "1"],
        cwd=ROOT, capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert proc.returncode == 2 and proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("vamp_mbm.py: VAMP is not installed in ")
    assert "bash ../shared/tools/vamp/build-vamp.sh PYTHON" in lines[0]


def test_vamp_mbm_verifies_paths_on_the_meshes():
    """kcplan's half of vamp_mbm.py: a path that stays at the start is clean on the meshes,
    one reaching into the objects collides, an unsolved problem has no verdict."""
    import numpy as np

    from kcplan.arm.mbm import read_mbm_archive

    archive = ROOT.parent / "shared" / "data" / "external" / "mbm" / "panda" / "problems.tar.bz2"
    start = read_mbm_archive(archive, "table_pick", 1).start
    down = start.copy()
    down[0], down[1], down[3] = 1.17, 1.3, -1.0  # reaching into the objects at y ~ 1 m
    results = [
        {"class": "table_pick", "index": 1, "solved": True, "path": [start.tolist()] * 2},
        {"class": "table_pick", "index": 1, "solved": True,
         "path": [start.tolist(), np.asarray(down).tolist()]},
        {"class": "box", "index": 1, "solved": False, "path": []},
    ]  # fmt: skip
    proc = subprocess.run(
        [sys.executable, str(SCRIPTS / "vamp_mbm.py"), "--step", "verify"],
        input=json.dumps({"results": results}), cwd=ROOT, capture_output=True, text=True,
        timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-4000:]
    verdicts = json.loads(proc.stdout)
    assert [v["collides"] for v in verdicts] == [False, True, None]
    assert verdicts[0]["min_clearance"] > 0.0 and verdicts[1]["where"][0] == 0


def test_every_script_has_a_case():
    assert {case.script for case in CASES} == {p.name for p in SCRIPTS.glob("*.py")}


def _id(case: Case) -> str:
    backend = [case.args[i + 1] for i, a in enumerate(case.args) if a == "--backend"]
    planner = [a for a in case.args if a.startswith("kc-")]
    return "-".join([case.script.removesuffix(".py"), *backend, *planner])


@pytest.mark.parametrize("case", CASES, ids=_id)
def test_script_runs(case: Case, tmp_path):
    help_only = case.hrm and not HRM.is_dir()
    args = (
        ["--help"]
        if help_only
        else [a.replace("{tmp}", str(tmp_path)).replace("{hrm}", str(HRM)) for a in case.args]
    )
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.run(
        [sys.executable, str(SCRIPTS / case.script), *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    assert proc.returncode == 0, proc.stderr[-4000:]
    assert "leaked" not in proc.stderr, proc.stderr[-4000:]  # nanobind: a cycle not broken
    if help_only:
        assert "usage:" in proc.stdout
        pytest.skip(f"{HRM} is absent: ran {case.script} --help only")
    for pattern in case.expect:
        assert re.search(pattern, proc.stdout, re.M), (pattern, proc.stdout[-4000:])
    for name in case.files:
        assert (tmp_path / name).stat().st_size > 0, name
    if case.check is not None:
        case.check(proc.stdout, tmp_path)
