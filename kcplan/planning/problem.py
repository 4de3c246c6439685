"""Planning a scenario with stock OMPL planners, with or without the KC validator.

Every planner runs through :func:`plan`, the same setup code: the same state space and
bounds, the same FCL state validity checker, the same start and goal. The only
differences are the planner and, for the ``kc-*`` planners, the motion validator. What
depends on the robot's kind (rigid or arm) is :mod:`kcplan.planning.setups`'
:class:`~kcplan.planning.setups.ProblemSetup`, chosen once per problem.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field, replace

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from kcplan.arm.scenario import ArmScenario
from kcplan.arm.verify import verify_arm_path
from kcplan.certification.certifier import CERTIFICATE_SETS, DEFAULT_PROBES
from kcplan.planning.lazy import solve_lazily
from kcplan.planning.names import (
    CERTIFIABLE,
    JOINT_STEP,
    OMPL_RANGE,
    PLANNER_NAMES,
    STOCK,
    check_planner_for,
    check_planner_name,
    default_planner,
)
from kcplan.planning.native import solve_natively
from kcplan.planning.progress import ProgressRecorder, reports_progress
from kcplan.planning.setups import setup_for
from kcplan.planning.verify import PathCheck, verify_path
from kcplan.scenarios import as_scenario
from kcplan.world.collision import CollisionWorld
from kcplan.world.scenario import Scenario

__all__ = ["PLANNERS", "PlannerSpec", "PlanResult", "plan", "seed_ompl"]


@dataclass(frozen=True)
class PlannerSpec:
    """A registered planner: the OMPL class and the motion validator's certificates.

    ``certificates`` is None for a stock planner (OMPL's discrete validator at
    ``resolution``, OMPL's default when None); otherwise the names the
    :class:`KCMotionValidator` uses (:data:`CERTIFICATE_SETS`). ``backend`` says who
    checks: ``"kernel"`` (the compiled kernel on coal: the certifier of a kc planner, the
    collision query of a stock one) or ``"python"`` (the Python certifier on python-fcl;
    for a stock planner the python-fcl state checker; ``"pin"``: an arm's Python
    ``isValid`` on Pinocchio, :mod:`kcplan.planning.pin_checker`). ``joint_step`` (arms,
    stock): the largest step between the states the discrete validator checks on an
    edge, radians of OMPL's joint-space distance (the L2 norm of the joint difference);
    the resolution is set to ``joint_step / space.getMaximumExtent()`` at setup.
    """

    make: type
    certificates: tuple[str, ...] | None = None
    fallback: str = "bisection"
    description: str = ""
    resolution: float | None = None  # OMPL's state validity checking resolution (stock)
    range_factor: float | None = None  # RRT-Connect range, fraction of the maximum extent
    near: bool = False  # stock: the kc planners' range (ARM_RANGE, RIGID_RANGE), not OMPL's
    neighbors: int | None = None  # PRM's maximum nearest neighbours (OMPL default 10)
    backend: str = "kernel"
    probes: int = DEFAULT_PROBES  # collision probes per edge before its guards (kc)
    joint_step: float | None = None  # arms (stock): largest checked step, rad of L2 distance
    part_balls: bool = True  # arms (kc, kernel): far groups of self pairs decided at once
    first_order: bool = True  # arms (kc): the bodies' twist at a guard bounds them as well
    guard_cache: bool = True  # arms (kc): guards and state checks remembered across edges
    arm_certificates: tuple[str, ...] | None = None  # arms (kc): the validator's, if not by kind
    learn_schedule: bool = True  # rigid (kc): the grid learns cells only while it pays
    lazy: bool = False  # kc: screen the trees' edges, certify the path (planning.lazy)
    lazy_repair: bool = True  # lazy: a rejected edge replaced by a certified sub-plan
    native: bool = False  # arms: the compiled RRT-Connect (planning.native), not OMPL's
    kd_tree: bool = True  # native: nearest neighbours by a k-d tree (False: a linear scan)

    @property
    def kc(self) -> bool:
        """Whether the planner's edges are certified (a :class:`KCMotionValidator`)."""
        return self.certificates is not None


_KC, _CA, _PAPER = CERTIFICATE_SETS["kc"], CERTIFICATE_SETS["ca"], CERTIFICATE_SETS["kc-paper"]
PLANNERS: dict[str, PlannerSpec] = {
    "kc-rrtconnect": PlannerSpec(
        og.RRTConnect,
        _KC,
        description="stock RRT-Connect, edges certified by free-region planes (exact), "
        "range RIGID_RANGE (OMPL's default: 0.2 x the space's maximum extent); arms: the "
        "chain's clearance balls, the KC guards and the free-region planes, range ARM_RANGE",
    ),
    "kc-rrtconnect-lazy": PlannerSpec(
        og.RRTConnect,
        _KC,
        description="kc-rrtconnect that screens its trees' edges by probes and certifies "
        "only the path it returns, replacing an edge the certificate rejects by a certified "
        "sub-plan, or starting again with denser probes (kcplan.planning.lazy)",
        lazy=True,
    ),
    "kc-rrtconnect-lazy-restart": PlannerSpec(
        og.RRTConnect,
        _KC,
        description="ablation: kc-rrtconnect-lazy that starts again at once when the "
        "certificate rejects an edge of its path, without trying to repair it",
        lazy=True,
        lazy_repair=False,
    ),
    "kc-rrtconnect-wide": PlannerSpec(
        og.RRTConnect,
        _KC,
        description="ablation: kc-rrtconnect at OMPL's default range (0.2 x the space's "
        "maximum extent), not the kc planners' shorter one",
        range_factor=OMPL_RANGE,
    ),
    "kc-prm": PlannerSpec(
        og.PRM, _KC, description="stock PRM, roadmap edges certified like kc-rrtconnect"
    ),
    "ca-rrtconnect": PlannerSpec(
        og.RRTConnect,
        _CA,
        description="ablation: kc-rrtconnect with the plain clearance ball only "
        "(classic conservative advancement; arms: without the KC guards)",
    ),
    "ca-prm": PlannerSpec(og.PRM, _CA, description="ablation: kc-prm with the clearance ball only"),
    "kc-rrtconnect-paper": PlannerSpec(
        og.RRTConnect,
        _PAPER,
        description="ablation: kc-rrtconnect with the paper's KC polytope only",
    ),
    "kc-prm-paper": PlannerSpec(
        og.PRM, _PAPER, description="ablation: kc-prm with the paper's KC polytope only"
    ),
    "kc-rrtconnect-discrete": PlannerSpec(
        og.RRTConnect,
        _KC,
        "discrete",
        "RRT-Connect with endpoint guards, then OMPL-style sampling (the design card's "
        "plain variant; not exact)",
    ),
    "kc-rrtconnect-noprobe": PlannerSpec(
        og.RRTConnect,
        _KC,
        description="ablation: kc-rrtconnect without collision probes before the guards",
        probes=0,
    ),
    "kc-rrtconnect-lever": PlannerSpec(
        og.RRTConnect,
        CERTIFICATE_SETS["kc-lever"],
        description="ablation: kc-rrtconnect whose free regions bound an offset body's "
        "centre by the lever rule alone, without its arc (rigid robots; arms: as "
        "kc-rrtconnect)",
    ),
    "kc-rrtconnect-learnall": PlannerSpec(
        og.RRTConnect,
        _KC,
        description="ablation: kc-rrtconnect whose occupancy grid tests the cell of every "
        "colliding state, not only while it pays (rigid robots; arms: as kc-rrtconnect)",
        learn_schedule=False,
    ),
    "kc-rrtconnect-noparts": PlannerSpec(
        og.RRTConnect,
        _KC,
        description="ablation (arms): kc-rrtconnect whose guard radii look at every self "
        "pair, without the links' balls that decide far groups of pairs at once (the "
        "world's state checks, every planner's, use those balls either way)",
        part_balls=False,
    ),
    "kc-rrtconnect-nocache": PlannerSpec(
        og.RRTConnect,
        _KC,
        description="ablation (arms): kc-rrtconnect whose certifier remembers one guard and "
        "one state check, not every state's across edges (an edge's end guards are "
        "measured again at every edge that shares the state)",
        guard_cache=False,
    ),
    "kc-rrtconnect-noplanes": PlannerSpec(
        og.RRTConnect,
        _KC,
        description="ablation (arms): kc-rrtconnect without the free-region planes (a link "
        "stays free of an obstacle while it does not cross the slab between them; rigid "
        "robots: as kc-rrtconnect)",
        arm_certificates=("ball", "kc"),
    ),
    "kc-rrtconnect-nofirst": PlannerSpec(
        og.RRTConnect,
        _KC,
        description="ablation (arms): kc-rrtconnect bounding the bodies' motion near a guard "
        "by the chain's levers alone, without their twist there (first order)",
        first_order=False,
    ),
    "kc-prm-noprobe": PlannerSpec(
        og.PRM,
        _KC,
        description="ablation: kc-prm without collision probes before the guards",
        probes=0,
    ),
    "kc-rrtconnect-py": PlannerSpec(
        og.RRTConnect,
        _KC,
        description="ablation: kc-rrtconnect decided by the Python certifier on python-fcl "
        "(the reference the compiled kernel replaces)",
        backend="python",
    ),
    "kc-prm-py": PlannerSpec(
        og.PRM,
        _KC,
        description="ablation: kc-prm decided by the Python certifier on python-fcl",
        backend="python",
    ),
    "rrtconnect": PlannerSpec(og.RRTConnect, description="stock RRT-Connect"),
    "prm": PlannerSpec(og.PRM, description="stock PRM"),
    "rrtconnect-fine": PlannerSpec(
        og.RRTConnect,
        description="stock RRT-Connect, discrete validator at 0.1 % of the extent "
        "(10 times finer than OMPL's default; safer, still not exact)",
        resolution=0.001,
    ),
    "prm-fine": PlannerSpec(
        og.PRM,
        description="stock PRM, discrete validator at 0.1 % of the extent",
        resolution=0.001,
    ),
}
_OMPL = {
    "rrt": (og.RRT, "RRT"),
    "rrtstar": (og.RRTstar, "RRT* (runs to the time limit)"),
    "informedrrtstar": (og.InformedRRTstar, "Informed RRT* (runs to the time limit)"),
    "sorrtstar": (og.SORRTstar, "SORRT* (runs to the time limit)"),
    "aorrtc": (og.AORRTC, "AORRTC (runs to the time limit)"),
    "prmstar": (og.PRMstar, "PRM* (runs to the time limit)"),
    "fmt": (og.FMT, "FMT*"),
    "bfmt": (og.BFMT, "bidirectional FMT*"),
    "bitstar": (og.BITstar, "BIT* (runs to the time limit)"),
    "kpiece1": (og.KPIECE1, "KPIECE1 (stock only: it needs lastValid)"),
    "bkpiece1": (og.BKPIECE1, "BKPIECE1 (stock only: it needs lastValid)"),
    "lbkpiece1": (og.LBKPIECE1, "LBKPIECE1 (stock only: it needs lastValid)"),
}
for _name, (_make, _what) in _OMPL.items():
    PLANNERS[_name] = PlannerSpec(_make, description=f"stock {_what}")
for _name in CERTIFIABLE:
    _make, _what = _OMPL[_name]
    PLANNERS[f"kc-{_name}"] = PlannerSpec(
        _make, _KC, description=f"{_what}, edges certified like kc-rrtconnect"
    )
    PLANNERS[f"ca-{_name}"] = PlannerSpec(
        _make, _CA, description=f"ablation: kc-{_name} with the clearance ball only"
    )
for _name in STOCK:
    _spec = PLANNERS[_name]
    PLANNERS[f"{_name}-fcl"] = replace(
        _spec,
        description=f"{_spec.description}, states checked by python-fcl (by hand in Python)",
        backend="python",
    )
for _name, _make, _what in (("rrtconnect", og.RRTConnect, "RRT-Connect"), ("prm", og.PRM, "PRM")):
    PLANNERS[f"{_name}-32"] = PlannerSpec(
        _make,
        description=f"stock {_what}, arms only: discrete validator stepping at most 1/32 rad "
        "of joint-space distance (the L2 norm of the joint difference), like VAMP's",
        joint_step=JOINT_STEP,
    )
PLANNERS["rrtconnect-near"] = replace(
    PLANNERS["rrtconnect"],
    description="stock RRT-Connect with the kc planners' range (ARM_RANGE on arms, "
    "RIGID_RANGE on rigid robots)",
    near=True,
)
PLANNERS["rrtconnect-32-near"] = replace(
    PLANNERS["rrtconnect-32"],
    description="rrtconnect-32 with the kc planners' range on arms (ARM_RANGE)",
    near=True,
)
PLANNERS["rrtconnect-pin"] = PlannerSpec(
    og.RRTConnect,
    description="stock RRT-Connect, arms only: a Python isValid calling Pinocchio's "
    "computeCollisions on the same ellipsoid cover (kcplan.planning.pin_checker)",
    backend="pin",
)
for _name, _base, _what in (
    ("kc-rrtconnect-native", "kc-rrtconnect", "RRT-Connect compiled beside the certifier "
     "(sampling, nearest neighbours, extension and shortcuts in C++), every edge certified "
     "as kc-rrtconnect's"),
    ("kc-rrtconnect-lazy-native", "kc-rrtconnect-lazy", "kc-rrtconnect-native screening its "
     "trees' edges and certifying the path it returns, a rejected edge repaired by a "
     "certified sub-plan"),
    ("rrtconnect-32-native", "rrtconnect-32", "the compiled RRT-Connect of "
     "kc-rrtconnect-native checking states every 1/32 rad on the same hulls (its stock "
     "twin; not a proof)"),
    ("rrtconnect-native", "rrtconnect", "the compiled RRT-Connect checking states at OMPL's "
     "default resolution (1 % of the joint box's diagonal) on the same hulls (not a proof)"),
):  # fmt: skip
    PLANNERS[_name] = replace(PLANNERS[_base], description=f"arms only: {_what}", native=True)
PLANNERS["kc-rrtconnect-lazy-native-scan"] = replace(
    PLANNERS["kc-rrtconnect-lazy-native"],
    description="ablation: kc-rrtconnect-lazy-native finding nearest neighbours by a linear "
    "scan, not its k-d tree (the same neighbours)",
    kd_tree=False,
)
PLANNERS = {name: PLANNERS[name] for name in PLANNER_NAMES}
"""Planner names accepted by ``kcplan plan`` and :func:`plan`. Stock planners use OMPL's
default discrete motion validator at the default resolution (1 % of the space extent),
checking states with the kernel's compiled collision query (``*-fcl``: python-fcl).
The ``kc-*``, ``ca-*`` and ``kc-*-paper`` planners differ only in their certificates,
``kc-*-py`` only in their backend."""
if tuple(PLANNERS) != PLANNER_NAMES:  # pragma: no cover - keeps the CLI's list honest
    raise ImportError("kcplan.planning.names.PLANNER_NAMES is out of date")

_SEEDED: list[int] = []
ou.setLogLevel(ou.LOG_WARN)


def seed_ompl(seed: int) -> bool:
    """Seed OMPL's RNG, once per process (OMPL ignores later seeds for determinism).

    Returns True when this call set the seed."""
    if _SEEDED:
        return _SEEDED[0] == seed
    ou.RNG.setSeed(int(seed))
    _SEEDED.append(int(seed))
    return True


@dataclass
class PlanResult:
    """What one planning run produced, as plain Python numbers (no OMPL objects)."""

    scenario: str
    planner: str
    dimension: int
    solved: bool
    time: float  # seconds spent in solve()
    simplify_time: float
    states: list = field(default_factory=list)  # flat poses of the (simplified) path
    length: float = 0.0  # OMPL path length (SE2: translation + 0.5 * |yaw change| ...)
    raw_length: float = 0.0  # the same, of the path solve() returned, before simplification
    seed: int | None = None
    counters: dict = field(default_factory=dict)
    problem: Scenario | None = field(default=None, repr=False, compare=False)
    """The scenario planned on (for :meth:`verify`; not written to JSON)."""
    progress: dict = field(default_factory=dict)
    """Best cost over time, ``{OMPL progress property: values}`` with ``"time REAL"``
    (seconds into ``solve()``) and ``"best cost REAL"`` (inf before the first solution);
    empty unless asked for and the planner reports it (:mod:`kcplan.planning.progress`)."""
    first_solution_time: float | None = None
    """Seconds into ``solve()`` of the first exact solution, when progress was recorded."""
    backend: str = "kernel"
    """Who checked: ``"kernel"`` (compiled, coal) or ``"python"`` (python-fcl)."""
    joints: tuple[str, ...] | None = None
    """An arm's planning group: ``states`` are joint vectors in this order (else None:
    flat poses)."""
    timing: dict = field(default_factory=dict)
    """Where the time went, in seconds: ``read`` and ``filter`` (the scenario's point
    clouds and depth images: reading, cropping, voxel and self filters), ``build`` (the
    collision world, its compiled twin with every cloud's tree, and the validator),
    ``plan`` (:attr:`time`) and ``simplify`` (:attr:`simplify_time`)."""
    trajectory: object = field(default=None, repr=False, compare=False)
    """The timed trajectory along the path when :func:`plan` was asked for it
    (``trajectory=True``): an arm's :class:`kcplan.trajectory.certified.CertifiedTrajectory`,
    a rigid robot's :class:`~kcplan.trajectory.certified.RigidTimedPath`; not written to
    JSON (its own file: their ``document()``)."""

    def verify(self, tolerance: float = 1e-6, padding: float | None = None) -> PathCheck:
        """Check the path without gaps, independently of every certificate
        (:func:`kcplan.planning.verify.verify_path`: FCL clearances and conservative
        advancement). ``tolerance`` is in the scenario's length unit; ``padding`` (default:
        the scenario's) is the clearance the path must keep from the obstacles, and an
        arm's links named in the scenario's ``robot.link_padding`` keep their own.

        Raises
        ------
        ValueError
            When there is no path (not solved) or no scenario to check it against.
        """
        if not self.solved or self.problem is None:
            raise ValueError(f"verify: expected a solved plan, got {self.planner} not solved")
        p = self.problem
        padding = p.padding if padding is None else float(padding)
        if isinstance(p, ArmScenario):
            return verify_arm_path(p.arm, p.obstacles, self.states, tolerance,
                                   allowed=p.allowed, padding=padding,
                                   link_padding=p.link_padding)  # fmt: skip
        return verify_path(CollisionWorld(p), self.states, tolerance, padding=padding)

    def to_json(self) -> dict:
        """The ``PATH.json`` document of ``kcplan plan`` (an arm's has ``joints``)."""
        joints = {} if self.joints is None else {"joints": list(self.joints)}
        return {
            "scenario": self.scenario,
            "planner": self.planner,
            "solved": self.solved,
            "dimension": self.dimension,
            **joints,
            "states": self.states,
            "length": self.length,
            "raw_length": self.raw_length,
            "time": self.time,
            "simplify_time": self.simplify_time,
            "seed": self.seed,
            "counters": self.counters,
            "first_solution_time": self.first_solution_time,
            "progress": self.progress,
            "backend": self.backend,
            "timing": self.timing,
        }


def plan(
    scenario: Scenario | str | os.PathLike,
    planner: str | None = None,
    time_limit: float = 10.0,
    seed: int | None = None,
    simplify: bool = True,
    world: CollisionWorld | None = None,
    first_solution: bool = False,
    progress: float | None = None,
    trajectory: bool = False,
    velocity_limits=None,
    acceleration_limits=None,
    padding: float | None = None,
) -> PlanResult:
    """Plan a path for the scenario's robot from start to goal.

    Parameters
    ----------
    scenario : Scenario or path-like
        A scenario, or the path of a scenario file (:func:`kcplan.scenarios.as_scenario`).
    planner : str, optional
        A key of :data:`PLANNERS`; default
        :func:`~kcplan.planning.names.default_planner` of the robot's kind
        (``kc-rrtconnect``, and ``kc-rrtconnect-lazy-native`` for an arm).
    time_limit : float
        Seconds for ``solve()``; simplification has its own budget of the same length.
    seed : int, optional
        Seeds OMPL's RNG (first call per process only, see :func:`seed_ompl`).
    simplify : bool
        Shortcut and smooth the path with OMPL's simplifier; every new edge it makes is
        checked by the same motion validator, so kc planners keep their guarantee. A
        simplified path that fails the validator's final check (OMPL then only warns) is
        dropped for the path ``solve()`` returned.
    world : CollisionWorld, optional
        Reuse a collision world (its counters are reset).
    first_solution : bool
        Stop at the first exact solution: the optimization objective's cost threshold is
        set to infinity and the planner stops once the problem has an exact solution, so
        asymptotically optimal planners (RRT*, BIT*, AORRTC, ...) report their time to a
        first solution instead of running to the time limit. PRM* still runs to the limit:
        it hands its path to the problem only when it stops.
    progress : float, optional
        Record the best cost every ``progress`` seconds while solving (planners for which
        :func:`kcplan.planning.progress.reports_progress` holds: RRT*, Informed RRT*,
        SORRT*, AORRTC, BIT*; ignored for the others).
    trajectory : bool
        With a ``kc-*`` or ``ca-*`` planner (whose edges are certified), as
        ``PlanResult.trajectory``: an arm's path smoothed with certified blends and timed
        within the joint limits (:func:`kcplan.trajectory.certified.certified_trajectory`);
        a rigid robot's timed edge by edge within translational and angular limits,
        stopping at every corner (:func:`kcplan.trajectory.certified.timed_rigid_path`).
    velocity_limits, acceleration_limits : optional
        The trajectory's limits (:func:`kcplan.trajectory.certified.joint_limits`, or
        :func:`~kcplan.trajectory.certified.rigid_limits`).
    padding : float, optional
        The clearance every certified edge keeps from every obstacle and point, in the
        scenario's unit (default: the scenario's ``robot.padding``, else 0): the compiled
        kernel's queries count a body nearer than it as a collision and take it off
        every clearance (MoveIt's link padding; an arm's self pairs are not padded). An
        arm's links named in ``robot.link_padding`` keep their own padding instead.

    Returns
    -------
    PlanResult
        ``counters`` holds FCL ``collision_queries`` and ``distance_queries`` (state
        checks and guards together), ``checker_calls``, and for kc planners the
        validator's counters, among them ``kc_simplify_edges``: the edges OMPL's
        simplifier asked the certifier (every shortcut and smoothing step is certified
        like the planner's edges).
    """
    try:
        if planner is not None:
            check_planner_name(planner)
    except ValueError as err:
        raise ValueError(f"planner: {err}") from None
    scenario = as_scenario(scenario)
    if padding is not None:
        if not (padding >= 0 and math.isfinite(padding)):
            raise ValueError(f"padding: expected a finite number >= 0, got {padding!r}")
        scenario = replace(scenario, padding=float(padding))
    arm = isinstance(scenario, ArmScenario)
    planner = planner or default_planner(arm)
    try:  # the arm-only planners refuse a rigid robot, the paper's any robot but E_a
        check_planner_for(planner, scenario)
    except ValueError as err:
        raise ValueError(f"planner: {err}") from None
    spec = PLANNERS[planner]
    if trajectory and not spec.kc:
        raise ValueError(f"trajectory: expected a kc-* or ca-* planner, whose edges are "
                         f"certified; {planner} checks them at samples")  # fmt: skip
    if seed is not None:
        seed_ompl(seed)
    checker_calls = [0]
    built = time.perf_counter()
    setup = setup_for(scenario, spec, world)
    built = time.perf_counter() - built
    space, ss, si, validator = setup.space, setup.ss, setup.si, setup.validator

    def is_valid(state) -> bool:
        checker_calls[0] += 1
        return setup.state_valid(state)

    si.setStateValidityChecker(is_valid)
    if spec.resolution is not None:
        si.setStateValidityCheckingResolution(spec.resolution)
    start, goal = si.allocState(), si.allocState()
    setup.write(start, scenario.start)
    setup.write(goal, scenario.goal)
    ss.setStartAndGoalStates(start, goal)
    planner_object = spec.make(si)
    ss.setPlanner(planner_object)
    ss.setup()
    range_factor = spec.range_factor
    if range_factor is None and (spec.kc or spec.near):  # certified edges: shorter pays
        range_factor = setup.kc_range
    if range_factor is not None and hasattr(planner_object, "setRange"):
        planner_object.setRange(range_factor * space.getMaximumExtent())
    if spec.neighbors is not None:
        planner_object.setMaxNearestNeighbors(spec.neighbors)
    objective = ss.getProblemDefinition().getOptimizationObjective()
    if first_solution and objective is not None:
        objective.setCostThreshold(ob.Cost(math.inf))

    recorder = None
    if progress is not None and reports_progress(planner_object) and not spec.lazy:
        recorder = ProgressRecorder(planner_object, progress)
        stop = recorder.termination_condition(float(time_limit))
    else:
        stop = ob.timedPlannerTerminationCondition(float(time_limit))
    if first_solution:  # AORRTC does not stop at a met cost threshold
        stop = ob.plannerOrTerminationCondition(
            stop, ob.exactSolnPlannerTerminationCondition(ss.getProblemDefinition())
        )
    try:
        if spec.native:
            solved_ = _solve_natively(setup, spec, scenario, time_limit, seed, simplify)
        else:
            solved_ = _solve_in_ompl(setup, spec, stop, recorder, time_limit, simplify)
        solved, solve_time, simplify_time = solved_.solved, solved_.time, solved_.simplify_time
        states, length, raw_length = solved_.states, solved_.length, solved_.raw_length
        queries = setup.world.counters
        counters = {
            **queries,
            "fcl_queries": sum(queries.get(k, 0) for k in _QUERY_KINDS),
            "checker_calls": checker_calls[0],
        }
        if validator is not None:
            counters |= {f"kc_{k}": v for k, v in validator.counters.items()}
            counters["kc_simplify_edges"] = solved_.simplify_edges
        counters |= solved_.counters
        timed = None  # after the counters: they are the planner's
        if solved and trajectory:
            timed = setup.timed(states, velocity_limits, acceleration_limits)
    finally:
        if validator is not None:
            validator.close()
    return PlanResult(
        scenario.name,
        planner,
        scenario.dimension,
        solved,
        solve_time,
        simplify_time,
        states,
        length,
        raw_length,
        seed,
        counters,
        scenario,
        recorder.to_json() if recorder is not None else {},
        recorder.first_solution_time if recorder is not None else None,
        setup.backend,
        setup.joints,
        trajectory=timed,
        timing={
            **sensed_times(scenario.obstacles),
            "build": built,
            "plan": solve_time,
            "simplify": simplify_time,
        },
    )


@dataclass(frozen=True)
class _Solved:
    """What a solve and its simplification gave :func:`plan` (times in seconds)."""

    solved: bool
    time: float
    simplify_time: float = 0.0
    states: list = field(default_factory=list)
    length: float = 0.0
    raw_length: float = 0.0
    simplify_edges: int = 0
    counters: dict = field(default_factory=dict)


def _solve_in_ompl(setup, spec: PlannerSpec, stop, recorder, time_limit: float,
                   simplify: bool) -> _Solved:  # fmt: skip
    """Solve ``setup.ss`` with its OMPL planner (lazily when ``spec.lazy``) and simplify
    the path with OMPL's simplifier, every new edge asked of the same validator."""
    ss, validator = setup.ss, setup.validator
    counters = {}
    if spec.lazy:  # the path certified after solve(); its time counts as the solve's
        lazy = solve_lazily(
            ss, validator, setup.read, float(time_limit), setup.screen_step, spec.lazy_repair
        )
        solve_time, solved = lazy.time, lazy.solved
        counters = {"kc_lazy_attempts": lazy.attempts,
                    "kc_lazy_rejected_paths": lazy.rejected_paths,
                    "kc_lazy_repaired_edges": lazy.repaired_edges}  # fmt: skip
    else:
        try:
            ss.solve(stop)
        finally:
            if recorder is not None:
                recorder.finish()
        if validator is not None:
            validator.raise_error()
        solve_time = float(ss.getLastPlanComputationTime())
        solved = bool(ss.haveExactSolutionPath())
    if not solved:
        return _Solved(False, solve_time, counters=counters)
    path = ss.getSolutionPath()
    raw_length = length = float(path.length())
    states = [setup.read(s).tolist() for s in path.getStates()]
    del path
    simplify_time, simplify_edges = 0.0, 0
    if simplify:
        t0 = time.perf_counter()
        before = validator.counters["edges"] if validator is not None else 0
        ss.simplifySolution(float(time_limit))
        if validator is not None:  # every edge the simplifier made was certified
            validator.raise_error()
            simplify_edges = validator.counters["edges"] - before
        path = ss.getSolutionPath()
        # OMPL's simplifier returns a path whose last check and repair failed with only a
        # warning ("may slightly touch on an invalid region"): keep the simplified path
        # only when every state and edge of it passes the checker
        if path.check():
            states = [setup.read(s).tolist() for s in path.getStates()]
            length = float(path.length())
        del path
        simplify_time = time.perf_counter() - t0
    return _Solved(True, solve_time, simplify_time, states, length, raw_length, simplify_edges,
                   counters)  # fmt: skip


def _solve_natively(setup, spec: PlannerSpec, scenario, time_limit: float, seed,
                    simplify: bool) -> _Solved:  # fmt: skip
    """Solve with the compiled RRT-Connect (:mod:`kcplan.planning.native`). Its edges never
    pass through the validator's ``checkMotion``, so a kernel error reaches the caller as
    the Python exception nanobind raises, with nothing stored to re-raise."""
    native = solve_natively(setup, spec, scenario.start, scenario.goal, time_limit, seed, simplify,
                            spec.kd_tree)  # fmt: skip
    return _Solved(
        native.solved, native.time, native.simplify_time, native.states,
        _joint_length(native.states), _joint_length(native.raw_states),
        native.counters["native_shortcut_edges"], native.counters,
    )  # fmt: skip


def _joint_length(states: list) -> float:
    """A path's length as OMPL measures a joint-space path: the L2 norms of its steps."""
    q = np.asarray(states, dtype=float)
    return float(np.linalg.norm(np.diff(q, axis=0), axis=1).sum()) if len(q) > 1 else 0.0


def sensed_times(obstacles) -> dict[str, float]:
    """Seconds spent reading and filtering the point clouds and depth images among
    ``obstacles`` (:class:`kcplan.world.pointcloud.CloudInfo`; empty without any)."""
    infos = [ob.cloud for ob in obstacles if getattr(ob, "cloud", None) is not None]
    if not infos:
        return {}
    return {
        "read": sum(info.read_seconds for info in infos),
        "filter": sum(info.filter_seconds for info in infos),
    }


_QUERY_KINDS = ("collision_queries", "distance_queries", "region_queries")
