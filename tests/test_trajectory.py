"""Certified trajectories (issue 40): the blended curve, its certificate, its timing."""

import json
import math
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from kcplan.trajectory.curve import BlendedPath
from kcplan.trajectory.timing import time_path

ROOT = Path(__file__).resolve().parents[1]
BOX = ROOT / "scenarios" / "arm" / "box_1.yaml"


@st.composite
def polylines(draw, dof: int = 3):
    """A polyline of 3-6 waypoints with segments of 0.2-2 rad, and blends that fit."""
    n = draw(st.integers(3, 6))
    steps = draw(arrays(float, (n - 1, dof), elements=st.floats(-1.0, 1.0)))
    lengths = np.linalg.norm(steps, axis=1)
    if (lengths < 0.2).any():
        steps = steps + 0.3
        lengths = np.linalg.norm(steps, axis=1)
    W = np.vstack([np.zeros(dof), np.cumsum(steps, axis=0)])
    share = draw(arrays(float, n - 2, elements=st.floats(0.0, 0.5)))
    blends = share * np.minimum(lengths[:-1], lengths[1:])
    return W, blends


@settings(max_examples=10)
@given(polylines())
def test_the_curve_is_continuous_with_its_tangent_and_stays_near_its_corners(case):
    W, blends = case
    path = BlendedPath(W, blends)
    x = path.breakpoints
    for k in range(1, len(x) - 1):  # both sides of every breakpoint: q and dq/ds agree
        s, h = x[k], 0.5 * (x[k] - x[k - 1])  # the left piece at its middle, exact to its end
        left = path(s - h) + h * path(s - h, 1) + 0.5 * h * h * path(s - h, 2)
        assert np.allclose(left, path(s), atol=1e-9)
        if not any(abs(s - kink) < 1e-12 for kink in path.kinks):  # no kink: C^1
            bend = np.abs(path(s - h, 2)).max() * s * 1e-14  # rounding of s, amplified
            assert np.allclose(path(s - h, 1) + h * path(s - h, 2), path(s, 1), atol=1e-9 + bend)
    assert np.allclose(path(0.0), W[0]) and np.allclose(path(path.length), W[-1])
    # every point of blend i lies within delta_i max(|u1_j|, |u2_j|) of its corner: the
    # set kcplan.trajectory.smoothing proves free
    units = np.diff(W, axis=0) / np.linalg.norm(np.diff(W, axis=0), axis=1)[:, None]
    curved = np.flatnonzero(path.curved)
    corners = [i for i in range(len(blends)) if path.blends[i] > 0]
    assert len(curved) == len(corners)
    for piece, i in zip(curved, corners, strict=True):
        m = np.maximum(np.abs(units[i]), np.abs(units[i + 1]))
        s = np.linspace(x[piece], x[piece + 1], 41)
        assert (np.abs(path(s) - W[i + 1]) <= path.blends[i] * m + 1e-12).all()


@settings(max_examples=40)
@given(polylines())
def test_a_piece_bound_holds_its_derivative(case):
    path = BlendedPath(*case)
    for (f, bound) in path.pieces():
        sigma = np.linspace(0.0, 1.0, 33)
        q = np.array([f(x) for x in sigma])
        speed = np.abs(np.diff(q, axis=0)) / np.diff(sigma)[:, None]
        assert (speed <= bound + 1e-9).all()


def _trapezoid(length: float, v: float, a: float) -> float:
    """Rest to rest along a line at most v and a: the exact time."""
    return length / v + v / a if length >= v * v / a else 2.0 * math.sqrt(length / a)


def test_stopping_at_every_corner_takes_the_exact_rest_to_rest_times():
    rng = np.random.default_rng(3)
    W = np.vstack([np.zeros(4), np.cumsum(rng.uniform(-1.0, 1.0, (5, 4)), axis=0)])
    v, a = np.array([1.0, 2.0, 1.5, 0.7]), np.array([2.0, 5.0, 1.0, 3.0])
    timed = time_path(BlendedPath(W), v, a)
    exact = 0.0
    for d in np.diff(W, axis=0):
        u = d / np.linalg.norm(d)
        with np.errstate(divide="ignore"):
            exact += _trapezoid(np.linalg.norm(d), np.min(v / np.abs(u)), np.min(a / np.abs(u)))
    # TOPP-RA's grid puts the switches between gridpoints: never faster, within 0.5 %
    assert exact * (1 - 1e-9) <= timed.duration <= exact * 1.005


