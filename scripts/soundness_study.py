"""Soundness of the edge certificates on random edges, checked independently (issue 12).

Random worlds of thin rotated walls, balls, boxes and ellipsoids
(:mod:`kcplan.world.clutter`; 2D and 3D, several robot shapes),
random edges from a free state closer to an obstacle than the robot's size (short, medium
and long, with and without rotation); with ``--arena`` each 3D world is also enclosed in a
convex mesh (a stretched icosphere of 1,280 triangles, semi-axes 26 to 34, so that some
robot poses reach or leave it: the kernel's mesh planes and coal's BVH both decide); with
``--bodies K`` each world gets a robot of K ellipses/ellipsoids offset up to 3 from its
origin (:func:`kcplan.world.clutter.random_robot`: long levers, the region certificate's
arc rule; the paper's polytope, for one body at the origin, is left out), each
decided by the certifier (``--backend
kernel``: the compiled :class:`kcplan.certification.kernel.KernelCertifier`, the default;
``python``: the Python :class:`kcplan.certification.certifier.EdgeCertifier`) with every
certificate set of the ablation (``ca``, ``kc-paper``, ``kc``, ``kc-lever``). Every accepted edge is
re-checked by gap-free conservative advancement with FCL clearances
(:func:`kcplan.planning.verify.verify_path`, which shares no code with the certificates);
a *violation* is an accepted edge that check finds in collision, and must be 0. A *free
edge rejected* is a rejected edge the check finds free (the price of proving). Prints a
Markdown table::

    python scripts/soundness_study.py [--edges 100000] [--seed 1] [--dimensions 2 3] \
        [--backend kernel] [--arena] [--bodies K]
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np
import trimesh

from kcplan.certification.certifier import CERTIFICATE_SETS, EdgeCertifier
from kcplan.certification.kernel import KernelCertifier
from kcplan.certification.ladder import GuardLadder
from kcplan.planning.verify import verify_path
from kcplan.world import CollisionWorld, Scenario
from kcplan.world.clutter import random_pose, random_robot, random_scenario
from kcplan.world.obstacles import Obstacle

SHAPES = {
    2: ([5.0, 3.5], [1.0, 0.4], [3.0, 3.0], [8.0, 1.0]),
    3: ([4.0, 2.5, 2.0], [1.0, 1.0, 0.3]),
}


def certifier(backend: str, world, kinds, ladder):
    """The edge certifier of ``backend`` for ``world``'s robot."""
    if backend == "kernel":
        return KernelCertifier(world, certificates=kinds, ladder=ladder)
    return EdgeCertifier(world, world.robot, kinds, ladder)


def with_arena(scenario: Scenario, rng: np.random.Generator) -> Scenario:
    """``scenario`` inside a convex mesh: an icosphere stretched to random semi-axes."""
    sphere = trimesh.creation.icosphere(subdivisions=3)
    vertices = sphere.vertices * rng.uniform(26.0, 34.0, 3)
    arena = Obstacle(
        "mesh", len(scenario.obstacles), {"file": "arena"}, np.zeros(3), np.eye(3),
        np.zeros(3), (), vertices, np.asarray(sphere.faces),
    )  # fmt: skip
    return dataclasses.replace(scenario, obstacles=(*scenario.obstacles, arena))


def study(
    n: int,
    edges: int,
    rng: np.random.Generator,
    backend: str = "kernel",
    arena: bool = False,
    bodies: int = 1,
) -> dict:
    """Counts per certificate set for ``edges`` random edges in ``n`` dimensions, with
    one body at the origin (:data:`SHAPES`) or ``bodies`` offset ones."""
    sets = {
        name: kinds
        for name, kinds in CERTIFICATE_SETS.items()
        if bodies == 1 or "polytope" not in kinds
    }
    counts = {name: dict.fromkeys(("accepted", "violations", "free_rejected"), 0) for name in sets}
    done = 0
    while done < edges:
        if bodies == 1:
            robot = SHAPES[n][int(rng.integers(len(SHAPES[n])))]
        else:
            robot = random_robot(rng, n, bodies)
        scenario = random_scenario(rng, n, robot, int(rng.integers(6, 16)))
        world = CollisionWorld(with_arena(scenario, rng) if arena and n == 3 else scenario)
        size = world.robot.largest_semi_axis
        certifiers = {
            name: certifier(
                backend, world, kinds, GuardLadder(robot) if "polytope" in kinds else None
            )
            for name, kinds in sets.items()
        }
        for _ in range(200):
            p1 = random_pose(rng, n, -22, 22)
            if not 0.0 < world.clearance(p1) < size:  # free, and near an obstacle
                continue
            p2 = p1.copy()
            p2[:n] += rng.normal(0, rng.choice([0.5, 3.0, 15.0]), n)
            if rng.random() < 0.5:
                p2[n:] = random_pose(rng, n, 0, 1)[n:]
            collides = verify_path(world, [p1, p2]).collides
            for name, decide in certifiers.items():
                ok = decide.check(p1, p2)
                c = counts[name]
                c["accepted"] += ok
                c["violations"] += ok and collides
                c["free_rejected"] += (not ok) and not collides
            done += 1
            if done >= edges:
                break
    return counts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--edges", type=int, default=100_000, help="edges per dimension")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--dimensions", type=int, nargs="+", default=[2, 3], choices=[2, 3])
    parser.add_argument(
        "--backend",
        choices=("kernel", "python"),
        default="kernel",
        help="who certifies: the compiled kernel (default) or the Python certifier",
    )
    parser.add_argument("--arena", action="store_true", help="enclose each 3D world in a mesh")
    parser.add_argument(
        "--bodies", type=int, default=1, help="bodies per robot (> 1: offset from its origin)"
    )
    args = parser.parse_args()
    if args.bodies < 1:
        parser.error("--bodies: expected a number >= 1")
    rng = np.random.default_rng(args.seed)
    print("| dimension | certificates | edges | accepted | violations | free edges rejected |")
    print("|---|---|---|---|---|---|")
    for n in args.dimensions:
        t0 = time.perf_counter()
        counts = study(n, args.edges, rng, args.backend, args.arena, args.bodies)
        for name, c in counts.items():
            print(
                f"| {n}D | {name} | {args.edges} | {c['accepted']} | {c['violations']} "
                f"| {c['free_rejected']} |",
                flush=True,
            )
        print(f"<!-- {n}D: {time.perf_counter() - t0:.0f} s -->", flush=True)


if __name__ == "__main__":
    main()
