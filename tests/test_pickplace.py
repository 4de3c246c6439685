"""Pick-and-place error analysis: LWR kinematics, error spaces, inflation, parts entropy."""

import csv
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from kcplan.cli import main
from kcplan.geometry.containment import containment_margin
from kcplan.geometry.rotations import exp_rotation
from kcplan.kc.geometric import GeometricLowerBound
from kcplan.pickplace import (
    OBJECT_SEMI_AXES,
    PAPER_JOINTS,
    error_space,
    forward_kinematics,
    min_inflation,
    parts_entropy,
)
from kcplan.pickplace.analysis import noise_study, relative_poses

D1, D3, D5, D7 = 0.3105, 0.4, 0.39, 0.078


def rot(axis: str, t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    return {
        "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


def test_zero_configuration_is_the_arm_straight_up():
    T = forward_kinematics(np.zeros(7))
    assert np.allclose(T[:3, :3], np.eye(3), atol=1e-15)
    assert np.allclose(T[:3, 3], [0, 0, D1 + D3 + D5 + D7], atol=1e-15)


@pytest.mark.parametrize("t", [0.3, -1.2, 2.5])
def test_single_joint_rotations_by_hand(t):
    up = D1 + D3 + D5 + D7
    # joints 1 and 7 turn the straight arm about its own axis
    for j in (0, 6):
        q = np.zeros(7)
        q[j] = t
        T = forward_kinematics(q)
        assert np.allclose(T[:3, :3], rot("z", t), atol=1e-12)
        assert np.allclose(T[:3, 3], [0, 0, up], atol=1e-12)
    # joint 2 (axis -y at the shoulder) swings the 0.868 m forearm-and-hand
    q = np.zeros(7)
    q[1] = t
    T = forward_kinematics(q)
    L = D3 + D5 + D7
    assert np.allclose(T[:3, 3], [-L * np.sin(t), 0, D1 + L * np.cos(t)], atol=1e-12)
    assert np.allclose(T[:3, :3], rot("y", -t), atol=1e-12)
    # joint 4 (axis +y at the elbow) swings the last 0.468 m
    q = np.zeros(7)
    q[3] = t
    T = forward_kinematics(q)
    L = D5 + D7
    assert np.allclose(T[:3, 3], [L * np.sin(t), 0, D1 + D3 + L * np.cos(t)], atol=1e-12)
    assert np.allclose(T[:3, :3], rot("y", t), atol=1e-12)


def test_forward_kinematics_is_vectorised_and_checks_shape():
    Q = np.random.default_rng(0).uniform(-2, 2, (5, 7))
    stacked = forward_kinematics(Q)
    assert stacked.shape == (5, 4, 4)
    for q, T in zip(Q, stacked, strict=True):
        assert np.allclose(forward_kinematics(q), T)
    with pytest.raises(ValueError, match="7 joint angles"):
        forward_kinematics(np.zeros(6))


def test_relative_poses_invert_composition():
    rng = np.random.default_rng(1)
    T = forward_kinematics(PAPER_JOINTS)
    xi = np.hstack([rng.normal(0, 0.3, (20, 3)), rng.normal(0, 0.1, (20, 3))])
    G = np.broadcast_to(np.eye(4), (20, 4, 4)).copy()
    G[:, :3, :3] = exp_rotation(xi[:, :3], 3)
    G[:, :3, 3] = xi[:, 3:]
    assert np.allclose(relative_poses(T, T @ G), xi, atol=1e-12)


def test_zero_noise_is_one_pose_needing_no_inflation():
    xi = error_space(0.0, 100, rng=3)
    assert xi.shape == (100, 6)
    assert np.abs(xi).max() < 1e-12
    assert min_inflation(xi) == 0.0
    assert min_inflation(xi, bound="geometric") < 1e-9


def _bisect_exact(xi, a, tol=1e-12):
    lo, hi = 0.0, 1.0
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        inside = np.all(containment_margin(a, (1 + mid) * a, xi) <= 1.0)
        lo, hi = (lo, mid) if inside else (mid, hi)
    return hi


@given(st.floats(0.001, 0.02), st.integers(0, 10**6))
def test_min_inflation_is_the_exact_threshold(sigma, seed):
    a = OBJECT_SEMI_AXES
    xi = error_space(sigma, 50, rng=seed)
    eps = min_inflation(xi, a)
    assert eps == pytest.approx(_bisect_exact(xi, a), abs=1e-9)
    assert np.all(containment_margin(a, (1 + eps) * a, xi) <= 1 + 1e-12)
    assert np.any(containment_margin(a, (1 + eps * (1 - 1e-6)) * a, xi) > 1)
    geo = min_inflation(xi, a, "geometric")
    assert geo >= eps
    assert np.all(GeometricLowerBound(a, geo).contains(xi))


@given(st.floats(0.001, 0.03), st.floats(0.002, 0.3), st.integers(0, 10**6))
def test_geometric_bound_never_contains_what_the_margin_excludes(sigma, eps, seed):
    a = OBJECT_SEMI_AXES
    xi = error_space(sigma, 100, rng=seed)
    inside = GeometricLowerBound(a, eps).contains(xi)
    margin = containment_margin(a, (1 + eps) * a, xi)
    assert np.all(margin[inside] <= 1 + 1e-12)


def test_required_inflation_grows_with_noise_over_seeds():
    trials, rows = noise_study([0.05, 0.1, 0.2], trials=12, poses=100, seed=7)
    per = {s: [t["eps_exact"] for t in trials if t["sigma_deg"] == s] for s in (0.05, 0.1, 0.2)}
    # nearly every trial of twice the noise needs more than the median of the smaller one
    assert np.mean(np.array(per[0.1]) > np.median(per[0.05])) >= 0.9
    assert np.mean(np.array(per[0.2]) > np.median(per[0.1])) >= 0.9
    medians = [r["eps_exact_median"] for r in rows]
    assert medians == sorted(medians)
    assert all(r["eps_geometric_median"] > r["eps_exact_median"] for r in rows)


def test_parts_entropy_is_monotone_and_the_geometric_bound_is_below():
    eps = [0.01, 0.03, 0.1, 0.3]
    true = [parts_entropy(e) for e in eps]
    geo = [parts_entropy(e, bound="geometric") for e in eps]
    assert np.all(np.diff(true) > 0) and np.all(np.diff(geo) > 0)
    assert all(g < t for g, t in zip(geo, true, strict=True))
    assert parts_entropy(0.0) == -np.inf
    with pytest.raises(ValueError, match="bound"):
        parts_entropy(0.1, bound="convex")


def test_pick_place_command(tmp_path, capsys):
    out = tmp_path / "pp"
    code = main(["pick-place", "--sigma-deg", "0", "0.1", "0.3", "--trials", "3", "-o", str(out)])
    assert code == 0
    with open(out / "summary.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [float(r["sigma_deg"]) for r in rows] == [0.0, 0.1, 0.3]
    assert float(rows[0]["eps_exact_median"]) == 0.0
    assert float(rows[1]["eps_exact_median"]) < float(rows[2]["eps_exact_median"])
    assert float(rows[2]["contained_exact_fraction"]) == 0.0  # eps 0.05 is too small at 0.3 deg
    with open(out / "trials.csv") as fh:
        assert len(list(csv.DictReader(fh))) == 9
    assert (out / "pick_place.png").read_bytes().startswith(b"\x89PNG")
    assert main(["pick-place", "--sigma-deg", "-1", "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--sigma-deg" in err


PANDA_URDF = Path(__file__).resolve().parents[1] / "scenarios" / "arm" / "panda" / "panda.urdf"


def test_a_urdf_arm_holds_the_object_at_its_link_through_pinocchio():
    """link_frames (the reduced model's joint frames and the link's placement) against
    Pinocchio's own frame placement, and the study with a URDF arm: no noise, no inflation;
    noise needs some, more with more noise."""
    import pinocchio as pin

    from kcplan.arm import load_arm
    from kcplan.arm.kinematics import link_frames

    arm = load_arm(PANDA_URDF, [f"panda_joint{i}" for i in range(1, 8)])
    rng = np.random.default_rng(4)
    Q = rng.uniform(arm.lower, arm.upper, (5, arm.dof))
    frames = link_frames(arm, Q, "panda_hand")
    data = arm.model.createData()
    for q, F in zip(Q, frames, strict=True):
        pin.framesForwardKinematics(arm.model, data, arm.configuration(q))
        expected = data.oMf[arm.model.getFrameId("panda_hand")].homogeneous
        np.testing.assert_allclose(F, expected, atol=1e-12)
    q = 0.5 * (arm.lower + arm.upper)
    forward = lambda Q: link_frames(arm, Q, "panda_hand")  # noqa: E731
    _, rows = noise_study([0.0, 0.1, 0.5], trials=2, poses=30, q=q, forward=forward)
    eps = [r["eps_exact_median"] for r in rows]
    assert eps[0] == 0.0 and 0.0 < eps[1] < eps[2]


def test_pick_place_takes_a_urdf_arm_and_refuses_a_bad_one(tmp_path, capsys):
    out = tmp_path / "pp"
    args = ["pick-place", "--urdf", str(PANDA_URDF), "--link", "panda_hand", "--sigma-deg",
            "0", "0.2", "--trials", "2", "--poses", "20", "-o", str(out)]  # fmt: skip
    assert main(args) == 0
    assert "arm: arm of 7 joints" in capsys.readouterr().out
    rows = list(csv.DictReader((out / "summary.csv").open()))
    assert float(rows[0]["eps_exact_median"]) == 0.0 < float(rows[1]["eps_exact_median"])
    assert main(["pick-place", "--urdf", str(PANDA_URDF), "--link", "nope", "-o", str(out)]) == 2
    assert capsys.readouterr().err.strip().endswith("--link: expected a link of "
                                                    f"{PANDA_URDF}, got 'nope'")  # fmt: skip
    assert main(["pick-place", "--urdf", str(PANDA_URDF), "--link", "panda_hand", "--q", "0",
                 "-o", str(out)]) == 2  # fmt: skip
    assert "--q: expected 7 joint values (panda_joint1" in capsys.readouterr().err
    assert main(["pick-place", "--link", "panda_hand", "-o", str(out)]) == 2
    assert capsys.readouterr().err.strip() == "kcplan pick-place: --link: only with --urdf"
