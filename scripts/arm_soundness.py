"""Soundness of the arm certifier on random joint-space edges, checked on the meshes (issue 25).

Random edges of every length in MotionBenchMaker scenes (:mod:`kcplan.arm.mbm`, VAMP's
``problems.tar.bz2``; the first ``--per-class`` problems of each of the 7 classes, taken
in turn, each with its allowed collision matrix; self-collision included): ``q1`` uniform
in the joint limits and valid for the cover (OMPL's contract: an edge starts at a valid
state), ``q'`` uniform in the limits and ``q2 = q1 + t (q' - q1)`` with ``t`` log-uniform
in ``[0.01, 1]``. The joints outside the group (fingers) are fixed at the first problem's
start values. Each edge is decided by the compiled certifier
(:class:`kcplan.planning.kernel.KernelArmCertifier`) and, for the first ``--twin`` edges,
also by its Python twin (:class:`kcplan.planning.arm_certifier.ArmEdgeCertifier`), both
with the certificates of the ``kc-*`` planners (the clearance balls and the KC guards of
inflation ``--kc-inflation``; 0: the balls alone, as ``ca-*``).

Every **accepted** edge (of either backend) is re-checked by the gap-free mesh verifier
(:class:`kcplan.arm.verify.ArmMeshChecker`: the links' own collision meshes, python-fcl,
independent of the covers and the certifiers); a *violation* is an accepted edge it finds
in collision, and must be 0. A rejected edge is counted under the step that rejected it
(the certifier's counters: an end state invalid or outside the limits, a colliding probe,
a guard in contact, not proven within ``max_guards``); a random ``--free-check`` fraction
of the rejected edges is verified on the meshes too, which estimates how many *free*
edges each step rejects (the price of proving, partly the cover's). Progress lines on
stderr; a Markdown table on stdout::

    python scripts/arm_soundness.py [--robot panda] [--edges 100000] [--seed 1]
        [--per-class 100] [--representation R] [--bodies 2] [--max-offset D] [--twin 0]
        [--free-check 0.05]
        [--kc-inflation 0.2] [--no-planes]

The arm's links are each their own convex hull with ``--representation hulls`` (kcplan's
default), else covered by ``--bodies`` ellipsoids each (2 by default: fast to fit
and to check), or with ``--max-offset D`` as :func:`kcplan.arm.load_arm` covers them by
default (``D = 0.01``: hundreds of bodies, a cold fit of about 20 minutes).
"""

from __future__ import annotations

import argparse
import functools
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

from kcplan.arm import ArmWorld, load_arm
from kcplan.arm.attach import Attached, attach
from kcplan.arm.mbm import MBM_CLASSES, load_mbm_archive
from kcplan.arm.verify import ArmMeshChecker
from kcplan.planning.arm_certifier import DEFAULT_KC_INFLATION, ArmEdgeCertifier
from kcplan.planning.kernel import KernelArmCertifier

ROOT = Path(__file__).resolve().parents[1]
MBM = ROOT.parent / "shared" / "data" / "external" / "mbm"
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


def _edge(rng: np.random.Generator, arm, decide) -> tuple[np.ndarray, np.ndarray]:
    """A random edge from a valid state (see the module docstring)."""
    for _ in range(10_000):
        q1 = rng.uniform(arm.lower, arm.upper)
        if decide.state_valid(q1):
            break
    else:
        raise RuntimeError("no valid state in 10,000 samples")
    t = math.exp(rng.uniform(math.log(0.01), 0.0))
    return q1, q1 + t * (rng.uniform(arm.lower, arm.upper) - q1)


def study(args: argparse.Namespace, out=sys.stderr) -> dict:
    """Decide and verify ``args.edges`` random edges; the counts (module docstring)."""
    rng = np.random.default_rng(args.seed)
    folder = Path(args.mbm) / args.robot
    t0 = time.perf_counter()
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
    if args.attach:
        arm = attach(arm, [held_part(args.robot, args.attach)])
    print(f"{len(chosen)} problems, {arm.describe()}, {len(arm.self_pairs)} self pairs, "
          f"ready in {time.perf_counter() - t0:.1f} s", file=out, flush=True)  # fmt: skip
    c = {"edges": 0, "accepted": 0, "violations": 0, "verified": 0, "twin": 0,
         "twin_accepted": 0, "twin_violations": 0, "twin_disagree": 0,
         "decide_s": 0.0, "verify_s": 0.0, "twin_s": 0.0, "grown_queries": 0,
         "kc_reaches": 0, "plane_reaches": 0}  # fmt: skip
    steps = {name: {"rejected": 0, "checked": 0, "free": 0} for name in STEPS}
    per_problem = math.ceil(args.edges / len(chosen))
    start = time.perf_counter()
    for k in range(args.edges):
        if k % per_problem == 0:
            problem = chosen[(k // per_problem) % len(chosen)]
            world = ArmWorld(arm, problem.obstacles, allowed=problem.allowed)
            kernel = KernelArmCertifier(world, kc_inflation=args.kc_inflation, planes=args.planes)
            meshes = ArmMeshChecker(arm, problem.obstacles, problem.allowed)
            twin = None
            if k < args.twin:
                twin = ArmEdgeCertifier(
                    world, kc_inflation=args.kc_inflation, planes=args.planes
                )
        q1, q2 = _edge(rng, arm, kernel)
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
            verdict = verified()
            c["violations"] += verdict
            if verdict:
                print(f"VIOLATION: {problem_name(problem)} {q1.tolist()} -> {q2.tolist()}",
                      file=out, flush=True)  # fmt: skip
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
    return {"counts": c, "steps": steps, "arm": arm, "problems": len(chosen)}


def _collides(meshes: ArmMeshChecker, q1: np.ndarray, q2: np.ndarray, c: dict) -> bool:
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
        from kcplan.world.scenario import FieldReader

        part = _cylinder(FieldReader("part"), PARTS[shape], 0)
    else:
        folder = ROOT / "scenarios" / "arm" / "panda"
        part = parse_scenario(data, "part", folder, check=False).obstacles[0]
    link, touch = HANDS[robot]
    return Attached("part", link, part, touch)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", choices=("panda", "ur5"), default="panda")
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
    parser.add_argument("--mbm", default=os.fspath(MBM), help="folder of the MBM robots")
    args = parser.parse_args(argv)
    if args.bodies is None and args.max_offset is None and args.representation != "hulls":
        args.bodies = 2
    if args.edges < 1 or args.per_class < 1 or not 0.0 <= args.free_check <= 1.0:
        parser.error("expected --edges >= 1, --per-class >= 1, 0 <= --free-check <= 1")
    if not (math.isfinite(args.kc_inflation) and args.kc_inflation >= 0.0):
        parser.error("expected --kc-inflation >= 0")
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
        f"- {r['problems']} problems ({args.per_class} per class), {r['arm'].describe()}, "
        f"seed {args.seed}; KC inflation {args.kc_inflation}: {c['grown_queries']} KC guards "
        f"asked, {c['kc_reaches']} took a body farther than its ball"
        + (f"; planes: {c['plane_reaches']} took a body farther" if args.planes else "; no planes")
    )
    print(f"- wall {c['wall_s']:.0f} s; kernel {1e6 * c['decide_s'] / c['edges']:.0f} us per "
          f"edge; mesh verification {verify_per:.1f} ms per edge ({c['verified']} verified)"
          + (f"; Python twin {1e3 * c['twin_s'] / c['twin']:.1f} ms per edge" if c["twin"]
             else ""))  # fmt: skip
    return 1 if c["violations"] or c["twin_violations"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
