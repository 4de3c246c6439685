"""Soundness of the arm certifier on random joint-space edges, checked on the meshes (issue 25).

Random edges of every length in MotionBenchMaker scenes (:mod:`kcplan.arm.mbm`, VAMP's
``problems.tar.bz2``; the first ``--per-class`` problems of each of the 7 classes, taken
in turn, each with its allowed collision matrix; self-collision included): ``q1`` uniform
in the joint limits and valid for the cover (OMPL's contract: an edge starts at a valid
state), ``q'`` uniform in the limits and ``q2 = q1 + t (q' - q1)`` with ``t`` log-uniform
in ``[0.01, 1]``. The joints outside the group (fingers) are fixed at the first problem's
start values. Each edge is decided by the compiled certifier
(:class:`kcplan.certification.kernel.KernelArmCertifier`) and, for the first ``--twin`` edges,
also by its Python twin (:class:`kcplan.certification.arm_certifier.ArmEdgeCertifier`), both
with the certificates of the ``kc-*`` planners (the clearance balls and the KC guards of
inflation ``--kc-inflation``; 0: the balls alone, as ``ca-*``).

Every **accepted** edge (of either backend) is re-checked by the gap-free mesh verifier
(:class:`kcplan.arm.verify.ArmMeshChecker`: the links' own collision meshes, python-fcl,
independent of the covers and the certifiers); a *violation* is an accepted edge it finds
in collision, and must be 0. A rejected edge is counted under the step that rejected it
(the certifier's counters: an end state invalid or outside the limits, a colliding probe,
a guard in contact, not proven within ``max_guards``); a random ``--free-check`` fraction
of the rejected edges is verified on the meshes too, which estimates how many *free*
edges each step rejects (the price of proving, partly the cover's).

Few random edges pass near an obstacle; ``--graze F`` makes a fraction ``F`` of them end
near one: from the same start, edges are drawn (up to :data:`GRAZE_TRIES`) until one
meets a state at which the certifier's bodies touch an obstacle (self-collision aside;
:data:`GRAZE_STEPS` states along it, then bisection to the first such state), and it
stops short of that state by a log-uniform fraction in :data:`GRAZE_BACK` of the stretch
before it. ``--scenarios FILE ...`` takes the scenes of arm scenarios instead (one robot
and planning group in all, e.g. a base that drives: issue 57's problems of
``make_whole_body_problems.py``); a wrapping angle's edge turns the shorter way for the
certifier and the re-check alike. Progress lines on stderr; a Markdown table on stdout::

    python scripts/arm_soundness.py [--robot panda] [--edges 100000] [--seed 1]
        [--per-class 100] [--representation R] [--bodies 2] [--max-offset D] [--twin 0]
        [--free-check 0.05] [--graze 0]
        [--kc-inflation 0.2] [--no-planes]

The arm's links are each their own convex hull with ``--representation hulls`` (kcplan's
default), else covered by ``--bodies`` ellipsoids each (2 by default: fast to fit
and to check), or with ``--max-offset D`` as :func:`kcplan.arm.load_arm` covers them by
default (``D = 0.01``: hundreds of bodies, a cold fit of about 20 minutes).

**Against point clouds** (issue 55), ``--cloud N``: each problem's obstacles are replaced
by ``N`` surface points of each (``scripts/make_cloud_scenarios.py``'s ``surface_cloud``:
:func:`kcplan.world.pointcloud.sample_surface_points` on
:func:`kcplan.views.arm.obstacle_mesh`, seeded by ``--seed`` and the problem's place in
turn), every point a ball of ``--point-radius`` (VAMP's 2.5 mm). The certifier sees one
``pointcloud`` obstacle: the points themselves, or with ``--spacing S`` what
:func:`kcplan.world.pointcloud.voxel_filter` keeps of them (every point within ``S`` of a
kept one) with radius ``point_radius + S``, as the scenario loader plans a filtered cloud.
Every accepted edge is re-checked on the links' meshes against the **original** points at
``point_radius`` (one :class:`ArmMeshChecker` per scene: python-fcl's BVH of the points,
each a triangle of legs 1e-9 m, less the radius, :func:`kcplan.arm.verify.point_triangles`;
with ``--balls`` every point its own ``fcl.Sphere`` in python-fcl's broad phase instead,
about 20 times slower), so the filter's guarantee is tested with it: no point it dropped
comes within ``point_radius`` of an accepted edge. A second table gives, per robot, the
points, what the filter kept, the edges accepted and re-checked, the violations, the
smallest link-to-cloud distance the re-check measured on an accepted edge (the least of
the distances at its samples: > 0 when sound) and how many accepted edges came within
:data:`NEAR` of the cloud::

    python scripts/arm_soundness.py --robot ur5 --representation hulls --cloud 10000 \\
        [--spacing 0.01] [--point-radius 0.0025] --graze 0.5 --per-class 2 --edges 252

The re-check dominates the time, less so with the cloud's BVH: against 10^5 points
(half of the edges grazing) about 0.07 s per accepted edge for the Panda and 0.3 s for the
UR5, and with ``--balls`` 1.5 s and 2.3 s (python-fcl's broad phase measures every ball
whose box is nearer than the best distance so far, often hundreds per query, through a
Python callback), against 2-6 ms for the certifier (``benchmarks/cloud-soundness/``).
"""