@settings(max_examples=10)
@given(polylines(), st.floats(0.5, 3.0), st.floats(0.5, 10.0))
def test_a_timed_curve_keeps_its_limits_everywhere_and_follows_the_curve(case, vmax, amax):
    W, blends = case
    path = BlendedPath(W, blends)
    v, a = np.full(3, vmax), np.full(3, amax) * np.array([1.0, 0.5, 2.0])
    timed = time_path(path, v, a)
    rv, ra = timed.peak_ratios()
    assert rv <= 1.0 + 1e-9 and ra <= 1.0 + 1e-9
    t, s, q, qd, qdd = timed.sample(1000.0)
    assert t[0] == 0.0 and t[-1] == pytest.approx(timed.duration)
    # the exact peaks bound the 1 kHz samples, and the samples come within 2 % of them
    assert (np.abs(qd) / v).max() <= rv + 1e-9 and (np.abs(qdd) / a).max() <= ra + 1e-9
    assert np.allclose(q, path(s), atol=1e-12)
    assert np.allclose(q[0], W[0]) and np.allclose(q[-1], W[-1])
    assert np.allclose(qd[0], 0.0) and np.allclose(qd[-1], 0.0)
    # qd is q's derivative: central differences of q at 1 kHz
    mid = (q[2:] - q[:-2]) / (t[2:] - t[:-2])[:, None]
    assert np.abs(mid - qd[1:-1]).max() <= 0.01 * vmax + 2e-3 * amax
    # (that blending pays against stopping at every corner is not a property of TOPP-RA's
    # grid on tiny blends: it is measured on MBM paths, test_plan_returns_... and RESULTS 14)


def test_limits_are_refused_in_one_line():
    path = BlendedPath([[0.0, 0.0], [1.0, 0.0]])
    with pytest.raises(ValueError, match=r"velocity_limits: expected 2 finite numbers > 0"):
        time_path(path, [1.0, 0.0], [1.0, 1.0])
    with pytest.raises(ValueError, match=r"blends: the blends at both ends of segment 1"):
        BlendedPath([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [2.0, 1.0]], [0.6, 0.6])


@pytest.fixture(scope="module")
def box():
    from kcplan.arm import ArmWorld
    from kcplan.arm.verify import ArmMeshChecker
    from kcplan.scenarios import as_scenario

    scenario = as_scenario(BOX)
    world = ArmWorld(scenario.arm, scenario.obstacles, allowed=scenario.allowed)
    return scenario, world, ArmMeshChecker(scenario.arm, scenario.obstacles, scenario.allowed)


def test_every_certified_blend_is_free_on_the_meshes(box):
    """Random corners of certified edges in an MBM scene: every blend certify_blends
    accepts is checked on the links' own meshes, without gaps (independent code)."""
    from kcplan._kernel import ArmCertifier
    from kcplan.trajectory.smoothing import certify_blends

    scenario, world, checker = box
    arm = scenario.arm
    certifier = ArmCertifier(world.kernel)
    rng = np.random.default_rng(11)
    blends = large = agree = 0
    while blends < 12:
        c = rng.uniform(arm.lower, arm.upper)
        q0 = np.clip(c + rng.normal(0.0, 0.4, arm.dof), arm.lower, arm.upper)
        q2 = np.clip(c + rng.normal(0.0, 0.4, arm.dof), arm.lower, arm.upper)
        if not (certifier.state_valid(q0.tolist()) and certifier.check(q0.tolist(), c.tolist())
                and certifier.check(c.tolist(), q2.tolist())):  # fmt: skip
            continue
        # the compiled advancement along the blend and its Python twin
        compiled = certify_blends(world, [q0, c, q2])
        twin = certify_blends(world, [q0, c, q2], backend="python")
        agree += compiled.blends[0] == twin.blends[0]
        for certificate in (compiled, twin):
            delta = certificate.blends[0]
            assert 0.0 < delta <= certificate.caps[0]
            large += delta > certificate.radii[0] * (1 + 1e-9)  # beyond the corner's guard
            path = BlendedPath([q0, c, q2], [delta])
            curve = [p for p, bent in zip(path.pieces(), path.curved, strict=True) if bent]
            assert not checker.check_pieces(curve).collides
        blends += 1
    assert large >= 2  # the guards along the curve proved a larger blend somewhere
    assert agree >= 10  # the twins' guards differ (caps), their blends seldom


