"""The bundled scenarios of example-robot-data's arms (issue 39): a table and a shelf of boxes.

For each arm of ``--arms`` (:data:`kcplan.arm.examples.EXAMPLE_ARMS`), scaled by its reach
``R`` (the farthest any body reaches from the base over random configurations): a table
in front of the arm (top at ``z = 0``, from ``0.3 R`` to ``0.95 R`` ahead), and beside it
a shelf of boxes (two boards, two sides and a back, open towards the arm). The start puts
the arm's last link above the table, the goal inside the shelf between its boards; both
are drawn at random (seeded) among the states that are free on the links' own meshes, and
kept only when ``kc-rrtconnect`` (seed 1) plans between them and its path is free on the
meshes. Writes ``DIR/example_NAME.yaml`` for each arm (``scenarios/arm`` by default)::

    python scripts/make_example_arm_scenarios.py [--arms ur3,ur10,xarm7] [--seed 1] [-o DIR]

A robot with two arms (``--arms baxter``, :data:`HANDS`) gets a hand-over instead: a
table in front of it with a post in its middle, a start with both hands held out to the
sides and a goal with the two hands within 0.3 m of each other above the table, both
arms moving at once.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from kcplan.arm import ArmWorld, load_arm
from kcplan.arm.examples import example_robot
from kcplan.arm.kinematics import body_frames
from kcplan.arm.verify import ArmMeshChecker
from kcplan.planning.problem import plan
from kcplan.scenarios import dump_scenario, parse_scenario

ROOT = Path(__file__).resolve().parents[1]


def scene(reach: float) -> list[dict]:
    """The table and the shelf of an arm of reach ``reach`` (metres), as scenario boxes."""
    R = reach

    def box(centre, size):
        return {"box": {"center": [round(float(c) * R, 4) for c in centre],
                        "size": [round(float(s) * R, 4) for s in size]}}  # fmt: skip

    return [
        box((0.625, 0.0, -0.03), (0.65, 1.2, 0.06)),  # the table
        box((0.2, 0.7, 0.25), (0.45, 0.35, 0.03)),  # the shelf's lower board
        box((0.2, 0.7, 0.62), (0.45, 0.35, 0.03)),  # its upper board
        box((-0.04, 0.7, 0.42), (0.03, 0.35, 0.45)),  # its sides
        box((0.44, 0.7, 0.42), (0.03, 0.35, 0.45)),
        box((0.2, 0.9, 0.42), (0.45, 0.03, 0.45)),  # its back
    ]


def regions(reach: float) -> tuple[np.ndarray, np.ndarray]:
    """Boxes ``[low, high]`` where the last body's centre lies at the start (above the
    table) and at the goal (in the shelf, between its boards)."""
    R = reach
    start = np.array([[0.4, -0.3, 0.1], [0.8, 0.3, 0.4]]) * R
    goal = np.array([[0.05, 0.6, 0.32], [0.35, 0.82, 0.55]]) * R
    return start, goal


def make(name: str, seed: int, folder: Path) -> Path:
    """Write one arm's scenario (module docstring); its path."""
    urdf, srdf, joints = example_robot(name)
    arm = load_arm(urdf, joints, srdf=srdf)
    rng = np.random.default_rng(seed)
    states = rng.uniform(arm.lower, arm.upper, size=(20000, arm.dof))
    frames = np.array([body_frames(arm, q) for q in states])  # (n, bodies, 4, 4)
    radii = np.array([b.semi_axes.max() for b in arm.bodies])
    reach = float((np.linalg.norm(frames[:, :, :3, 3], axis=2) + radii).max())
    data = {
        "name": f"example_{name}",
        "description": f"example-robot-data's {name} beside a table and a shelf of boxes "
        "(scripts/make_example_arm_scenarios.py).",
        "robot": {"example": name},
        "start": {"joints": [0.0] * arm.dof},
        "goal": {"joints": [0.0] * arm.dof},
        "obstacles": scene(reach),
    }
    obstacles = parse_scenario(data, "scene", folder, check=False).obstacles
    world = ArmWorld(arm, obstacles)
    meshes = ArmMeshChecker(arm, obstacles)  # built once, for every state and path
    ends = frames[:, -1, :3, 3]
    picks = []
    for low, high in regions(reach):
        inside = np.flatnonzero(((ends >= low) & (ends <= high)).all(axis=1))
        free = [i for i in inside[:400] if not world.in_collision(states[i])]
        free = [i for i in free[:40]
                if not meshes.check([states[i]] * 2).collides]  # fmt: skip
        if not free:
            raise SystemExit(f"{name}: no free state found in {low.round(3)}..{high.round(3)}")
        picks.append(free)
    path = folder / f"example_{name}.yaml"
    for a in picks[0][:5]:
        for b in picks[1][:5]:
            data["start"]["joints"] = [round(float(v), 6) for v in states[a]]
            data["goal"]["joints"] = [round(float(v), 6) for v in states[b]]
            scenario = parse_scenario(data, str(path), folder, check=False)
            result = plan(scenario, "kc-rrtconnect", time_limit=10.0, seed=1, simplify=False)
            if result.solved:
                q = np.array(result.states).reshape(-1, arm.dof)
                if not meshes.check(q).collides:
                    dump_scenario(data, path)
                    print(f"{path}: reach {reach:.3f} m, solved in {result.time:.3f} s")
                    return path
    raise SystemExit(f"{name}: kc-rrtconnect solved no start and goal pair tried")