from __future__ import annotations

import argparse
import functools
import math
import os
import sys
import time
from pathlib import Path
from typing import NamedTuple

import numpy as np

from kcplan.arm import ArmWorld, load_arm
from kcplan.arm.attach import Attached, attach
from kcplan.arm.mbm import MBM_CLASSES, load_mbm_archive
from kcplan.arm.verify import ArmMeshChecker
from kcplan.certification.arm_certifier import DEFAULT_KC_INFLATION, ArmEdgeCertifier
from kcplan.certification.kernel import KernelArmCertifier
from kcplan.scenarios import load_scenario
from kcplan.world.obstacles import Obstacle
from kcplan.world.pointcloud import sample_surface_points, voxel_filter

ROOT = Path(__file__).resolve().parents[1]
MBM = ROOT.parent / "shared" / "data" / "external" / "mbm"
POINT_RADIUS = 0.0025  # metres: VAMP's point radius (make_cloud_scenarios.py's)
GRAZE_STEPS = 64
"""States along a grazing edge tested for the first invalid one (:func:`_graze`)."""
GRAZE_TRIES = 50
"""Edges drawn from one start for one that meets an invalid state, to graze (:func:`_edge`)."""
GRAZE_BACK = (1e-4, 1e-1)
"""A grazing edge stops short of the first invalid state by a log-uniform fraction in this
range of the stretch before it (:func:`_graze`)."""
NEAR = (0.01, 0.001)
"""Metres: accepted edges that came within these of the obstacles on the meshes are counted
(how many edges test the certifier where it matters)."""
STEPS = ("rejected_end_state", "rejected_probe", "rejected_guard", "not_proven")
"""The certifier's rejection counters, in the order its steps run."""
STEP_NAMES = {
    "rejected_end_state": "end state",
    "rejected_probe": "probe",
    "rejected_guard": "guard in contact",
    "not_proven": "not proven",
}


def _step(before: dict, after: dict) -> str:
    """The rejection counter that one ``check`` raised."""
    for name in STEPS:
        if after[name] > before[name]:
            return name
    raise RuntimeError("a rejected edge raised no rejection counter")


def _edge(
    rng: np.random.Generator, arm, decide, graze: float = 0.0, touch=None
) -> tuple[np.ndarray, np.ndarray, bool]:
    """A random edge from a valid state (see the module docstring), and whether it was
    cut short to graze (a ``graze`` fraction of them, :func:`_graze`, near what makes
    ``touch``'s states invalid)."""
    for _ in range(10_000):
        q1 = rng.uniform(arm.lower, arm.upper)
        if decide.state_valid(q1):
            break
    else:
        raise RuntimeError("no valid state in 10,000 samples")
    t = math.exp(rng.uniform(math.log(0.01), 0.0))
    q2 = q1 + t * (rng.uniform(arm.lower, arm.upper) - q1)
    if graze > 0.0 and rng.random() < graze:
        for _ in range(GRAZE_TRIES):
            q1, end, grazing = _graze(rng, touch, q1, q2)
            if grazing:
                return q1, end, True
            t = math.exp(rng.uniform(math.log(0.01), 0.0))
            q2 = q1 + t * (rng.uniform(arm.lower, arm.upper) - q1)
    return q1, q2, False