def test_plan_returns_a_certified_trajectory_faster_than_stopping(box):
    from kcplan.planning.problem import plan

    scenario, _, checker = box
    with pytest.raises(ValueError, match="trajectory: expected a kc-\\* or ca-\\* planner"):
        plan(scenario, "rrtconnect", 1.0, seed=1, trajectory=True)
    result = plan(scenario, "kc-rrtconnect", 10.0, seed=1, trajectory=True)
    timed = result.trajectory
    assert result.solved and timed is not None
    assert timed.timed.duration < timed.stop_duration
    assert np.allclose(timed.path.waypoints[0], scenario.start)
    assert np.allclose(timed.path.waypoints[-1], scenario.goal)
    doc = timed.document(100.0)
    assert set(doc) >= {"joints", "t", "q", "qd", "qdd", "velocity_limits",
                        "acceleration_limits", "certificate", "curve"}  # fmt: skip
    assert doc["joints"] == list(scenario.arm.joints)
    assert np.diff(doc["t"]).max() <= 0.01 + 1e-12
    assert not checker.check_pieces(timed.path.pieces()).collides


def test_cli_writes_verifies_and_refuses_trajectories(tmp_path, monkeypatch, capsys):
    from kcplan.cli import main

    monkeypatch.chdir(tmp_path)

    def _kcplan(*args, cwd):
        code = main([str(a) for a in args])
        out = capsys.readouterr()
        return SimpleNamespace(returncode=code, stdout=out.out, stderr=out.err)

    r = _kcplan("plan", BOX, "--seed", "1", "--trajectory", "T.json", "--rate", "50",
                "--velocity-plot", "V.png", cwd=tmp_path)  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "certified blends" in r.stdout and (tmp_path / "V.png").stat().st_size > 10_000
    doc = json.loads((tmp_path / "T.json").read_text())
    assert doc["rate"] == 50.0 and len(doc["t"]) == len(doc["q"]) == len(doc["qdd"])
    r = _kcplan("verify", BOX, "T.json", cwd=tmp_path)
    assert r.returncode == 0 and r.stdout.startswith("clean: the links' meshes along the whole")
    doc["qd"][len(doc["qd"]) // 2][0] = 100.0  # faster than any joint may go
    (tmp_path / "fast.json").write_text(json.dumps(doc))
    r = _kcplan("verify", BOX, "fast.json", cwd=tmp_path)
    assert r.returncode == 1 and re.match(r"a speed reaches \d+\.\d+ of its limit", r.stdout)
    del doc["qdd"]
    (tmp_path / "bad.json").write_text(json.dumps(doc))
    r = _kcplan("verify", BOX, "bad.json", cwd=tmp_path)
    assert r.returncode == 2 and r.stderr.strip().endswith(
        "bad.json: qdd: expected the field (a trajectory file of kcplan plan --trajectory)")
    assert "Traceback" not in r.stderr
    r = _kcplan("plan", BOX, "--seed", "1", "--trajectory", "T.csv", cwd=tmp_path)
    lines = (tmp_path / "T.csv").read_text().splitlines()
    assert r.returncode == 0 and lines[0].startswith("t,q_panda_joint1,")
    assert len(lines[1].split(",")) == 1 + 3 * 7
    r = _kcplan("plan", BOX, "--trajectory", "X.json", "--acceleration-limit", "1,2",
                cwd=tmp_path)  # fmt: skip
    assert r.returncode == 2 and "--acceleration-limit: acceleration_limits: expected 7" in r.stderr
    assert not (tmp_path / "X.json").exists()
    r = _kcplan("plan", BOX, "--planner", "rrtconnect", "--trajectory", "X.json", cwd=tmp_path)
    assert r.returncode == 2 and "expected a kc-* or ca-* planner" in r.stderr
    r = _kcplan("plan", BOX, "--trajectory", "X.json", "--speed-limit", "1,1", cwd=tmp_path)
    assert r.returncode == 2 and "--speed-limit: a rigid robot's" in r.stderr


def test_rigid_edges_take_the_exact_rest_to_rest_times_within_both_limits():
    from kcplan.trajectory.rigid import time_rigid_path

    W = np.array([[0.0, 0.0, 0.0], [3.0, 4.0, 0.5], [3.0, 4.0, 3.0], [3.0, 4.2, -2.9]])
    v, a = np.array([2.0, 0.5]), np.array([1.0, 0.25])
    timed = time_rigid_path(W, 2, v, a)
    exact = 0.0  # the yaw goes the shorter way round: 3.0 -> -2.9 turns 0.383 rad
    for length, angle in ((5.0, 0.5), (0.0, 2.5), (0.2, 2 * np.pi - 5.9)):
        with np.errstate(divide="ignore"):
            V = min(v[0] / length, v[1] / angle)  # per unit of the fraction f
            A = min(a[0] / length, a[1] / angle)
        exact += _trapezoid(1.0, V, A)
    assert exact * (1 - 1e-9) <= timed.duration <= exact * 1.005
    t, s, q, vel, acc = timed.sample(1000.0)
    assert np.allclose(q[0], W[0]) and np.allclose(q[-1], W[-1]) and s[-1] == pytest.approx(3)
    assert (np.linalg.norm(vel[:, :2], axis=1) <= v[0] * (1 + 1e-9)).all()
    assert (np.abs(vel[:, 2]) <= v[1] * (1 + 1e-9)).all()
    assert (np.abs(acc[:, 2]) <= a[1] * (1 + 1e-9)).all()
    mid = (q[2:, :2] - q[:-2, :2]) / (t[2:] - t[:-2])[:, None]  # velocity is q's derivative
    assert np.abs(mid - vel[1:-1, :2]).max() < 2e-3
    assert max(timed.peak_ratios()) <= 1 + 1e-9


def test_cli_times_and_verifies_a_rigid_robots_path(tmp_path, monkeypatch, capsys):
    from kcplan.cli import main

    monkeypatch.chdir(tmp_path)
    rigid = ROOT / "scenarios" / "3d" / "box_field.yaml"
    assert main(["plan", str(rigid), "--seed", "1", "--trajectory", "R.json", "--speed-limit",
                 "2,0.5"]) == 0  # fmt: skip
    assert "stopping at every corner (rigid robot: no blends)" in capsys.readouterr().out
    doc = json.loads((tmp_path / "R.json").read_text())
    assert doc["joints"] == ["x", "y", "z", "qx", "qy", "qz", "qw"]
    assert doc["velocity_limits"] == [2, 0.5]
    assert main(["verify", str(rigid), "R.json"]) == 0
    assert capsys.readouterr().out.startswith("clean: ")
    doc["q"][len(doc["q"]) // 2][0] += 0.01  # a sample off the path
    (tmp_path / "off.json").write_text(json.dumps(doc))
    assert main(["verify", str(rigid), "off.json"]) == 1
    assert "a sample is 0.01 off the curve" in capsys.readouterr().out
    assert main(["plan", str(rigid), "--trajectory", "X.json", "--speed-limit", "1,0"]) == 2
    assert "--speed-limit: velocity_limits: expected a translational and an angular" in (
        capsys.readouterr().err)  # fmt: skip


def test_every_edge_the_simplifier_makes_is_certified(box):
    """OMPL's shortcutting and smoothing ask the kc validator for every new edge (counted),
    and every edge of the path it returns is proved free by an independent certifier and
    free on the meshes; the path is no longer than the planner's."""
    from kcplan._kernel import ArmCertifier
    from kcplan.planning.problem import plan

    scenario, world, checker = box
    result = plan(scenario, "kc-rrtconnect", 10.0, seed=1, world=world)
    assert result.solved and result.counters["kc_simplify_edges"] > 0
    assert result.length <= result.raw_length + 1e-12
    certifier = ArmCertifier(world.kernel)
    for q1, q2 in zip(result.states[:-1], result.states[1:], strict=True):
        assert certifier.check(q1, q2)
    assert not checker.check(result.states).collides
    unsimplified = plan(scenario, "kc-rrtconnect", 10.0, seed=1, world=world, simplify=False)
    assert unsimplified.counters["kc_simplify_edges"] == 0
