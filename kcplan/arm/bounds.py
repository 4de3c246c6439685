"""How far a point of a link can move along a joint-space edge: the chain's bounds.

For the straight edge ``q(s) = q1 + s (q2 - q1)``, ``s`` in ``[0, 1]``, a point ``x`` fixed
to body ``k`` moves with the velocity (Schwarzer, Saha and Latombe, T-RO 21(3), 2005,
Sec. III)

    dx/ds = sum_j dq_j (w_j x (x - o_j))   (revolute joint j: unit axis w_j through o_j)
          + sum_j dq_j w_j                  (prismatic joint j: unit axis w_j)

over the joints ``j`` of the group that carry body ``k`` (those on the path from the root
to the body's joint), with ``dq = q2 - q1``. ``|w_j x (x - o_j)|`` is the distance of ``x``
from joint ``j``'s axis, at most ``|x - o_j|``. So if ``rho[k, j]`` bounds ``|x - o_j|`` for
every point of body ``k`` and every configuration in the joint limits (and ``rho[k, j] =
1`` for a prismatic joint), integrating over ``[a, b]`` gives

    |x(b) - x(a)| <= (b - a) * sum_j |dq_j| rho[k, j]          (the body's *speed* bound)

``rho`` is configuration-independent: from joint ``j`` to body ``k`` the chain passes the
joint origins ``o_j = o_{i0}, o_{i1}, ..., o_{im}`` (``m`` joints down to the body's own
joint ``i_m``), and by the triangle inequality

    |x - o_j| <= sum_{l=1..m} |o_{il} - o_{i(l-1)}| + |c_k| + a_max,k

where ``|o_i - o_parent(i)|`` is the length of joint ``i``'s placement in its parent's
frame (Pinocchio: ``oMi = oMparent * jointPlacement_i * motion_i(q_i)``), plus, for a
prismatic joint ``i``, its largest slide ``max(|lower_i|, |upper_i|)``; ``c_k`` is the
body's centre in its joint's frame and ``a_max,k`` its largest semi-axis.

*Relative* motion of two bodies (self-collision): the joints that carry both bodies move
them as one rigid body, which changes no distance between them. In the frame of the
deepest joint that carries both (a moving frame, in which distances are the world's),
only the joints that carry exactly one of the two move their points, each no faster than
above (a point's distance from an axis is the same in every frame). So the distance
between any point of body ``k`` and any point of body ``l`` changes at most at the rate

    sum_{j carries k only} |dq_j| rho[k, j] + sum_{j carries l only} |dq_j| rho[l, j].

*Local* bounds at a guard. At the configuration ``q(m)`` the farthest point of body ``k``
from joint ``j``'s origin is ``lever[k, j] = |c_k - o_j| + a_max,k`` (centre and origin at
``q(m)``; :func:`levers`), usually far below ``rho[k, j]``. Along the edge that distance
changes only through the joints ``i`` below ``j`` that carry ``k`` (the joints above ``j``,
and ``j`` itself, move ``x`` and ``o_j`` rigidly together or turn ``x`` about an axis
through ``o_j``), each at most at ``|dq_i| rho[k, i]``. So within ``t`` of ``m``

    |x(s) - x(m)| <= t A_k + t^2 Q_k / 2,   A_k = sum_j |dq_j| lever[k, j],
                                             Q_k = sum_j |dq_j| sum_(i below j) |dq_i| rho[k, i]

(:func:`lever_growth` gives the terms of ``Q_k``; a prismatic joint's lever is 1 and does
not grow). A self pair's terms sum those of the joints that carry one body only, as for
its speed.

*First order* at a guard. The sum ``A_k`` adds every joint's contribution by its size;
the contributions are vectors and partly cancel. At ``q(m)`` body ``k`` moves rigidly with
angular velocity ``w = sum_j dq_j w_j`` (revolute ``j``) and centre velocity
``u = sum_j dq_j w_j x (c_k - o_j) + sum_j dq_j w_j`` (prismatic), signed ``dq``, so every
point moves at ``|u + w x (x - c_k)| <= |u| + |w| a_max,k =: A1_k`` (:func:`first_order_speeds`;
median half of ``A_k`` on random Panda edges). Along the edge the acceleration of a point
is, differentiating ``dx/ds`` once more (the axis ``w_j`` turns with the joints above ``j``
at most at ``S_j = sum_{i above j, revolute} |dq_i|``, and ``o_j`` moves with them),

    |d2x/ds2| <= M_k = sum_{j revolute} |dq_j| (2 S_j rho[k, j] + sum_{i <= j} |dq_i| rho[k, i])
                     + sum_{j prismatic} |dq_j| S_j          (i <= j: j and the joints below)

(:func:`point_accelerations`; ``rho[k, i] = 1`` for a prismatic ``i``): the first ``S_j``
term is the turning axis ``(Omega_j x w_j) x (x - o_j)``, the second the frame's own turn in
``w_j x (dx/ds - do_j/ds)``, the sum the joints from ``j`` down. By Taylor's theorem with
its integral remainder, within ``t`` of ``m``

    |x(s) - x(m)| <= A1_k t + M_k t^2 / 2.

*Relative first order* (self pairs). The joints that carry both bodies of a pair ``(k,
l)`` (the deepest of them ``J`` and the joints above it) move them as one rigid body. In
``J``'s frame every point of body ``k`` is a function of the other joints alone: the chain
from ``J`` down, as if ``J`` were fixed. So the first-order bound above, computed with the
steps of the joints that carry both set to 0, ``A1_k^J`` and ``M_k^J``
(:func:`relative_first_order`, :func:`relative_accelerations`), bounds how far a point of
``k`` moves in ``J``'s frame, and the same of ``l``; distances are the same in every frame,
so within ``t`` of ``m`` the distance between any point of ``k`` and any point of ``l``
changes by at most

    (A1_k^J + A1_l^J) t + (M_k^J + M_l^J) t^2 / 2.

These are the bounds of the clearance-ball certificate for arms: a body whose clearance
``d`` at ``q(m)`` exceeds ``min(v t, A t + Q t^2 / 2, A1 t + M t^2 / 2)`` stays free within
``t``, and so does a pair with its own terms.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from kcplan.arm.kinematics import body_frames, joint_axes, joint_frames

if TYPE_CHECKING:  # the model calls these functions: no import at run time
    from kcplan.arm.model import ArmModel

__all__ = [
    "carries",
    "first_order_speeds",
    "point_accelerations",
    "lever_growth",
    "levers",
    "chain_speeds",
    "pair_speeds",
    "point_speeds",
    "reach_ball",
    "relative_accelerations",
    "relative_first_order",
    "relative_speeds",
    "speeds",
    "turn_speeds",
    "twist_speeds",
    "twists",
]


def carries(arm: ArmModel, joints: Sequence[int] | None = None) -> NDArray[np.bool_]:
    """``C[k, j]``: joint ``j`` of the group (state order) carries body ``k`` (or the part
    carried by joint ``joints[k]`` of the reduced model), shape ``(parts, arm.dof)``."""
    model = arm.model
    state_of = {int(model.getJointId(name)): j for j, name in enumerate(arm.joints)}
    joints = [b.joint for b in arm.bodies] if joints is None else list(joints)
    out = np.zeros((len(joints), arm.dof), dtype=bool)
    for k, i in enumerate(joints):
        while i > 0:
            if i in state_of:
                out[k, state_of[i]] = True
            i = int(model.parents[i])
    return out


def point_speeds(arm: ArmModel) -> NDArray[np.float64]:
    """``rho[k, j]``: how far a point of body ``k`` moves per unit of joint ``j``'s motion
    (metres per radian, or 1 for a prismatic joint; 0 where ``j`` does not carry ``k``),
    for every configuration in the limits; shape ``(len(arm.bodies), arm.dof)``. See the
    module docstring for the proof."""
    joints = [b.joint for b in arm.bodies]
    reaches = [float(np.linalg.norm(b.placement[:3, 3]) + b.semi_axes.max()) for b in arm.bodies]
    return chain_speeds(arm, joints, reaches)


def chain_speeds(
    arm: ArmModel, joints: Sequence[int], reaches: Sequence[float]
) -> NDArray[np.float64]:
    """``rho[k, j]`` of :func:`point_speeds` for any parts: part ``k`` is carried by joint
    ``joints[k]`` of the reduced model and every point of it lies within ``reaches[k]`` of
    that joint's origin (a body's centre distance plus its largest semi-axis, or a mesh's
    farthest vertex). Shape ``(len(joints), arm.dof)``."""
    model = arm.model
    state_of = {int(model.getJointId(name)): j for j, name in enumerate(arm.joints)}
    # how far joint i's origin lies from its parent's, over the whole joint box
    hop = np.zeros(model.njoints)
    for i in range(1, model.njoints):
        hop[i] = float(np.linalg.norm(model.jointPlacements[i].translation))
        j = state_of.get(i)
        if j is not None and arm.kinds[j] == "prismatic":
            hop[i] += max(abs(arm.lower[j]), abs(arm.upper[j]))
    rho = np.zeros((len(joints), arm.dof))
    for k, (i, reach) in enumerate(zip(joints, reaches, strict=True)):
        while i > 0:  # walking up: reach is the bound on |x - o_i|
            if i in state_of:
                j = state_of[i]
                rho[k, j] = 1.0 if arm.kinds[j] == "prismatic" else reach
            reach += hop[i]
            i = int(model.parents[i])
    return rho


def _radial(p: NDArray, u: NDArray, c: float, sine: float, rho: float) -> float:
    """The largest distance from a parent joint's axis ``a`` of the disk ``x + w`` (``w``
    normal to a child's axis ``d``, ``|w| <= rho``) about a point ``x`` whose part normal
    to ``a`` is ``p``; ``u = d - c a`` (``c = a . d``, ``|u| = sine``). In the plane
    normal to ``a`` the disk projects to an ellipse of half axes ``rho`` (along ``a x d``)
    and ``rho |c|`` (along ``u``); with ``p = p_1 (a x d)^ + p_u u^``, Cauchy-Schwarz gives
    ``|p + w|^2 <= |p|^2 + 2 rho sqrt(p_1^2 + c^2 p_u^2) + rho^2``."""
    square = float(p @ p)
    along = float(p @ u) / sine if sine > 1e-12 else 0.0
    across = max(square - along * along, 0.0)
    return math.sqrt(square + 2.0 * rho * math.sqrt(across + c * c * along * along) + rho * rho)


def _joint_frame_vertices(body) -> NDArray[np.float64]:
    """A hull body's vertices in its joint's frame (the world's for joint 0), ``(m, 3)``."""
    return body.hull.vertices @ body.placement[:3, :3].T + body.placement[:3, 3]


def reach_ball(arm: ArmModel) -> tuple[NDArray[np.float64], float]:
    """A ball that holds every body of ``arm`` at every state within its limits: its
    centre ``(3,)`` and radius (metres). A point cloud keeps only the points whose balls
    meet it, grown by the padding (``World.set_reach``, kcplan/_kernel/point_cloud.hpp):
    no body ever meets the others, so every verdict stays that of the whole cloud.

    The proof bounds, from the leaves up, all that joint ``i`` carries over the whole
    joint box, in its frame before its own motion: by a ball of radius ``B`` about its
    origin, and by a cylinder about its axis ``a`` (an axial interval ``[lo, hi]`` and a
    radius ``rho``: a point ``z a + w``, ``w`` normal to ``a``, has ``z`` in the interval
    and ``|w| <= rho``). Turning about ``a`` moves no point out of either; a slide along
    ``a`` widens the interval by its limits and ``B`` by its largest. A body gives its own
    extents (a hull's vertices; an ellipsoid's centre and largest semi-axis). A child's
    points ``t + z d + w`` (its placement ``t``, its axis ``d`` in the parent's frame, ``c
    = a . d``) lie
      - axially within ``a . t + z c`` plus at most ``rho sqrt(1 - c^2)``,
      - radially within :func:`_radial` of ``t + z d`` (convex in ``z``: largest at an
        end),
      - within ``|t| + B`` of the parent's origin (the triangle inequality, as
        ``point_speeds`` adds the placements' lengths), and within ``sqrt(|t + z d|^2 + 2
        rho |t - (t . d) d| + rho^2)`` (``d . w = 0``), whichever is smaller;
    and the cylinder is cut to the ball (``rho <= B``, ``|z| <= B``). The first joint below
    the universe keeps its origin however the joints turn: when every moving body hangs
    from it, that origin is the centre and the radius the smaller of ``B`` and
    ``sqrt(max(lo^2, hi^2) + rho^2)``; else the centre is the world's origin and each such
    joint adds its placement's length. A body that never moves (joint 0) counts by its
    own distance from the centre (RESULTS 36.5)."""
    model = arm.model
    axes = arm.joint_axes()
    state_of = {int(model.getJointId(name)): j for j, name in enumerate(arm.joints)}
    n = model.njoints
    lo, hi, rho, ball = np.full(n, np.inf), np.full(n, -np.inf), np.zeros(n), np.zeros(n)

    def include(i: int, z_lo: float, z_hi: float, r: float, b: float) -> None:
        lo[i], hi[i] = min(lo[i], z_lo), max(hi[i], z_hi)
        rho[i], ball[i] = max(rho[i], r), max(ball[i], b)

    for b in arm.bodies:
        if b.joint == 0:
            continue
        a = axes[b.joint]
        if b.hull is not None:
            v = _joint_frame_vertices(b)
            z = v @ a
            radial = float(np.linalg.norm(v - np.outer(z, a), axis=1).max())
            include(b.joint, z.min(), z.max(), radial, float(np.linalg.norm(v, axis=1).max()))
        else:
            c, r = b.placement[:3, 3], float(b.semi_axes.max())
            include(b.joint, c @ a - r, c @ a + r, float(np.linalg.norm(c - (c @ a) * a)) + r,
                    float(np.linalg.norm(c)) + r)  # fmt: skip
    roots = []
    for i in range(n - 1, 0, -1):  # children before parents
        if not np.isfinite(lo[i]):
            continue  # carries nothing
        j = state_of.get(i)
        if j is not None and arm.kinds[j] == "prismatic":  # a slide of lower..upper
            lo[i], hi[i] = lo[i] + arm.lower[j], hi[i] + arm.upper[j]
            ball[i] += max(abs(arm.lower[j]), abs(arm.upper[j]))
        lo[i], hi[i], rho[i] = max(lo[i], -ball[i]), min(hi[i], ball[i]), min(rho[i], ball[i])
        parent = int(model.parents[i])
        if parent == 0:
            roots.append(i)
            continue
        placement = model.jointPlacements[i]
        t, d = np.asarray(placement.translation, dtype=float), placement.rotation @ axes[i]
        a = axes[parent]
        c = float(np.clip(a @ d, -1.0, 1.0))
        sine = math.sqrt(max(1.0 - c * c, 0.0))
        ends = [t + lo[i] * d, t + hi[i] * d]
        axial = [float(a @ e) for e in ends]
        across = float(np.linalg.norm(t - (t @ d) * d))
        far = max(math.sqrt(float(e @ e) + 2.0 * rho[i] * across + rho[i] ** 2) for e in ends)
        include(parent, min(axial) - rho[i] * sine, max(axial) + rho[i] * sine,
                max(_radial(e - (a @ e) * a, d - c * a, c, sine, rho[i]) for e in ends),
                min(float(np.linalg.norm(t)) + ball[i], far))  # fmt: skip
    reach = {k: min(ball[k], math.hypot(max(abs(lo[k]), abs(hi[k])), rho[k])) for k in roots}
    grow = 1.0 + 1e-9  # rounding: a few products of the numbers, each within 1e-15 of them
    if len(roots) == 1:
        centre = np.asarray(model.jointPlacements[roots[0]].translation, dtype=float)
        radius = reach[roots[0]] * grow
    else:
        centre = np.zeros(3)
        radius = max((float(np.linalg.norm(model.jointPlacements[k].translation)) + reach[k])
                     * grow for k in roots) if roots else 0.0  # fmt: skip
    for b in arm.bodies:  # the bodies that never move, by their own place
        if b.joint == 0:
            if b.hull is not None:
                far = float(np.linalg.norm(_joint_frame_vertices(b) - centre, axis=1).max())
            else:
                far = float(np.linalg.norm(b.placement[:3, 3] - centre) + b.semi_axes.max())
            radius = max(radius, far * grow)
    return centre, radius


def speeds(arm: ArmModel, q1: Sequence[float], q2: Sequence[float]) -> NDArray[np.float64]:
    """Bound on how far any point of each body moves over the whole edge ``q1 -> q2``
    (per unit of the edge parameter ``s``), shape ``(len(arm.bodies),)``, metres."""
    dq = np.abs(np.asarray(q2, dtype=float) - np.asarray(q1, dtype=float))
    return point_speeds(arm) @ dq


def relative_speeds(
    rho: NDArray[np.float64], C: NDArray[np.bool_], pairs: NDArray[np.int64]
) -> NDArray[np.float64]:
    """``rho_pair[m, j]``: how fast the distance between a point of part ``k`` and a
    point of part ``l``, ``(k, l) = pairs[m]``, can change per unit of joint ``j``'s
    motion: only the joints that carry one of the two count (module docstring). From
    ``rho`` (:func:`chain_speeds`) and ``C`` (:func:`carries`) of the same parts; shape
    ``(len(pairs), dof)``."""
    first, second = pairs[:, 0], pairs[:, 1]
    return rho[first] * (C[first] & ~C[second]) + rho[second] * (C[second] & ~C[first])


def _common_masks(C: NDArray[np.bool_], pairs: NDArray[np.int64]) -> tuple[NDArray, NDArray]:
    """The distinct sets of joints that carry both bodies of a pair (rows of ``(masks,
    dof)``, True: carries both) and each pair's row, ``(len(pairs),)``."""
    common = C[pairs[:, 0]] & C[pairs[:, 1]]
    masks, which = np.unique(common.reshape(len(pairs), -1), axis=0, return_inverse=True)
    return masks.reshape(-1, C.shape[1]), which.reshape(-1)


def relative_first_order(
    arm: ArmModel, state: Sequence[float], dq: Sequence[float], pairs: NDArray[np.int64]
) -> NDArray[np.float64]:
    """``A1_k^J + A1_l^J`` of each self pair ``(k, l) = pairs[m]`` at ``state`` along the
    signed joint step ``dq``: the first-order speeds of both bodies in the frame of the
    joints that carry both (module docstring, *Relative first order*); shape
    ``(len(pairs),)``, metres per unit of the edge parameter."""
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    masks, which = _common_masks(carries(arm), pairs)
    step = np.asarray(dq, dtype=float)
    out = np.zeros(len(pairs))
    for row, mask in enumerate(masks):
        speeds = first_order_speeds(arm, state, np.where(mask, 0.0, step))
        chosen = which == row
        out[chosen] = speeds[pairs[chosen, 0]] + speeds[pairs[chosen, 1]]
    return out


def relative_accelerations(
    arm: ArmModel, dq: Sequence[float], pairs: NDArray[np.int64]
) -> NDArray[np.float64]:
    """``M_k^J + M_l^J`` of each self pair ``(k, l) = pairs[m]`` for joint steps ``|dq|``:
    the largest accelerations of both bodies' points in the frame of the joints that carry
    both, anywhere along the edge (module docstring, *Relative first order*); shape
    ``(len(pairs),)``."""
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    masks, which = _common_masks(carries(arm), pairs)
    step = np.abs(np.asarray(dq, dtype=float))
    out = np.zeros(len(pairs))
    for row, mask in enumerate(masks):
        accel = point_accelerations(arm, np.where(mask, 0.0, step))
        chosen = which == row
        out[chosen] = accel[pairs[chosen, 0]] + accel[pairs[chosen, 1]]
    return out


def pair_speeds(
    arm: ArmModel, q1: Sequence[float], q2: Sequence[float], pairs: NDArray[np.int64]
) -> NDArray[np.float64]:
    """Bound on how fast the distance between a point of body ``k`` and a point of body
    ``l`` can change along ``q1 -> q2``, for every pair ``(k, l)`` of ``pairs`` (shape
    ``(m, 2)``): :func:`relative_speeds` of the bodies. Shape ``(m,)``, metres per unit
    of ``s``."""
    dq = np.abs(np.asarray(q2, dtype=float) - np.asarray(q1, dtype=float))
    return relative_speeds(point_speeds(arm), carries(arm), pairs) @ dq


def levers(arm: ArmModel, state: Sequence[float]) -> NDArray[np.float64]:
    """``lever[k, j]``: the farthest any point of body ``k`` lies from joint ``j``'s origin
    at ``state`` (``|c_k - o_j| + a_max,k``; 1 for a prismatic joint; 0 where ``j`` does not
    carry ``k``), shape ``(len(arm.bodies), arm.dof)``; never above :func:`point_speeds`."""
    model = arm.model
    state_of = {int(model.getJointId(name)): j for j, name in enumerate(arm.joints)}
    joints, bodies = joint_frames(arm, state), body_frames(arm, state)
    out = np.zeros((len(arm.bodies), arm.dof))
    for k, body in enumerate(arm.bodies):
        i = body.joint
        while i > 0:
            j = state_of[i]
            if arm.kinds[j] == "prismatic":
                out[k, j] = 1.0
            else:
                centre, origin = bodies[k][:3, 3], joints[i][:3, 3]
                out[k, j] = np.linalg.norm(centre - origin) + body.semi_axes.max()
            i = int(model.parents[i])
    return out


def lever_growth(arm: ArmModel, dq: Sequence[float]) -> NDArray[np.float64]:
    """``G[k, j] = |dq_j| sum_i |dq_i| rho[k, i]`` over the joints ``i`` below ``j`` that
    carry body ``k``: the rate at which ``|dq_j| lever[k, j]`` can grow per unit of ``s``
    (module docstring; 0 for a prismatic ``j``), shape ``(len(arm.bodies), arm.dof)``."""
    model = arm.model
    state_of = {int(model.getJointId(name)): j for j, name in enumerate(arm.joints)}
    rho, step = point_speeds(arm), np.abs(np.asarray(dq, dtype=float))
    out = np.zeros((len(arm.bodies), arm.dof))
    for k, body in enumerate(arm.bodies):
        below, i = 0.0, body.joint
        while i > 0:
            j = state_of[i]
            if arm.kinds[j] != "prismatic":
                out[k, j] = step[j] * below
            below += step[j] * rho[k, j]
            i = int(model.parents[i])
    return out


def twists(
    arm: ArmModel, state: Sequence[float], dq: Sequence[float]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The bodies' twists at ``state`` along the signed joint step ``dq``: ``w[k]`` the
    angular velocity of body ``k`` and ``u[k]`` the velocity of its centre, per unit of the
    edge parameter (module docstring, *First order*), each of shape
    ``(len(arm.bodies), 3)``, world frame (rad and metres)."""
    model = arm.model
    state_of = {int(model.getJointId(name)): j for j, name in enumerate(arm.joints)}
    step = np.asarray(dq, dtype=float)
    joints, bodies, local = joint_frames(arm, state), body_frames(arm, state), joint_axes(arm)
    w = np.zeros((model.njoints, 3))  # angular velocity of each joint's frame
    u = np.zeros((model.njoints, 3))  # with w: the velocity of a point x is w x x + u
    for i in range(1, model.njoints):
        parent = int(model.parents[i])
        w[i], u[i] = w[parent], u[parent]
        j = state_of.get(i)
        if j is None:
            continue
        axis = joints[i][:3, :3] @ local[i]
        if arm.kinds[j] == "prismatic":
            u[i] = u[i] + step[j] * axis
        else:
            w[i] = w[i] + step[j] * axis
            u[i] = u[i] - step[j] * np.cross(axis, joints[i][:3, 3])
    at = [body.joint for body in arm.bodies]
    centres = np.array([frame[:3, 3] for frame in bodies]).reshape(-1, 3)
    return w[at], np.cross(w[at], centres) + u[at]


def first_order_speeds(arm: ArmModel, state: Sequence[float], dq: Sequence[float]) -> NDArray:
    """``A1[k] = |u_k| + |w_k| a_max,k``: the fastest any point of body ``k`` moves at
    ``state`` along the joint step ``dq`` (signed, per unit of the edge parameter), from
    the body's exact twist there (:func:`twists`; module docstring, *First order*); shape
    ``(len(arm.bodies),)``, metres."""
    return twist_speeds(arm, *twists(arm, state, dq))


def twist_speeds(arm: ArmModel, w: NDArray, u: NDArray) -> NDArray[np.float64]:
    """``|u_k| + |w_k| a_max,k`` of the bodies' twists ``(w, u)`` (:func:`twists`): what
    :func:`first_order_speeds` gives, for twists already at hand; shape
    ``(len(arm.bodies),)``."""
    a_max = np.array([body.semi_axes.max() for body in arm.bodies])
    return np.linalg.norm(u, axis=1) + np.linalg.norm(w, axis=1) * a_max


def turn_speeds(arm: ArmModel, dq: Sequence[float]) -> NDArray[np.float64]:
    """``turn[k] = sum_j |dq_j|`` over the revolute joints ``j`` that carry body ``k``: the
    body's angular velocity along an edge of joint step ``dq`` is ``sum_j dq_j w_j`` (unit
    axes ``w_j``), so it turns at most this far per unit of the edge parameter, anywhere
    along the edge; shape ``(len(arm.bodies),)``, radians."""
    revolute = np.array([kind != "prismatic" for kind in arm.kinds])
    return (carries(arm) & revolute) @ np.abs(np.asarray(dq, dtype=float))


def point_accelerations(arm: ArmModel, dq: Sequence[float]) -> NDArray[np.float64]:
    """``M[k]``: the largest acceleration (per unit of the edge parameter, squared) of any
    point of body ``k`` anywhere along an edge of joint step ``dq`` in the limits (module
    docstring, *First order*); shape ``(len(arm.bodies),)``, metres."""
    model = arm.model
    state_of = {int(model.getJointId(name)): j for j, name in enumerate(arm.joints)}
    rho, step = point_speeds(arm), np.abs(np.asarray(dq, dtype=float))
    turning = np.zeros(model.njoints)  # S: how fast each joint's frame turns at most
    for i in range(1, model.njoints):
        parent, j = int(model.parents[i]), state_of.get(int(model.parents[i]))
        turning[i] = turning[parent] + (
            step[j] if j is not None and arm.kinds[j] != "prismatic" else 0.0
        )
    out = np.zeros(len(arm.bodies))
    for k, body in enumerate(arm.bodies):
        below, i = 0.0, body.joint
        while i > 0:
            j = state_of[i]
            below += step[j] * rho[k, j]
            if arm.kinds[j] == "prismatic":
                out[k] += step[j] * turning[i]
            else:
                out[k] += step[j] * (2.0 * turning[i] * rho[k, j] + below)
            i = int(model.parents[i])
    return out
