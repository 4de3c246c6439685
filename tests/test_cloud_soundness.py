"""The point-cloud soundness study of issue 55, small (``scripts/arm_soundness.py --cloud``).

Two hundred random edges of the Panda in MotionBenchMaker scenes turned into sparse
surface clouds, half of them grazing the cloud, decided by the compiled certifier; every
accepted edge is re-checked on the links' own meshes against every *original* point as a
ball of the point radius (python-fcl), with the certifier seeing the cloud as it is or
through a voxel filter (then at ``point_radius + spacing``): no violation, and the
re-check does see a point on a link. The full study's numbers are in
``benchmarks/cloud-soundness/``.
"""

from __future__ import annotations

import functools
import importlib.util
import io
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import panda_arm

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "arm_soundness.py"
ARCHIVE = ROOT.parent / "shared" / "data" / "external" / "mbm" / "panda" / "problems.tar.bz2"

pytestmark = pytest.mark.skipif(not ARCHIVE.exists(), reason="no MotionBenchMaker data")


@functools.cache
def script():
    """scripts/arm_soundness.py as a module."""
    spec = importlib.util.spec_from_file_location("arm_soundness", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def study(*argv: str) -> tuple:
    """``args`` and :func:`study`'s result for the command line ``argv``."""
    args = script().parse_args(list(argv))
    return args, script().study(args, out=io.StringIO())


SMALL = ("--edges", "100", "--per-class", "1", "--representation", "hulls")
SMALL += ("--cloud", "300", "--graze", "0.5", "--free-check", "0")


def test_accepted_edges_are_clear_of_every_point():
    """The certifier on the cloud itself: edges accepted, every one re-checked on the
    meshes, none touches a ball, and some pass within a millimetre of one (the grazing
    edges: the study tests the certifier where it matters)."""
    _, r = study(*SMALL)
    c = r["counts"]
    assert c["edges"] == 100 and c["scenes"] == 7
    assert c["points"] == c["kept"]  # no filter: the certifier sees every point
    assert c["accepted"] > 50 and c["rechecked"] == c["accepted"]
    assert c["violations"] == 0
    assert c["grazing_accepted"] > 0
    assert c["near"][1] > 0  # within 1 mm of the cloud on the meshes
    assert 0.0 < r["lowest"]["scene"] < 1e-3
    assert r["lowest"]["any"] > 0.0


def test_points_the_filter_dropped_stay_clear_of_accepted_edges():
    """The certifier on a voxel filter's points at ``point_radius + spacing``: every
    accepted edge is re-checked against the original points at ``point_radius``, the
    dropped ones included, and none comes nearer than that."""
    args, r = study(*SMALL, "--spacing", "0.04")
    c = r["counts"]
    assert sum(c["kept"]) < 0.8 * sum(c["points"])  # the filter dropped points
    assert c["accepted"] > 50 and c["rechecked"] == c["accepted"]
    assert c["violations"] == 0
    assert c["grazing_accepted"] > 0
    assert 0.0 < r["lowest"]["scene"] < math.inf
    assert args.point_radius + args.spacing == pytest.approx(0.0425)


def test_the_certifier_sees_the_filtered_cloud_and_the_recheck_the_original():
    """``scene_obstacles``: the planned cloud is the voxel filter's subset of the original
    points at ``point_radius + spacing``, every original point within ``spacing`` of a
    kept one; the re-checked cloud is every original point at ``point_radius``; the same
    seed gives the same points."""
    from scipy.spatial import cKDTree

    from kcplan.arm.mbm import load_mbm_archive

    args = script().parse_args(["--cloud", "200", "--spacing", "0.02"])
    problem = load_mbm_archive(ARCHIVE, [("box", 1)])["box", 1]
    planned, checked, counts = script().scene_obstacles(problem, 3, args)
    (plan,), (check,) = planned, checked
    assert counts == (len(check.vertices), len(plan.vertices))
    assert plan.kind == check.kind == "pointcloud"
    assert plan.extents.tolist() == [0.0225] * 3 and check.extents.tolist() == [0.0025] * 3
    assert len(check.vertices) == 200 * len(problem.obstacles)
    assert len(plan.vertices) < len(check.vertices)
    gap, _ = cKDTree(check.vertices).query(plan.vertices)
    assert gap.max() == 0.0  # the kept points are original points
    reach, _ = cKDTree(plan.vertices).query(check.vertices)
    assert reach.max() <= 0.02
    again, _, _ = script().scene_obstacles(problem, 3, args)
    assert np.array_equal(again[0].vertices, plan.vertices)
    raw, _, _ = script().scene_obstacles(problem, 3, script().parse_args(["--cloud", "200"]))
    assert np.array_equal(raw[0].vertices, check.vertices)
    args.balls = True  # every point its own ball, as python-fcl's broad phase takes them
    _, balls, _ = script().scene_obstacles(problem, 3, args)
    assert {ob.kind for ob in balls} == {"sphere"} and len(balls) == len(check.vertices)
    assert np.array_equal([ob.center for ob in balls], check.vertices)
    assert {float(ob.extents[0]) for ob in balls} == {0.0025}


@pytest.mark.parametrize("balls", [False, True], ids=["bvh", "balls"])
def test_the_recheck_sees_a_point_on_a_link(balls):
    """The mesh re-check is not vacuous, with the cloud as python-fcl's BVH of its points
    or each point an FCL ball (``--balls``): a point at a vertex of a link's mesh (a vertex
    of its hull) is in contact at the point radius; the same cloud three metres up is
    clear, and the smallest distance it measured to the cloud is reported."""
    from kcplan.arm.kinematics import body_frames

    cloud = script().ball_obstacles if balls else lambda v, r: [script().cloud_obstacle(v, r)]
    arm = panda_arm(None)
    q = 0.5 * (arm.lower + arm.upper)
    frames = body_frames(arm, q)
    k = max(i for i, body in enumerate(arm.bodies) if body.hull is not None)
    vertex = frames[k][:3, :3] @ arm.bodies[k].hull.vertices[0] + frames[k][:3, 3]
    points = vertex + np.random.default_rng(0).uniform(-0.2, 0.2, (50, 3))
    points[0] = vertex
    meshes = script()._Meshes(arm, cloud(points, 0.0025))
    hit = meshes.check([q, q])
    assert hit.collides and hit.what.endswith("and an obstacle")
    assert meshes.scene_lowest <= meshes.tolerance
    far = script()._Meshes(arm, cloud(points + [0.0, 0.0, 3.0], 0.0025))
    assert not far.check([q, q]).collides
    assert 1.0 < far.scene_lowest < math.inf


def test_a_certifier_that_accepts_every_edge_is_caught(monkeypatch):
    """The study's verdict is not vacuous: a certifier that accepts every edge it is asked
    (the compiled one, its answer ignored) gets violations, each printed with its edge."""
    module = script()

    class Lenient(module.KernelArmCertifier):
        def check(self, q1, q2):
            super().check(q1, q2)
            return True

    monkeypatch.setattr(module, "KernelArmCertifier", Lenient)
    args = module.parse_args(["--edges", "42", "--per-class", "1", "--representation", "hulls",
                              "--cloud", "300", "--free-check", "0"])  # fmt: skip
    out = io.StringIO()
    c = module.study(args, out=out)["counts"]
    assert c["accepted"] == c["rechecked"] == 42
    assert c["violations"] > 0
    lines = [line for line in out.getvalue().splitlines() if line.startswith("VIOLATION: ")]
    assert len(lines) == c["violations"]
    assert all(" within 1e-06 m at segment parameter " in line for line in lines), lines


def test_the_two_rechecks_agree():
    """The cloud as python-fcl's BVH of its points (the verifier's own) and as one FCL
    ball per point (``--balls``) give the same verdicts, and the same smallest clearance
    within the BVH's 1e-9 m."""
    small = ("--edges", "28", "--per-class", "1", "--representation", "hulls", "--cloud", "200")
    small += ("--graze", "1", "--free-check", "1")
    _, bvh = study(*small)
    _, balls = study(*small, "--balls")
    keys = ("edges", "accepted", "rechecked", "violations", "verified", "near", "grazing")
    assert {k: bvh["counts"][k] for k in keys} == {k: balls["counts"][k] for k in keys}
    assert bvh["steps"] == balls["steps"]
    assert bvh["counts"]["near"][0] > 0
    assert bvh["lowest"]["scene"] == pytest.approx(balls["lowest"]["scene"], abs=1e-8)
    assert bvh["lowest"]["edge"][1] == balls["lowest"]["edge"][1]