def _graze(rng: np.random.Generator, decide, q1: np.ndarray, q2: np.ndarray):
    """The edge ``q1 -> q2`` cut short of the first state along it that ``decide`` finds
    invalid (:data:`GRAZE_STEPS` states, then bisection), by a log-uniform fraction in
    :data:`GRAZE_BACK` of the valid stretch: it ends near the obstacles as ``decide``
    sees them (:func:`study`: the certifier's, self-collision aside). ``q1 -> q2`` as it
    is (not grazing) when none of those states is invalid. A wrapping angle turns the
    shorter way, as the certifier's edge does."""
    dq = decide.world.arm.edge_end(q1, q2) - q1
    steps = np.linspace(0.0, 1.0, GRAZE_STEPS + 1)
    for i in range(1, len(steps)):
        if not decide.state_valid(q1 + steps[i] * dq):
            break
    else:
        return q1, q2, False
    lo, hi = steps[i - 1], steps[i]
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        if decide.state_valid(q1 + mid * dq):
            lo = mid
        else:
            hi = mid
    back = math.exp(rng.uniform(*np.log(GRAZE_BACK)))
    return q1, q1 + lo * (1.0 - back) * dq, True


class ScenarioScene(NamedTuple):
    """A scenario's scene as a problem of the study (``--scenarios``): its obstacles, its
    allowed pairs and its goal (for messages). A named tuple: the tests load this script
    by its path, where a dataclass cannot find its module."""

    obstacles: tuple
    allowed: frozenset
    goal: np.ndarray


def _problems(args: argparse.Namespace) -> tuple[list, object]:
    """The scenes in turn and the arm: the MBM problems of ``--robot``, or the scenes of
    ``--scenarios`` (one robot, the first scenario's)."""
    if args.scenarios:
        scenarios = [load_scenario(path) for path in args.scenarios]
        arm = scenarios[0].arm
        if any(s.arm.urdf != arm.urdf or s.arm.joints != arm.joints for s in scenarios):
            raise SystemExit("--scenarios: expected one robot and planning group in all")
        return [ScenarioScene(s.obstacles, s.allowed, s.goal) for s in scenarios], arm
    folder = Path(args.mbm) / args.robot
    keys = [(c, i) for c in MBM_CLASSES for i in range(1, args.per_class + 1)]
    problems = load_mbm_archive(folder / "problems.tar.bz2", keys)
    chosen = [
        problems[c, i]
        for i in range(1, args.per_class + 1)
        for c in MBM_CLASSES
        if (c, i) in problems
    ]
    joints = chosen[0].joints
    fixed = {k: v for k, v in chosen[0].start_state.items() if k not in joints}
    arm = load_arm(folder / f"{args.robot}.urdf", joints, srdf=folder / f"{args.robot}.srdf",
                   fixed=_known(folder / f"{args.robot}.urdf", fixed),
                   bodies_per_link=args.bodies, max_offset=args.max_offset,
                   representation=args.representation)  # fmt: skip
    return chosen, arm


def _source(args: argparse.Namespace) -> str:
    """Where the problems came from, for the report."""
    if args.scenarios:
        return "scenarios " + ", ".join(path.name for path in args.scenarios[:3]) + (
            ", ..." if len(args.scenarios) > 3 else "")
    return f"{args.per_class} per class"


