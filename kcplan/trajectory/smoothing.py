"""Certified smoothing of an arm's path: every corner replaced by a blend proved free.

At an interior waypoint ``c`` of a certified path, with unit directions ``u1`` in and
``u2`` out, :class:`kcplan.trajectory.curve.BlendedPath` replaces the corner by the
quadratic Bezier curve through ``a = c - delta u1``, ``c``, ``b = c + delta u2``. Each of its
points is ``c + D`` with ``|D_j| <= delta m_j``, ``m_j = max(|u1_j|, |u2_j|)`` (the curve's
module docstring). One guard at ``c`` proves all of them free:

*Proof.* The guard measures every body's certain clearance ``d_k`` to the obstacles and
every checked self pair's certain distance ``d_kl`` (:meth:`kcplan.arm.ArmWorld.
safe_clearances`), and its levers (:func:`kcplan.arm.bounds.levers`). A configuration
``c + D`` in the joint box is reached from ``c`` along the straight edge ``c + sD``,
``s`` in ``[0, 1]``; along it no point of body ``k`` moves farther than ``sum_j |D_j|
rho[k, j]`` nor than ``A(|D|) + Q(|D|) / 2`` (:mod:`kcplan.arm.bounds`: the global and the
lever bound with ``dq = D``, ``t = 1``), and a self pair's distance changes by no more than
the same with its own terms. Both bounds have nonnegative coefficients in ``|D_j|``, so
with ``|D_j| <= delta m_j`` they are at most ``delta v`` and ``delta A(m) + delta^2 Q(m) /
2``, ``v``, ``A(m)``, ``Q(m)`` the terms of the "edge" ``dq = m``. So every body and pair
stays clear while ``delta`` is below the radius ``r`` that the straight-edge certifier's
ball would give this guard for ``dq = m`` (:func:`kcplan.certification.arm_certifier.
stretch_radii`: ``max(d / v, t)`` with ``A t + Q t^2 / 2 = d``, the smallest over bodies and
pairs), and the blend, whose points all lie in that set, is free. The straight pieces
left between blends are parts of certified edges. (The twist and KC bounds of the edge
certifier need a straight motion in one signed direction and are not used.)

*Larger blends, along the curve.* A corner of a shortened path is often close to an
obstacle, which holds that one guard's radius to a few milliradians, while a blend many
times larger is free. So the curve itself is certified first, by conservative advancement
(:func:`kcplan.certification.certifier.advance`) in its parameter ``t``: ``B'(t) = 2 delta ((1 -
t) u1 + t u2)``, so ``|B'_j(t)| <= b_j = 2 delta m_j`` along the whole blend, and the proof
above holds for the curve with ``b`` in place of ``|dq|`` (the chain's bounds integrate
``|dq_j/dt|``, which any curve in the joint box has; :mod:`kcplan.arm.bounds`): a guard at
``B(t_m)`` proves ``|t - t_m| < r`` free, ``r`` from :func:`stretch_radii` with ``dq = b``
(the lever bound too: a lever grows at most at ``sum_i b_i rho[k, i]`` over the joints
below, whatever the curve). The blends stay in the joint box (the convex hull of ``a``,
``c``, ``b``, all in it), where ``rho`` holds. The largest blend is tried first, then
half of it (:data:`BLEND_SHRINK`), and so on, each with at most :data:`BLEND_GUARDS`
guards, down to the one the corner's guard proves. The compiled certifier advances
(``ArmCertifier::check_blend``, its guards' clearances capped at what each radius needs);
this module's advancement (``backend="python"``, every clearance measured) is its twin,
tested to agree.

Each blend also fits its segments: ``delta <= share * min(|W_i - W_{i-1}|, |W_{i+1} -
W_i|)``, so two blends never overlap. A guard costs one distance query of every body and
checked pair. The module imports neither OMPL nor FCL.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kcplan._kernel import ArmCertifier
from kcplan.arm.bounds import carries, point_speeds, relative_speeds
from kcplan.certification.arm_certifier import stretch_radii
from kcplan.certification.certifier import advance
from kcplan.trajectory.curve import TURN_FLOOR, BlendedPath, corner_directions

__all__ = ["BLEND_SHARE", "BlendCertificate", "certify_blends", "smooth_path"]

BLEND_SHARE = 0.5
"""The largest share of each adjacent segment a blend may take (so blends never meet)."""
BLEND_GUARDS = 24
"""Guards per try of a blend along its curve before a smaller one is tried."""
BLEND_SHRINK = 0.5
"""Each try's blend is this share of the last one's."""
RADIUS_MARGIN = 1.0 - 1e-9
"""Taken off the radius, as the edge certifier does, for rounding."""


@dataclass(frozen=True)
class BlendCertificate:
    """What :func:`certify_blends` proved.

    Attributes
    ----------
    blends : ndarray, shape (N - 2,)
        ``delta`` of each interior waypoint (radians of joint-space distance; 0 at a
        straight corner).
    radii : ndarray, shape (N - 2,)
        The radius each corner's guard proved (``inf`` at a straight corner).
    caps : ndarray, shape (N - 2,)
        What the segments allow each blend (``share`` of the shorter one).
    clearances : ndarray, shape (N - 2,)
        The smallest certain clearance of a body or pair at each corner, metres.
    queries : int
        Guards measured (one per corner that turns).
    """

    blends: NDArray[np.float64]
    radii: NDArray[np.float64]
    caps: NDArray[np.float64]
    clearances: NDArray[np.float64]
    queries: int

    def summary(self) -> dict:
        """Plain numbers for a trajectory file's ``certificate``."""
        turning = np.isfinite(self.radii)
        return {
            "blends": int(turning.sum()),
            "guards": self.queries,
            "smallest_blend": float(self.blends[turning].min(initial=np.inf)),
            "limited_by_clearance": int((self.radii[turning] < self.caps[turning]).sum()),
            "smallest_clearance": float(self.clearances[turning].min(initial=np.inf)),
        }


