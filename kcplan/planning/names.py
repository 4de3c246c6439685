"""Planner names, importable without loading OMPL (for the command line's help)."""

CERTIFIABLE = (
    "rrt",
    "rrtstar",
    "informedrrtstar",
    "sorrtstar",
    "aorrtc",
    "prmstar",
    "fmt",
    "bfmt",
    "bitstar",
)
"""OMPL planners (besides RRT-Connect and PRM) that reach the motion validator only through
the two-argument ``checkMotion``: each is offered stock, as ``kc-<name>`` and as
``ca-<name>``. The asymptotically optimal ones run to the time limit."""

LAST_VALID = ("kpiece1", "bkpiece1", "lbkpiece1")
"""OMPL planners that ask the motion validator for the last valid state: offered stock only."""

STOCK = ("rrtconnect", "prm", "rrtconnect-fine", "prm-fine", *CERTIFIABLE, *LAST_VALID)
"""Stock OMPL planners: OMPL's discrete motion validator on the kernel's compiled collision
query; each also as ``<name>-fcl``, the same on python-fcl (what a Python user writes by
hand)."""

JOINT_STEP = 1.0 / 32.0
"""The largest step between the states that ``rrtconnect-32`` and ``prm-32`` check on an
edge, radians of joint-space distance (OMPL's: the L2 norm of the joint difference), as
VAMP's 1/32 rad resolution."""

ARM_RANGE = 0.05
"""RRT-Connect's range on an arm for the kc planners (and the stock ``-near`` twins), as a
fraction of the joint box's diagonal; OMPL's default is 0.2. A certificate's work grows
with the edge's length and an edge is more often rejected after it: on box_1 and
bookshelf_small_2 (5 seeds) 0.05 took kc-rrtconnect's median from 0.043 to 0.032 s and
from 0.71 to 0.085 s (RESULTS 11)."""

OMPL_RANGE = 0.2
"""OMPL's default range of RRT-Connect (and the other tree planners), as a fraction of the
state space's maximum extent: what the stock planners keep."""

RIGID_RANGE = 0.05
"""The range of the kc planners (and of the stock ``rrtconnect-near``) on a rigid robot,
as a fraction of the state space's maximum extent; OMPL's default is 0.2. As on arms, a
certificate's work grows with the edge's length and a long edge is more often rejected
after its guards were paid: on HRM's maze and cluttered map with the rabbit (10 seeds)
kc-rrtconnect's median went from 0.60 to 0.13 s and from 0.15 to 0.08 s (RESULTS 16.6).
Stock RRT-Connect gains from it too (``rrtconnect-near``)."""

ARM_ONLY = {
    "rrtconnect-32-near": "rrtconnect-32 with the kc planners' range on arms (ARM_RANGE)",
    "rrtconnect-32": "stock RRT-Connect checking an edge every 1/32 rad of joint-space "
    "distance, which only an arm's joint space has",
    "prm-32": "stock PRM checking an edge every 1/32 rad of joint-space distance, which "
    "only an arm's joint space has",
    "rrtconnect-pin": "stock RRT-Connect checking states with Pinocchio's computeCollisions "
    "on the link covers of a URDF robot",
    "kc-rrtconnect-native": "RRT-Connect compiled beside the arm certifier, every edge "
    "certified (kcplan.planning.native)",
    "kc-rrtconnect-lazy-native": "kc-rrtconnect-native screening its trees' edges and "
    "certifying the path it returns, as kc-rrtconnect-lazy",
    "kc-rrtconnect-lazy-native-scan": "ablation: kc-rrtconnect-lazy-native finding nearest "
    "neighbours by a linear scan",
    "rrtconnect-32-native": "the compiled RRT-Connect checking an edge every 1/32 rad of "
    "joint-space distance on the same hulls (the stock twin of kc-rrtconnect-native)",
    "rrtconnect-native": "the compiled RRT-Connect checking an edge at OMPL's default "
    "resolution (1 % of the joint box's diagonal) on the same hulls",
}
"""Planners for arms only, with what they are (the reason a rigid robot is refused)."""

SINGLE_ELLIPSOID_ONLY = {
    "kc-rrtconnect-paper": "kc-rrtconnect with the paper's KC polytope only",
    "kc-prm-paper": "kc-prm with the paper's KC polytope only",
}
"""Planners whose certificate is the paper's polytope, which holds for one ellipsoid centred
at the robot's origin (``E_a``) only, with what they are (the reason another robot is
refused)."""