HANDS = {"baxter": ("left_gripper_base_link", "right_gripper_base_link")}
"""The two hands' links of each robot with two arms (:func:`make_handover`)."""


def make_handover(name: str, seed: int, folder: Path) -> Path:
    """Write a two-armed robot's hand-over scenario (module docstring); its path."""
    data = {
        "name": f"example_{name}",
        "description": f"example-robot-data's {name} hands over: both arms at once, from "
        "held out to the sides to meet above a table, round a post "
        "(scripts/make_example_arm_scenarios.py).",
        "robot": {"example": name},
        "start": {"joints": []},
        "goal": {"joints": []},
        "obstacles": [
            {"box": {"center": [0.8, 0.0, -0.2], "size": [0.6, 1.2, 0.04]}},
            {"cylinder": {"center": [0.8, 0.0, 0.05], "radius": 0.04, "height": 0.46}},
        ],
    }
    path = folder / f"example_{name}.yaml"
    dof = len(example_robot(name)[2])
    zeros = {"joints": [0.0] * dof}
    scenario = parse_scenario({**data, "start": zeros, "goal": zeros}, str(path), folder,
                              check=False)  # fmt: skip
    arm = scenario.arm
    world = ArmWorld(arm, scenario.obstacles, allowed=scenario.allowed)
    meshes = ArmMeshChecker(arm, scenario.obstacles, scenario.allowed)  # built once
    hands = [[i for i, b in enumerate(arm.bodies) if b.link == link][0] for link in HANDS[name]]

    def wanted(q, goal: bool) -> bool:
        left, right = (body_frames(arm, q)[i][:3, 3] for i in hands)
        if goal:  # the hands together above the table
            low, high = min(left[2], right[2]), max(left[2], right[2])
            return (np.linalg.norm(left - right) < 0.3 and min(left[0], right[0]) > 0.55
                    and -0.1 < low and high < 0.35)  # fmt: skip
        return left[1] > 0.55 and right[1] < -0.55 and min(left[2], right[2]) > 0.0

    rng = np.random.default_rng(seed)
    found = {}
    for _ in range(40000):
        q = rng.uniform(arm.lower, arm.upper)
        role = "goal" if "goal" not in found else "start"
        if not wanted(q, role == "goal") or world.in_collision(q):
            continue
        if meshes.check([q, q]).collides:
            continue
        found[role] = [round(float(v), 4) for v in q]
        if len(found) == 2:
            break
    if len(found) < 2:
        raise SystemExit(f"{name}: no free {'start' if found else 'goal'} found")
    data["start"]["joints"], data["goal"]["joints"] = found["start"], found["goal"]
    scenario = parse_scenario(data, str(path), folder, check=False)
    result = plan(scenario, seed=1, time_limit=10.0)
    if not result.solved:
        raise SystemExit(f"{name}: the default planner solved no hand-over")
    q = np.array(result.states).reshape(-1, arm.dof)
    if meshes.check(q).collides:
        raise SystemExit(f"{name}: the hand-over's path is not free on the meshes")
    dump_scenario(data, path)
    print(f"{path}: a hand-over of {arm.dof} joints, solved in {result.time:.3f} s")
    return path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arms", default="ur3,ur10,xarm7")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("-o", "--output", default=str(ROOT / "scenarios" / "arm"))
    args = parser.parse_args(argv)
    folder = Path(args.output)
    folder.mkdir(parents=True, exist_ok=True)
    for name in args.arms.split(","):
        (make_handover if name in HANDS else make)(name, args.seed, folder)
    return 0


if __name__ == "__main__":
    sys.exit(main())