def certify_blends(
    world, waypoints: ArrayLike, share: float = BLEND_SHARE, backend: str = "kernel"
) -> BlendCertificate:
    """The largest blend at each corner of a certified path that is proved free (module
    docstring): along its own curve, or, at least, by the guard at its corner.

    Parameters
    ----------
    world : kcplan.arm.ArmWorld
        The scene the path was certified in (its bodies, checked self pairs and obstacles;
        the compiled twin measures).
    waypoints : array_like, shape (N, n)
        The path's joint vectors, within the limits; consecutive ones differ.
    share : float
        :data:`BLEND_SHARE`.
    backend : {"kernel", "python"}
        Who advances along a blend: the compiled certifier (``ArmCertifier.check_blend``,
        its guards' clearances capped at what each radius needs) or this module (every
        clearance measured; the twin). Both prove the same way; their guards may differ.

    Returns
    -------
    BlendCertificate
    """
    if backend not in ("kernel", "python"):
        raise ValueError(f"backend: expected 'kernel' or 'python', got {backend!r}")
    arm = world.arm
    W = np.asarray(waypoints, dtype=float)
    if W.ndim != 2 or W.shape[1] != arm.dof:
        raise ValueError(f"waypoints: expected joint vectors of {arm.dof} values, got {W.shape}")
    n_corners = max(len(W) - 2, 0)
    blends, radii = np.zeros(n_corners), np.full(n_corners, np.inf)
    clearances = np.full(n_corners, np.inf)
    if n_corners == 0:
        return BlendCertificate(blends, radii, radii.copy(), clearances, 0)
    u1, u2, lengths = corner_directions(W)
    caps = share * np.minimum(lengths[:-1], lengths[1:])
    pairs = world.self_pairs
    rho, C = point_speeds(arm), carries(arm)
    rho_pairs = relative_speeds(rho, C, pairs)
    only_first, only_second = C[pairs[:, 0]] & ~C[pairs[:, 1]], C[pairs[:, 1]] & ~C[pairs[:, 0]]
    kernel = world.kernel
    compiled = ArmCertifier(kernel, first_order=False) if backend == "kernel" else None
    dof = arm.dof
    first, second = pairs[:, 0], pairs[:, 1]
    queries = 0

    def radius(q: NDArray, b: NDArray, growth: NDArray) -> tuple[float, float]:
        """(the radius a guard at q gives a motion of joint speeds at most b, its clearance),
        ``growth`` the lever growth of b."""
        nonlocal queries
        queries += 1
        scene, pair_d = (np.asarray(x, dtype=float) for x in kernel.safe_clearances(q.tolist()))
        L = np.asarray(kernel.chain.levers(q.tolist())).reshape(-1, dof)
        pair_levers = L[first] * only_first + L[second] * only_second
        pair_growth = (growth[first] * only_first + growth[second] * only_second).sum(axis=1)
        r = min(
            stretch_radii(scene, rho @ b, L @ b, growth.sum(axis=1)).min(initial=np.inf),
            stretch_radii(pair_d, rho_pairs @ b, pair_levers @ b, pair_growth).min(initial=np.inf),
        )
        clearance = min(scene.min(initial=np.inf), pair_d.min(initial=np.inf))
        return (r * RADIUS_MARGIN if clearance > 0 else 0.0), clearance

    for i in range(n_corners):
        if np.linalg.norm(u2[i] - u1[i]) < TURN_FLOOR:
            continue
        c = W[i + 1]
        m = np.maximum(np.abs(u1[i]), np.abs(u2[i]))
        growth_m = np.asarray(kernel.chain.lever_growth(m.tolist())).reshape(-1, dof)
        radii[i], clearances[i] = radius(c, m, growth_m)  # the corner's guard: any blend
        delta = caps[i]
        while delta > radii[i]:  # larger blends, certified along their curve
            enter, leave = c - delta * u1[i], c + delta * u2[i]
            if compiled is not None:
                proved = compiled.check_blend(enter.tolist(), c.tolist(), leave.tolist(),
                                              BLEND_GUARDS)  # fmt: skip
            else:  # |B'_j(t)| <= speed_j all along the blend (module docstring)
                speed, growth = 2.0 * delta * m, (2.0 * delta) ** 2 * growth_m

                def reach(t, s0, s1, enter=enter, c=c, leave=leave, speed=speed, growth=growth):
                    point = (1 - t) ** 2 * enter + 2 * t * (1 - t) * c + t * t * leave
                    r, _ = radius(point, speed, growth)
                    return None if r <= 0.0 else (t - r, t + r)

                proved = advance(0.0, 1.0, BLEND_GUARDS, reach)[0] is None
            if proved:
                break
            delta *= BLEND_SHRINK
        blends[i] = min(max(delta, radii[i]), caps[i])
    if compiled is not None:
        queries += int(compiled.counters["guards"])
    return BlendCertificate(blends, radii, caps, clearances, queries)


def smooth_path(
    world, waypoints: ArrayLike, share: float = BLEND_SHARE
) -> tuple[BlendedPath, BlendCertificate]:
    """The path through ``waypoints`` with every corner blended as far as
    :func:`certify_blends` proves free."""
    certificate = certify_blends(world, waypoints, share)
    return BlendedPath(waypoints, certificate.blends), certificate