def study(args: argparse.Namespace, out=sys.stderr) -> dict:
    """Decide and verify ``args.edges`` random edges; the counts (module docstring)."""
    rng = np.random.default_rng(args.seed)
    t0 = time.perf_counter()
    chosen, arm = _problems(args)
    if args.attach:
        arm = attach(arm, [held_part(args.robot, args.attach)])
    print(f"{len(chosen)} problems, {arm.describe()}, {len(arm.self_pairs)} self pairs, "
          f"ready in {time.perf_counter() - t0:.1f} s", file=out, flush=True)  # fmt: skip
    c = {"edges": 0, "accepted": 0, "violations": 0, "verified": 0, "twin": 0,
         "twin_accepted": 0, "twin_violations": 0, "twin_disagree": 0,
         "decide_s": 0.0, "verify_s": 0.0, "twin_s": 0.0, "grown_queries": 0,
         "kc_reaches": 0, "plane_reaches": 0, "rechecked": 0, "scene_s": 0.0,
         "scenes": 0, "points": [], "kept": [], "near": [0] * len(NEAR),
         "grazing": 0, "grazing_accepted": 0}  # fmt: skip
    lowest = {"scene": math.inf, "any": math.inf, "edge": None}  # on the accepted edges
    steps = {name: {"rejected": 0, "checked": 0, "free": 0} for name in STEPS}
    per_problem = math.ceil(args.edges / len(chosen))
    start = time.perf_counter()
    for k in range(args.edges):
        if k % per_problem == 0:
            j = (k // per_problem) % len(chosen)
            problem = chosen[j]
            t = time.perf_counter()
            planned, checked, counts = scene_obstacles(problem, j, args)
            world = ArmWorld(arm, planned, allowed=problem.allowed)
            if args.cloud_tolerance is not None:
                world.kernel.scene.cloud_tolerance = args.cloud_tolerance
            c["cloud_tolerance"] = world.kernel.scene.cloud_tolerance
            kernel = KernelArmCertifier(world, kc_inflation=args.kc_inflation, planes=args.planes,
                                        probes=args.probes)  # fmt: skip
            meshes = _Meshes(arm, checked, problem.allowed)
            touch = None
            if args.graze:  # the same obstacles, no self pair: graze the obstacles
                every = {frozenset((arm.bodies[a].link, arm.bodies[b].link))
                         for a, b in arm.self_pairs}  # fmt: skip
                touch = KernelArmCertifier(ArmWorld(arm, planned, allowed=every,
                                                    prove_pairs=False))  # fmt: skip
            c["scene_s"] += time.perf_counter() - t
            c["scenes"] += 1
            if args.cloud:
                c["points"].append(counts[0])
                c["kept"].append(counts[1])
            twin = None
            if k < args.twin:
                twin = ArmEdgeCertifier(world, kc_inflation=args.kc_inflation, planes=args.planes)
        q1, q2, grazing = _edge(rng, arm, kernel, args.graze, touch)
        c["grazing"] += grazing
        before = dict(kernel.counters)
        t = time.perf_counter()
        ok = kernel.check(q1, q2)
        c["decide_s"] += time.perf_counter() - t
        c["edges"] += 1
        for name in ("grown_queries", "kc_reaches", "plane_reaches"):  # what they did
            c[name] += kernel.counters[name] - before[name]
        verdict = None
        verified = functools.partial(_collides, meshes, q1, q2, c)
        if ok:
            c["accepted"] += 1
            c["grazing_accepted"] += grazing
            verdict = verified()
            c["rechecked"] += 1
            c["violations"] += verdict
            hit = meshes.last
            if verdict:
                print(f"VIOLATION: {problem_name(problem)}, edge {k}"
                      f"{' (grazing)' if grazing else ''}: {hit.what} within "
                      f"{meshes.tolerance:g} m at segment parameter {hit.where[1]:.6g} (the "
                      f"re-check's first such sample: distance {hit.min_clearance:.3g} m): "
                      f"{q1.tolist()} -> {q2.tolist()}", file=out, flush=True)  # fmt: skip
            lowest["any"] = min(lowest["any"], hit.min_clearance)
            for i, near in enumerate(NEAR):
                c["near"][i] += meshes.scene_lowest < near
            if meshes.scene_lowest < lowest["scene"]:
                lowest["scene"] = meshes.scene_lowest
                lowest["edge"] = (problem_name(problem), k, q1.tolist(), q2.tolist())
        else:
            s = steps[_step(before, kernel.counters)]
            s["rejected"] += 1
            if rng.random() < args.free_check:
                verdict = verified()
                s["checked"] += 1
                s["free"] += not verdict
        if twin is not None and k < args.twin:
            t = time.perf_counter()
            twin_ok = twin.check(q1, q2)
            c["twin_s"] += time.perf_counter() - t
            c["twin"] += 1
            c["twin_accepted"] += twin_ok
            c["twin_disagree"] += twin_ok != ok
            if twin_ok:
                if verdict is None:
                    verdict = verified()
                c["twin_violations"] += verdict
        if (k + 1) % max(1, args.edges // 20) == 0 or k + 1 == args.edges:
            print(f"{k + 1} edges, {c['accepted']} accepted, {c['violations']} violations, "
                  f"{time.perf_counter() - start:.0f} s", file=out, flush=True)  # fmt: skip
    c["wall_s"] = time.perf_counter() - start
    return {"counts": c, "steps": steps, "arm": arm, "problems": len(chosen), "lowest": lowest}


class _Meshes(ArmMeshChecker):
    """:class:`ArmMeshChecker` that keeps its last check (``last``) and the smallest
    distance that check measured between a link and the obstacles (``scene_lowest``; the
    self pairs apart), through its per-item distances (a link against the scene is item
    ``< len(self._links)``)."""

    def check_pieces(self, pieces, max_queries: int = 1_000_000):
        self.scene_lowest = math.inf
        self.last = super().check_pieces(pieces, max_queries)
        return self.last

    def _distance(self, item: int) -> float:
        d = super()._distance(item)
        if item < len(self._links):
            self.scene_lowest = min(self.scene_lowest, d)
        return d


def surface_cloud(obstacles, per_object: int, seed: int) -> np.ndarray:
    """``per_object`` surface samples of each obstacle, shape (k * per_object, 3)
    (``scripts/make_cloud_scenarios.py``'s ``surface_cloud``)."""
    from kcplan.views.arm import obstacle_mesh

    return np.concatenate([
        sample_surface_points(*obstacle_mesh(ob), per_object, seed=seed + i)
        for i, ob in enumerate(obstacles)
    ])  # fmt: skip


def cloud_obstacle(points: np.ndarray, radius: float) -> Obstacle:
    """An in-memory ``pointcloud`` obstacle: every point a ball of ``radius``."""
    return Obstacle(kind="pointcloud", index=0, spec={}, center=np.zeros(3),
                    rotation=np.eye(3), extents=np.full(3, float(radius)), pieces=(),
                    vertices=np.ascontiguousarray(points, dtype=np.float64),
                    triangles=None)  # fmt: skip


def ball_obstacles(points: np.ndarray, radius: float) -> list[Obstacle]:
    """Every point its own ``sphere`` obstacle of ``radius`` (``--balls``: an FCL ball per
    point in the mesh re-check)."""
    return [Obstacle(kind="sphere", index=i, spec={}, center=p, rotation=np.eye(3),
                     extents=np.full(3, float(radius)))
            for i, p in enumerate(np.asarray(points, dtype=np.float64))]  # fmt: skip


def scene_obstacles(problem, j: int, args: argparse.Namespace) -> tuple[list, list, tuple]:
    """The obstacles the certifier sees, those the meshes are re-checked against, and the
    points of the cloud and those kept for the certifier (0, 0 without one): the problem's
    own twice, or with ``--cloud`` (module docstring) the cloud as planned (the voxel
    filter's points at ``point_radius + spacing``, or all of them at ``point_radius``) and
    the original cloud at ``point_radius`` (with ``--balls`` as one ball each); ``j`` is
    the problem's place in turn (its cloud's seed)."""
    if not args.cloud:
        return list(problem.obstacles), list(problem.obstacles), (0, 0)
    points = surface_cloud(problem.obstacles, args.cloud, args.seed + 1000 * j)
    kept = voxel_filter(points, args.spacing) if args.spacing > 0 else points
    planned = cloud_obstacle(kept, args.point_radius + args.spacing)
    checked = (ball_obstacles(points, args.point_radius) if args.balls
               else [cloud_obstacle(points, args.point_radius)])  # fmt: skip
    return [planned], checked, (len(points), len(kept))


def _collides(meshes: _Meshes, q1: np.ndarray, q2: np.ndarray, c: dict) -> bool:
    """Whether the mesh verifier finds the edge ``q1 -> q2`` in collision (timed in ``c``)."""
    t = time.perf_counter()
    hit = meshes.check([q1, q2])
    c["verify_s"] += time.perf_counter() - t
    c["verified"] += 1
    return hit.collides


def problem_name(problem) -> str:
    """A short label of a problem for messages (its goal)."""
    return f"problem with goal {np.round(problem.goal, 3).tolist()}"


def _known(urdf: Path, fixed: dict) -> dict:
    """The ``fixed`` joints that the URDF has (a request also names virtual joints)."""
    import pinocchio as pin

    model = pin.buildModelFromUrdf(os.fspath(urdf))
    return {k: v for k, v in fixed.items() if model.existJointName(k)}


PARTS = {  # a part held between the fingers, in the hand's frame (the gripper's axis z)
    "box": {"center": [0.0, 0.0, 0.12], "size": [0.04, 0.04, 0.16],
            "quaternion": [0.0, 0.0, 0.38268343, 0.92387953]},
    "cylinder": {"center": [0.0, 0.0, 0.12], "radius": 0.03, "height": 0.15},
    "mesh": {"file": "meshes/collision/finger.obj", "scale": 2.0,
             "position": [0.0, 0.0, 0.1]},
}  # fmt: skip
HANDS = {  # the link that holds it and the links that may touch it
    "panda": ("panda_hand", ("panda_leftfinger", "panda_rightfinger")),
    "ur5": ("robotiq_85_base_link", tuple(f"robotiq_85_{side}_{part}_link"
                                          for side in ("left", "right")
                                          for part in ("knuckle", "finger", "inner_knuckle",
                                                       "finger_tip"))),
}  # fmt: skip


def held_part(robot: str, shape: str) -> Attached:
    """The part of ``--attach``: :data:`PARTS` held by the robot's hand (:data:`HANDS`); a
    mesh part is the bundled Panda's finger, twice its size."""
    from kcplan.scenarios import parse_scenario

    data = {"name": "part", "dimension": 3,
            "bounds": {"low": [-1.0, -1.0, -1.0], "high": [1.0, 1.0, 1.0]},
            "robot": {"semi_axes": [0.1, 0.1, 0.1]},
            "start": {"position": [0.0, 0.0, 0.0]}, "goal": {"position": [0.0, 0.0, 0.0]},
            "obstacles": [{shape: PARTS[shape]}]}  # fmt: skip
    if shape == "cylinder":  # the arm scenario's kind: read there
        from kcplan.arm.scenario import _cylinder
        from kcplan.world.fields import FieldReader

        part = _cylinder(FieldReader("part"), PARTS[shape], 0)
    else:
        folder = ROOT / "scenarios" / "arm" / "panda"
        part = parse_scenario(data, "part", folder, check=False).obstacles[0]
    link, touch = HANDS[robot]
    return Attached("part", link, part, touch)


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    """The command line's arguments, checked (``study``'s ``args``)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="panda",
                        help="panda or ur5 (MBM robots); with --scenarios, the table label")
    parser.add_argument("--edges", type=int, default=100_000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--per-class", type=int, default=100, help="problems per class")
    parser.add_argument(
        "--bodies", type=int, default=None,
        help="ellipsoids per link (default 2; with --max-offset: the most)",
    )  # fmt: skip
    parser.add_argument(
        "--max-offset", type=float, default=None,
        help="metres a link's cover may stick out of its mesh (as load_arm)",
    )  # fmt: skip
    parser.add_argument("--representation", choices=("hulls", "ellipsoids"), default=None,
                        help="the links' bodies (default: ellipsoids; hulls: kcplan's "
                        "default, each link its own convex hull)")  # fmt: skip
    parser.add_argument("--attach", choices=sorted(PARTS), default=None,
                        help="the arm holds a part of this shape between its fingers "
                        "(hulls only): every check includes it")  # fmt: skip
    parser.add_argument("--twin", type=int, default=0, help="edges also decided in Python")
    parser.add_argument("--free-check", type=float, default=0.05,
                        help="fraction of rejected edges verified on the meshes")  # fmt: skip
    parser.add_argument("--kc-inflation", type=float, default=DEFAULT_KC_INFLATION,
                        help="the KC guards' inflation (0: the clearance balls alone)")  # fmt: skip
    parser.add_argument("--no-planes", dest="planes", action="store_false",
                        help="certify without the free-region planes (the ablation)")  # fmt: skip
    parser.add_argument("--no-probes", dest="probes", action="store_false",
                        help="certify without the probes, which only reject early: the "
                        "lazy compiled planner's check of its path's edges")  # fmt: skip
    parser.add_argument("--cloud-tolerance", type=float, default=None, metavar="T",
                        help="with --cloud: the kernel's relative tolerance of a cloud's "
                        "distances (World.cloud_tolerance; default the kernel's)")  # fmt: skip
    parser.add_argument("--cloud", type=int, default=0, metavar="N",
                        help="replace each problem's obstacles by N surface points of each "
                        "(0: the primitives)")  # fmt: skip
    parser.add_argument("--spacing", type=float, default=0.0, metavar="S",
                        help="with --cloud: the certifier sees the cloud through a voxel "
                        "filter of this spacing, at radius point_radius + S (0: none)")  # fmt: skip
    parser.add_argument("--point-radius", type=float, default=POINT_RADIUS,
                        help="with --cloud: metres, the radius of one point")  # fmt: skip
    parser.add_argument("--balls", action="store_true",
                        help="with --cloud: re-check every point as its own FCL ball (the "
                        "verifier's cloud surface otherwise)")  # fmt: skip
    parser.add_argument("--graze", type=float, default=0.0, metavar="F",
                        help="fraction of the edges made to end near an obstacle, just "
                        "short of the certifier's first state touching it (0: none)")  # fmt: skip
    parser.add_argument("--mbm", default=os.fspath(MBM), help="folder of the MBM robots")
    parser.add_argument("--scenarios", nargs="+", type=Path, metavar="SCENARIO",
                        help="the scenes of these arm scenarios instead of MBM's (one robot: "
                        "a moving base, two arms)")  # fmt: skip
    args = parser.parse_args(argv)
    if not args.scenarios and args.robot not in ("panda", "ur5"):
        parser.error(f"--robot: expected panda or ur5 (or --scenarios), got {args.robot!r}")
    if not 0.0 <= args.graze <= 1.0:
        parser.error("expected 0 <= --graze <= 1")
    if args.cloud < 0 or not (math.isfinite(args.spacing) and args.spacing >= 0.0):
        parser.error("expected --cloud >= 0 and --spacing >= 0")
    if not (math.isfinite(args.point_radius) and args.point_radius > 0.0):
        parser.error("expected --point-radius > 0")
    if args.cloud_tolerance is not None and not (
        math.isfinite(args.cloud_tolerance) and args.cloud_tolerance >= 0.0
    ):
        parser.error("expected --cloud-tolerance >= 0")
    if (args.spacing > 0 or args.balls or args.cloud_tolerance is not None) and not args.cloud:
        parser.error("--spacing, --balls and --cloud-tolerance are about a cloud: give "
                     "--cloud N too")  # fmt: skip
    if args.bodies is None and args.max_offset is None and args.representation != "hulls":
        args.bodies = 2
    if args.edges < 1 or args.per_class < 1 or not 0.0 <= args.free_check <= 1.0:
        parser.error("expected --edges >= 1, --per-class >= 1, 0 <= --free-check <= 1")
    if not (math.isfinite(args.kc_inflation) and args.kc_inflation >= 0.0):
        parser.error("expected --kc-inflation >= 0")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    r = study(args)
    c, steps = r["counts"], r["steps"]
    verify_per = 1e3 * c["verify_s"] / max(c["verified"], 1)
    print(
        "| robot | backend | edges | accepted | violations | rejected: end state / probe / "
        "guard in contact / not proven | free among rejected, verified (est. free) |"
    )
    print("|---|---|---|---|---|---|---|")
    rejected = " / ".join(str(steps[s]["rejected"]) for s in STEPS)
    free = " / ".join(
        f"{steps[s]['free']} of {steps[s]['checked']} "
        f"(~{round(steps[s]['rejected'] * steps[s]['free'] / max(steps[s]['checked'], 1))})"
        for s in STEPS
    )
    print(f"| {args.robot} | kernel | {c['edges']} | {c['accepted']} | {c['violations']} "
          f"| {rejected} | {free} |")  # fmt: skip
    if c["twin"]:
        print(f"| {args.robot} | python | {c['twin']} | {c['twin_accepted']} | "
              f"{c['twin_violations']} | ({c['twin_disagree']} decided otherwise than the "
              "kernel) | |")  # fmt: skip
    print()
    print(
        f"- {r['problems']} problems ({_source(args)}), {r['arm'].describe()}, "
        f"seed {args.seed}; KC inflation {args.kc_inflation}: {c['grown_queries']} KC guards "
        f"asked, {c['kc_reaches']} took a body farther than its ball"
        + (f"; planes: {c['plane_reaches']} took a body farther" if args.planes else "; no planes")
        + ("" if args.probes else "; no probes (the lazy compiled planner's path check)")
    )
    if args.graze:
        print(f"- grazing (--graze {args.graze:g}): {c['grazing']} edges cut short to end near "
              f"an invalid state, {c['grazing_accepted']} of them accepted")  # fmt: skip
    print(f"- wall {c['wall_s']:.0f} s; kernel {1e6 * c['decide_s'] / c['edges']:.0f} us per "
          f"edge; mesh verification {verify_per:.1f} ms per edge ({c['verified']} verified)"
          + (f"; Python twin {1e3 * c['twin_s'] / c['twin']:.1f} ms per edge" if c["twin"]
             else ""))  # fmt: skip
    low = r["lowest"]
    if low["edge"] is not None:
        name, k, q1, q2 = low["edge"]
        print(f"- smallest distance the mesh re-check measured on an accepted edge: "
              f"{low['scene']:.3g} m to the obstacles (edge {k}, {name}: "
              f"{np.round(q1, 4).tolist()} -> {np.round(q2, 4).tolist()}), {low['any']:.3g} m "
              "to anything (self pairs too)")  # fmt: skip
    if args.cloud:
        print()
        _cloud_table(args, c, low)
    return 1 if c["violations"] or c["twin_violations"] else 0


def _cloud_table(args: argparse.Namespace, c: dict, low: dict) -> None:
    """The table of ``--cloud`` (module docstring), and how its scenes were made."""
    points, kept = np.array(c["points"]), np.array(c["kept"])
    radius = args.point_radius + args.spacing
    filtered = f"voxel {args.spacing:g}" if args.spacing > 0 else "none"
    print("| robot | scenes | points per scene | filter | kept for the certifier | radius "
          "certified / re-checked (m) | edges | accepted | re-checked | violations | "
          "smallest clearance to the cloud (m) | accepted within "
          + " / ".join(f"{1e3 * d:g} mm" for d in NEAR) + " of the cloud |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    print(f"| {args.robot} | {c['scenes']} | {points.mean():,.0f} ({points.min():,}-"
          f"{points.max():,}) | {filtered} | {kept.mean():,.0f} "
          f"({100 * kept.sum() / points.sum():.1f} %) | {radius:g} / {args.point_radius:g} | "
          f"{c['edges']} | {c['accepted']} | {c['rechecked']} | {c['violations']} | "
          f"{low['scene']:.3g} | {' / '.join(str(n) for n in c['near'])} |")  # fmt: skip
    print()
    how = ("each an FCL ball (--balls)" if args.balls
           else "python-fcl's BVH of the points, ArmMeshChecker's own")  # fmt: skip
    print(f"- {args.cloud:,} surface points per object, seed {args.seed}; every accepted edge "
          f"re-checked on the links' meshes against every original point as a ball of "
          f"{args.point_radius:g} m ({how}); scenes built in {c['scene_s']:.0f} s "
          f"({c['scene_s'] / max(c['scenes'], 1):.1f} s each); the kernel's cloud distances "
          f"within a relative tolerance of {c['cloud_tolerance']:g}")  # fmt: skip


if __name__ == "__main__":
    raise SystemExit(main())
