"""The compiled planning loop of arms: RRT-Connect in the kernel, no Python per edge.

OMPL drives its planners from Python here: every edge a planner asks is one call from
OMPL into Python and one from Python into the kernel, and OMPL's nearest neighbours,
state copies and simplifier run around them (RESULTS 20.1: a lazy kc solve spends 27 %
in OMPL's neighbours and distances, 11 % in CPython). The ``wheel`` ships no C++ headers,
so OMPL's own loop cannot call the kernel directly; :class:`kcplan._kernel.ArmRRTConnect`
is RRT-Connect written beside the certifier instead (``kcplan/_kernel/arm_planner.hpp``):
sampling, a linear-scan nearest neighbour, extension, connection and shortcutting in C++,
each edge decided by a compiled :class:`kcplan._kernel.ArmMotionValidator`:

* ``kc-rrtconnect-native``: every tree edge certified (``CertifiedArmMotions``, the
  certifier of ``kc-rrtconnect``);
* ``kc-rrtconnect-lazy-native``: tree edges screened by probes every
  :data:`~kcplan.planning.lazy.LAZY_SCREEN_STEP` rad (``ScreenedArmMotions``), the found
  path certified edge by edge, a rejected edge repaired by a certified sub-plan
  (:mod:`kcplan.planning.lazy`'s scheme);
* ``rrtconnect-32-native`` and ``rrtconnect-native``: the stock twins on the same loop,
  checking states every 1/32 rad (:data:`~kcplan.planning.names.JOINT_STEP`) or every 1 %
  of the joint box's diagonal (OMPL's default resolution) on the same exact hulls
  (``DiscreteArmMotions``), not a proof.

All four take the kc planners' range (:data:`~kcplan.planning.names.ARM_RANGE` of the
joint box's diagonal, radians), shortcut the path with the same validator when asked,
and are seeded by ``seed`` (the same seed, the same path on the same machine).
"""

from __future__ import annotations

import secrets
from dataclasses import dataclass

from kcplan import _kernel
from kcplan.planning.lazy import REPAIR_SHARE

__all__ = ["NativeOutcome", "OMPL_RESOLUTION", "solve_natively"]

OMPL_RESOLUTION = 0.01
"""OMPL's default state validity checking resolution: a fraction of the space's maximum
extent (the joint box's diagonal), the step of ``rrtconnect-native``."""


@dataclass(frozen=True)
class NativeOutcome:
    """What :func:`solve_natively` did (times in seconds, joint vectors as lists).

    ``counters`` has the loop's own: ``native_iterations`` (samples), ``native_tree_states``,
    ``native_tree_edges`` (edges the trees asked), ``native_path_edges`` (lazy: path edges
    certified), ``native_repaired_edges``, ``native_attempts``, ``native_shortcut_edges``
    and, for the stock twins, ``native_checked_states``."""

    solved: bool
    time: float
    simplify_time: float
    states: list
    raw_states: list
    counters: dict


def solve_natively(
    setup,
    spec,
    start,
    goal,
    time_limit: float,
    seed: int | None,
    simplify: bool,
    kd_tree: bool = True,
) -> NativeOutcome:
    """Plan ``setup``'s arm from ``start`` to ``goal`` with the compiled RRT-Connect.

    Parameters
    ----------
    setup : kcplan.planning.setups.ArmSetup
        Its world's kernel and, for a kc planner (``spec.kc``), its validator's compiled
        certifier decide the edges.
    spec : kcplan.planning.problem.PlannerSpec
        A native planner's (``spec.native``): certified when ``spec.kc``, lazily when
        ``spec.lazy``; else discrete every ``spec.joint_step`` rad, or at
        :data:`OMPL_RESOLUTION` of the diagonal when None.
    start, goal : array_like, shape (dof,)
        Joint vectors within the limits.
    time_limit : float
        Seconds for the search; the shortcuts have as many again.
    seed : int or None
        The sampler's seed; None draws one.
    simplify : bool
        Shortcut the path (greedy, then random pairs of points; kcplan/_kernel/arm_planner.hpp).
    kd_tree : bool
        Nearest neighbours by a k-d tree; False: a linear scan (the ablation, the same
        neighbours).
    """
    world = setup.world.kernel
    extent = float(setup.space.getMaximumExtent())
    discrete = None
    if spec.kc:
        certifier = setup.validator.certifier.compiled
        certified = _kernel.CertifiedArmMotions(certifier)
        if spec.lazy:
            tree = _kernel.ScreenedArmMotions(certifier, setup.screen_step)
            planner = _kernel.ArmRRTConnect(world.chain, tree, certified)
        else:
            planner = _kernel.ArmRRTConnect(world.chain, certified)
    else:
        step = spec.joint_step if spec.joint_step is not None else OMPL_RESOLUTION * extent
        discrete = _kernel.DiscreteArmMotions(world, float(step))
        planner = _kernel.ArmRRTConnect(world.chain, discrete)
    seed = secrets.randbits(63) if seed is None else int(seed)
    plan, path, raw = planner.solve(
        [float(v) for v in start], [float(v) for v in goal], setup.kc_range * extent,
        float(time_limit), seed, bool(simplify), REPAIR_SHARE, bool(kd_tree),
    )  # fmt: skip
    counters = {
        f"native_{name}": getattr(plan, name)
        for name in ("iterations", "tree_states", "tree_edges", "path_edges",
                     "repaired_edges", "attempts", "shortcut_edges")
    }  # fmt: skip
    if discrete is not None:
        counters["native_checked_states"] = discrete.states
    return NativeOutcome(plan.solved, plan.solve_seconds, plan.simplify_seconds, path, raw,
                         counters)  # fmt: skip