PLANNER_NAMES = (
    "kc-rrtconnect",
    "kc-prm",
    "ca-rrtconnect",
    "ca-prm",
    "kc-rrtconnect-paper",
    "kc-prm-paper",
    "kc-rrtconnect-lazy",
    "kc-rrtconnect-lazy-restart",
    "kc-rrtconnect-wide",
    "kc-rrtconnect-discrete",
    "kc-rrtconnect-noprobe",
    "kc-rrtconnect-lever",
    "kc-rrtconnect-learnall",
    "kc-rrtconnect-noparts",
    "kc-rrtconnect-nofirst",
    "kc-rrtconnect-nocache",
    "kc-rrtconnect-noplanes",
    "kc-prm-noprobe",
    "kc-rrtconnect-py",
    "kc-prm-py",
    *STOCK,
    "rrtconnect-near",
    *ARM_ONLY,
    *(f"{name}-fcl" for name in STOCK),
    *(f"kc-{name}" for name in CERTIFIABLE),
    *(f"ca-{name}" for name in CERTIFIABLE),
)

REFUSED_PLANNERS = {
    f"{kind}-{name}": (
        f"{name.upper()} asks the motion validator for the last valid state of a rejected "
        "edge (checkMotion with lastValid), which the OMPL Python binding never passes to "
        "a Python validator, so a rejected edge would count as wholly invalid; use the "
        f"stock {name} or another kc planner"
    )
    for kind in ("kc", "ca")
    for name in LAST_VALID
}
"""Certified variants refused on purpose, with the reason given to the user."""


DEFAULT_PLANNER = "kc-rrtconnect"
"""The planner of a rigid robot when none is named: the eager certified RRT-Connect. The
lazy one loses on the smallest narrow passages, where nearly every screened edge ends on
the path and is certified as well (1.2-1.35x; RESULTS 18.2)."""

DEFAULT_ARM_PLANNER = "kc-rrtconnect-lazy-native"
"""The planner of an arm when none is named: the lazy kc planner of the compiled loop
(:mod:`kcplan.planning.native`). On 70 MBM Panda problems, with simplification, it solves
in 0.89x the time of ``kc-rrtconnect-lazy`` (OMPL's loop, the same certifier) and its
shortcuts take 1.75 ms against OMPL's simplifier's 18.6 (median per problem), for paths
10 % longer (5.33 against 4.86 rad); 0 colliding paths (RESULTS 26.2). On clouds the
whole plan goes from 323 to 73 ms per problem (RESULTS 26.3). ``kc-rrtconnect-lazy`` and
the eager planners stay one name away."""


def default_planner(arm: bool) -> str:
    """The planner used when none is named: :data:`DEFAULT_ARM_PLANNER` for an arm,
    :data:`DEFAULT_PLANNER` for a rigid robot."""
    return DEFAULT_ARM_PLANNER if arm else DEFAULT_PLANNER


def check_planner_name(name: str, arm: bool | None = None, single: bool | None = None) -> str:
    """``name`` if it is a planner; otherwise ``ValueError`` with one line saying why.

    ``arm=False`` (a rigid robot's scenario) also refuses the planners of
    :data:`ARM_ONLY`; ``single=False`` (a robot other than one ellipsoid centred at its
    origin, :attr:`kcplan.geometry.robot.Robot.is_single`) those of
    :data:`SINGLE_ELLIPSOID_ONLY`; None checks the name alone."""
    if name in REFUSED_PLANNERS:
        raise ValueError(f"{name}: refused: {REFUSED_PLANNERS[name]}")
    if name not in PLANNER_NAMES:
        raise ValueError(f"expected a planner name ({', '.join(PLANNER_NAMES)}), got {name!r}")
    if arm is False and name in ARM_ONLY:
        raise ValueError(f"{name}: for arms only: {ARM_ONLY[name]}; this robot is rigid")
    if single is False and name in SINGLE_ELLIPSOID_ONLY:
        raise ValueError(
            f"{name}: {SINGLE_ELLIPSOID_ONLY[name]}, which needs one ellipsoid centred at the "
            "robot's origin; this robot is not (use the kc-* planners)"
        )
    return name


def check_planner_for(name: str, scenario) -> str:
    """:func:`check_planner_name` for the robot of ``scenario`` (an arm's, with ``arm``
    set, or a rigid robot's ``Scenario``): the arm-only planners refuse a rigid robot, the
    paper's any robot but one ellipsoid centred at its origin."""
    arm = getattr(scenario, "arm", None) is not None
    return check_planner_name(name, arm=arm, single=None if arm else scenario.robot.is_single)

