"""Error spaces of a pick-and-place, the inflation a target needs, and parts entropy.

The setting of the paper's Sec. 9.2 (Table 2): a KUKA LWR holds an ellipsoidal object
(semi-axes :data:`OBJECT_SEMI_AXES`, centred and aligned with the flange frame) and places
it at the pose reached with the joint angles :data:`PAPER_JOINTS`. The target is the
object's ellipsoid at that desired pose, inflated by ``eps``: semi-axes ``(1 + eps) a0``.
Joint noise (zero-mean Gaussian, standard deviation ``sigma`` radians on every joint)
scatters the placed object; its poses relative to the target form the *error space*.

Conventions: a relative pose is given by KC coordinates ``xi = [omega, tau]`` (rotation
vector in radians, translation in metres, both in the target's frame), so the object's
points are ``exp(hat(omega)) diag(a0) u + tau``, ``|u| <= 1`` — the convention of
:func:`kcplan.geometry.containment_margin` and of the KC bounds.

Inflation. The exact containment margin scales as ``m_b(xi) = m_a(xi) / (1 + eps)`` for
``b = (1 + eps) a``, so the smallest inflation containing every pose is closed-form,
``max_k m_a(xi_k) - 1`` (no bisection needed; the tests check it against one). The
geometric lower bound has no such scaling; its smallest inflation is found by bisection.

Parts entropy ``S = log V``, ``V`` the volume of allowable motions of the
object in the target (rad^3 m^3, exponential coordinates of the identity component,
:func:`kcplan.kc.kc_volume`), for the true KC set and for the geometric lower bound.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan.geometry.containment import containment_margin
from kcplan.geometry.rotations import log_rotation
from kcplan.kc.geometric import GeometricLowerBound
from kcplan.kc.volume import kc_volume
from kcplan.pickplace.kinematics import LWR_DH, forward_kinematics

__all__ = [
    "OBJECT_SEMI_AXES",
    "PAPER_JOINTS",
    "relative_poses",
    "error_space",
    "min_inflation",
    "parts_entropy",
    "noise_study",
]

OBJECT_SEMI_AXES = np.array([0.2, 0.15, 0.1])
"""Semi-axes of the placed object in metres (paper Table 2)."""

PAPER_JOINTS = np.array([-0.7768, 0.1991, -0.1991, 1.6981, -1.6241, 1.9656, -0.9147])
"""Desired joint angles in radians (paper Table 2)."""


def relative_poses(target: ArrayLike, actual: ArrayLike) -> NDArray[np.float64]:
    """KC coordinates of poses ``actual`` (k, 4, 4) seen from ``target`` (4, 4), shape (k, 6)."""
    Tt = np.asarray(target, dtype=float)
    Ta = np.asarray(actual, dtype=float).reshape(-1, 4, 4)
    Rt = Tt[:3, :3]
    R = np.einsum("ji,kjl->kil", Rt, Ta[:, :3, :3])  # Rt^T R_a
    tau = (Ta[:, :3, 3] - Tt[:3, 3]) @ Rt  # Rt^T (p_a - p_t), row-wise
    return np.hstack([log_rotation(R), tau])


def error_space(
    sigma: float,
    poses: int = 100,
    q: ArrayLike = PAPER_JOINTS,
    rng: np.random.Generator | int | None = None,
    dh: ArrayLike = LWR_DH,
    forward: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None = None,
) -> NDArray[np.float64]:
    """Relative poses of the placed object for noisy joints.

    Parameters
    ----------
    sigma : float
        Standard deviation of the zero-mean Gaussian noise on each joint, radians.
    poses : int
        Number of noisy placements (the paper uses 100 per trial).
    q : array_like, shape (7,)
        Desired joint angles, radians.
    rng : numpy Generator or seed, optional
    dh : array_like, shape (len(q), 3)
        The arm's DH parameters (:func:`kcplan.pickplace.kinematics.forward_kinematics`).
    forward : callable, optional
        Joint vectors ``(k, len(q))`` to the held object's frames ``(k, 4, 4)``, in place
        of ``dh`` (a URDF arm: :func:`kcplan.arm.kinematics.link_frames`).

    Returns
    -------
    ndarray, shape (poses, 6)
        ``[omega, tau]`` of each placement relative to the desired pose (radians, metres).
        With ``sigma = 0`` every row is the identity pose (zeros, to rounding).
    """
    if not (sigma >= 0 and math.isfinite(sigma)):
        raise ValueError(f"sigma: expected a finite number >= 0, got {sigma}")
    gen = np.random.default_rng(rng)
    q = np.asarray(q, dtype=float)
    noisy = q + sigma * gen.standard_normal((int(poses), len(q)))
    if forward is None:
        return relative_poses(forward_kinematics(q, dh), forward_kinematics(noisy, dh))
    return relative_poses(forward(q[None])[0], forward(noisy))


def min_inflation(
    xi: ArrayLike,
    semi_axes: ArrayLike = OBJECT_SEMI_AXES,
    bound: str = "exact",
    tolerance: float = 1e-6,
    max_inflation: float = 100.0,
) -> float:
    """Smallest inflation ``eps`` of the target that contains every pose of ``xi``.

    Parameters
    ----------
    xi : array_like, shape (k, 6)
        Relative poses (see :func:`error_space`).
    bound : {"exact", "geometric"}
        "exact": by the exact containment margin (closed form, ``max m_a - 1``, clipped
        at 0). "geometric": smallest eps for which the geometric lower bound contains all
        poses, by bisection to ``tolerance`` (relative); always >= the exact answer.
    max_inflation : float
        Give up (return ``inf``) above this inflation.

    Returns
    -------
    float
        ``eps >= 0``; for the geometric bound, the upper end of the final bracket, so the
        bound does contain the poses at the returned value.
    """
    a = np.asarray(semi_axes, dtype=float)
    X = np.atleast_2d(np.asarray(xi, dtype=float))
    exact = max(float(np.max(containment_margin(a, a, X))) - 1.0, 0.0)
    if bound == "exact":
        return exact
    if bound != "geometric":
        raise ValueError(f"bound: expected 'exact' or 'geometric', got {bound!r}")

    def holds(eps: float) -> bool:
        return bool(np.all(GeometricLowerBound(a, eps).contains(X)))

    lo = exact
    hi = max(2.0 * exact, 1e-9)
    while not holds(hi):
        lo, hi = hi, 2.0 * hi
        if hi > max_inflation:
            return math.inf
    while hi - lo > tolerance * hi and hi > 1e-12:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if holds(mid) else (mid, hi)
    return hi


def parts_entropy(
    inflation: float,
    semi_axes: ArrayLike = OBJECT_SEMI_AXES,
    bound: str = "exact",
) -> float:
    """Parts entropy ``S = log V`` of the object in its target inflated by ``inflation``.

    ``V`` is the volume of allowable motions (rad^3 m^3 in 3D, exponential coordinates):
    of the true KC set (``bound="exact"``, :func:`kcplan.kc.kc_volume`) or of the
    geometric lower bound (``bound="geometric"``). Natural logarithm; ``-inf`` for
    ``inflation = 0`` (no motion is allowed). Increasing in ``inflation``.
    """
    if inflation == 0:
        return -math.inf
    if bound == "exact":
        volume = kc_volume(semi_axes, inflation)
    elif bound == "geometric":
        volume = GeometricLowerBound(semi_axes, inflation).volume()
    else:
        raise ValueError(f"bound: expected 'exact' or 'geometric', got {bound!r}")
    return math.log(volume)


def noise_study(
    sigmas_deg: ArrayLike,
    trials: int = 20,
    poses: int = 100,
    target_inflation: float = 0.05,
    seed: int = 0,
    semi_axes: ArrayLike = OBJECT_SEMI_AXES,
    q: ArrayLike = PAPER_JOINTS,
    progress=None,
    forward: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None = None,
) -> tuple[list[dict], list[dict]]:
    """The study of ``kcplan pick-place``: per noise level, ``trials`` error spaces.

    Returns ``(trial_rows, sigma_rows)``. A trial row has ``sigma_deg``, ``trial``,
    ``eps_exact`` and ``eps_geometric`` (:func:`min_inflation`), ``max_rotation_deg`` and
    ``max_translation`` (metres) of the error space, and whether the target inflated by
    ``target_inflation`` contains every pose by the exact margin and by the geometric
    lower bound. A sigma row has the medians and 10/90 % quantiles of both inflations
    over the trials, the fractions of trials contained, and the parts entropy at the
    median exact inflation (true KC volume and geometric lower bound). Trial ``t`` of
    every noise level draws from ``numpy.random.default_rng((seed, t))``. ``q`` and
    ``forward``: the arm (:func:`error_space`; default the paper's KUKA LWR).
    """
    a = np.asarray(semi_axes, dtype=float)
    target = GeometricLowerBound(a, target_inflation)
    limit = 1.0 + target_inflation
    trial_rows, sigma_rows = [], []
    for sigma in np.asarray(sigmas_deg, dtype=float):
        mine = []
        for t in range(trials):
            rng = np.random.default_rng((seed, t))
            xi = error_space(np.radians(sigma), poses, q, rng, forward=forward)
            margin = containment_margin(a, a, xi)
            row = {
                "sigma_deg": float(sigma),
                "trial": t,
                "eps_exact": min_inflation(xi, a, "exact"),
                "eps_geometric": min_inflation(xi, a, "geometric"),
                "max_rotation_deg": float(np.degrees(np.linalg.norm(xi[:, :3], axis=1).max())),
                "max_translation": float(np.linalg.norm(xi[:, 3:], axis=1).max()),
                "contained_exact": bool(np.all(margin <= limit)),
                "contained_geometric": bool(np.all(target.contains(xi))),
            }
            mine.append(row)
        trial_rows += mine
        exact = np.array([r["eps_exact"] for r in mine])
        geo = np.array([r["eps_geometric"] for r in mine])
        eps = float(np.median(exact))
        sigma_rows.append(
            {
                "sigma_deg": float(sigma),
                "trials": trials,
                "eps_exact_median": eps,
                "eps_exact_p10": float(np.percentile(exact, 10)),
                "eps_exact_p90": float(np.percentile(exact, 90)),
                "eps_geometric_median": float(np.median(geo)),
                "eps_geometric_p10": float(np.percentile(geo, 10)),
                "eps_geometric_p90": float(np.percentile(geo, 90)),
                "geometric_over_exact": float(np.median(geo / exact)) if exact.all() else math.nan,
                "contained_exact_fraction": float(np.mean([r["contained_exact"] for r in mine])),
                "contained_geometric_fraction": float(
                    np.mean([r["contained_geometric"] for r in mine])
                ),
                "entropy_true": parts_entropy(eps, a, "exact"),
                "entropy_geometric": parts_entropy(eps, a, "geometric"),
            }
        )
        if progress is not None:
            progress(sigma_rows[-1])
    return trial_rows, sigma_rows
