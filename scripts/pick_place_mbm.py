"""Pick and place on MotionBenchMaker's table_pick problems, every edge certified.

For each of the first ``--problems`` table_pick problems of a robot's MBM archive (the
scenario ``kcplan import mbm`` writes, each link its own convex hull):

1. *reach*: plan from the start to the problem's goal, a grasp of its target object
   (``--target``, MBM's ``Can1``), the object an obstacle;
2. *carry*: attach the object to the hand (``--link``; in its place relative to the hand
   at the grasp, the fingers allowed to touch it: :func:`kcplan.arm.attach.attach`
   through the scenario's ``attached`` field) and plan to a *place* configuration: the
   grasp turned about the base joint by the first of +-0.6, +-0.9, +-1.2, +-0.3 rad that
   is valid with the object held and leaves the object over the table top, at the height
   it was picked from;
3. *return*: leave the object there (an obstacle at its new pose) and plan back to the
   start.

Every leg is planned by kc-rrtconnect (``--time`` seconds, seed ``--seed``) and its path
verified without gaps on the links' own meshes, the held object on its own shape
(:mod:`kcplan.arm.verify`), code independent of the certificates. It prints (and writes
to ``DIR/pick_place_table.md``) one row per problem (legs solved, planning time per leg,
colliding legs) and a summary row; ``--html FILE`` writes the first problem's whole
sequence as one interactive view (the object standing, carried, then left)::

    python scripts/pick_place_mbm.py [--robot panda] [--problems 20] [--time 10]
        [--seed 1] [--target Can1] [--link panda_hand] [--html FILE] [-o DIR]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from kcplan.arm.kinematics import link_frames
from kcplan.arm.mbm import load_mbm_archive, mbm_scenario
from kcplan.files import write_text_atomic
from kcplan.planning.problem import plan
from kcplan.scenarios import dump_scenario, parse_scenario
from kcplan.world import ScenarioError

ROOT = Path(__file__).resolve().parents[1]
MBM = ROOT.parent / "shared" / "data" / "external" / "mbm"
ROBOTS = {  # URDF, SRDF, the hand and the fingers that hold the object
    "panda": (ROOT / "scenarios" / "arm" / "panda" / "panda.urdf",
              ROOT / "scenarios" / "arm" / "panda" / "panda.srdf",
              "panda_hand", ("panda_leftfinger", "panda_rightfinger")),
}  # fmt: skip
TURNS = (0.6, -0.6, 0.9, -0.9, 1.2, -1.2, 0.3, -0.3)
"""Radians about the base joint tried, in order, for the place configuration."""


def link_pose(arm, q, link: str) -> np.ndarray:
    """The 4 x 4 world frame of URDF link ``link`` at joint vector ``q``."""
    return link_frames(arm, [q], link)[0]


def _pose(obstacle) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = obstacle.rotation, obstacle.center
    return T


def _placed(spec: dict, T: np.ndarray) -> dict:
    """A cylinder's spec moved to the pose T (4 x 4)."""
    quaternion = Rotation.from_matrix(T[:3, :3]).as_quat()  # x, y, z, w
    return {**spec, "center": T[:3, 3].tolist(), "quaternion": quaternion.tolist()}


def _over(T: np.ndarray, table, margin: float) -> bool:
    """Whether the point T's origin lies over the table top's footprint, ``margin`` inside."""
    local = table.rotation.T @ (T[:3, 3] - table.center)
    return bool((np.abs(local[:2]) <= table.extents[:2] - margin).all())


def _leg(scenario, args) -> dict:
    result = plan(scenario, "kc-rrtconnect", args.time, args.seed)
    out = {"solved": result.solved, "time": result.time, "states": result.states}
    if result.solved:
        out["colliding"] = bool(result.verify().collides)
    return out


def sequence(problem, name: str, args, folder: Path) -> dict:
    """The three legs of one problem (module docstring); what each found, and what the
    view needs."""
    urdf, srdf, link, fingers = ROBOTS[args.robot]
    if args.target not in problem.names:
        return {"name": name, "skipped": f"no object {args.target}"}
    k = problem.names.index(args.target)
    target = problem.obstacles[k]
    if target.kind != "cylinder":
        return {"name": name, "skipped": f"{args.target} is a {target.kind}"}
    data = mbm_scenario(problem, name, urdf, srdf, folder / f"{name}.yaml", None, None, "hulls")
    directory = folder
    reach = parse_scenario(data, os.fspath(folder / f"{name}.yaml"), folder)
    arm, q_grasp = reach.arm, reach.goal
    # the object in the hand's frame at the grasp
    held = np.linalg.solve(link_pose(arm, q_grasp, link), _pose(target))
    others = [ob for i, ob in enumerate(data["obstacles"]) if i != k]
    carry_data = {
        **data, "name": f"{name}_carry", "obstacles": others,
        "start": {"joints": q_grasp.tolist()},
        "attached": [{"link": link, "name": args.target, "touch": list(fingers),
                      "cylinder": _placed(target.spec, held)}],
    }  # fmt: skip
    table = next((ob for i, ob in enumerate(problem.obstacles)
                  if problem.names[i] == "table_top"), None)  # fmt: skip
    carry = place = None
    for turn in TURNS:
        q = q_grasp.copy()
        q[0] += turn
        if not (arm.lower[0] <= q[0] <= arm.upper[0]):
            continue
        where = link_pose(arm, q, link) @ held
        if table is not None and not _over(where, table, target.extents[0]):
            continue
        try:
            carry = parse_scenario({**carry_data, "goal": {"joints": q.tolist()}},
                                   f"{name}_carry.yaml", directory)  # fmt: skip
        except ScenarioError:
            continue
        place = where
        break
    row = {"name": name, "turn": None if carry is None else float(carry.goal[0] - q_grasp[0])}
    legs = {"reach": _leg(reach, args)}
    if carry is None:
        return row | {"skipped": "no place configuration", "legs": legs}
    legs["carry"] = _leg(carry, args)
    back_data = {
        **data, "name": f"{name}_return",
        "obstacles": others + [{"cylinder": _placed(target.spec, place)}],
        "start": {"joints": carry.goal.tolist()}, "goal": {"joints": reach.start.tolist()},
    }  # fmt: skip
    back = parse_scenario(back_data, f"{name}_return.yaml", directory)
    legs["return"] = _leg(back, args)
    dump_scenario({**carry_data, "goal": {"joints": carry.goal.tolist()}},
                  folder / f"{name}_carry.yaml")  # fmt: skip
    dump_scenario(back_data, folder / f"{name}_return.yaml")
    return row | {"legs": legs, "scenarios": (reach, carry, back), "held": held,
                  "poses": (_pose(target), place)}  # fmt: skip


def write_view(run: dict, path: str, link: str, frames: int = 60) -> None:
    """The whole sequence of one problem as one HTML view: the held object is one more
    moving mesh, standing, carried by the hand, then left (module docstring)."""
    from kcplan.views.arm import joint_path
    from kcplan.views.html import arm_html, arm_view_data

    reach, carry, back = run["scenarios"]
    legs = [joint_path(run["legs"][leg]["states"], frames) for leg in ("reach", "carry", "return")]
    scenario = dataclasses.replace(carry, name=f"{reach.name}: pick and place",
                                   start=reach.start, goal=carry.goal)  # fmt: skip
    data = arm_view_data(scenario, np.concatenate(legs), timed=True)
    data["frame_ms"] = 80
    arm = carry.arm
    joint = int(arm.model.frames[arm.model.getFrameId(link)].parentJoint)
    extra = len(data["start_frames"])  # a joint of its own for the object
    held_name = arm.attached[0].name
    for item in data["meshes"] + data["cover"]:
        if item.get("link") == held_name or item.get("name", "").startswith(held_name):
            item["joint"] = extra
    placement = None
    for item in data["meshes"]:
        if item["joint"] == extra:
            placement = np.vstack([np.reshape(item["placement"], (3, 4)), [0, 0, 0, 1]])
    placement = np.eye(4) if placement is None else placement

    def row(T: np.ndarray) -> list:
        return np.round(T[:3].ravel(), 12).tolist()

    standing, left = (row(T @ np.linalg.inv(placement)) for T in run["poses"])
    cuts = np.cumsum([len(leg) for leg in legs])
    for f, frame in enumerate(data["joint_frames"]):
        frame.append(standing if f < cuts[0] else frame[joint] if f < cuts[1] else left)
    data["start_frames"].append(standing)
    data["goal_frames"].append(left)
    write_text_atomic(path, arm_html(scenario, data))


def _median(values: list[float]) -> str:
    return f"{statistics.median(values):.3f}" if values else "-"


def table(runs: list[dict]) -> list[str]:
    lines = ["| problem | turn (rad) | reach: solved, s | carry: solved, s | return: solved, s "
             "| colliding legs |", "|---|---|---|---|---|---|"]  # fmt: skip
    for run in runs:
        legs = run.get("legs", {})
        cells = [run["name"], "-" if run.get("turn") is None else f"{run['turn']:+.1f}"]
        for leg in ("reach", "carry", "return"):
            r = legs.get(leg)
            cells.append("-" if r is None else f"{'yes' if r['solved'] else 'no'}, {r['time']:.3f}")
        cells.append(str(sum(r.get("colliding", False) for r in legs.values())))
        lines.append("| " + " | ".join(cells) + (f" ({run['skipped']})" if "skipped" in run
                                                   else "") + " |")  # fmt: skip
    done = [r for r in runs if len(r.get("legs", {})) == 3]
    solved = [r for r in done if all(leg["solved"] for leg in r["legs"].values())]
    colliding = sum(leg.get("colliding", False) for r in runs for leg in r.get("legs", {}).values())
    totals = [sum(leg["time"] for leg in r["legs"].values()) for r in solved]
    lines.append(f"| **all** | {len(done)} of {len(runs)} with a place | sequences solved "
                 f"{len(solved)} / {len(done)} | median total planning {_median(totals)} s | | "
                 f"**{colliding}** |")  # fmt: skip
    return lines


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--robot", choices=sorted(ROBOTS), default="panda")
    p.add_argument("--problems", type=int, default=20)
    p.add_argument("--time", type=float, default=10.0)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--target", default="Can1")
    p.add_argument("--mbm", default=str(MBM), help="the MBM folder (its ROBOT/problems.tar.bz2)")
    p.add_argument("--html", help="the first problem's sequence as one interactive view")
    p.add_argument("-o", "--output", default="pick-place-mbm")
    args = p.parse_args(argv)
    start = time.perf_counter()
    keys = [("table_pick", i) for i in range(1, args.problems + 1)]
    problems = load_mbm_archive(Path(args.mbm) / args.robot / "problems.tar.bz2", keys)
    folder = Path(args.output) / "scenarios"
    folder.mkdir(parents=True, exist_ok=True)
    runs = []
    for index in range(1, args.problems + 1):
        if ("table_pick", index) not in problems:
            continue
        run = sequence(problems["table_pick", index], f"table_pick_{index}", args, folder)
        runs.append(run)
        print(f"{run['name']}: " + ", ".join(f"{leg} {'solved' if r['solved'] else 'NOT solved'}"
              for leg, r in run.get("legs", {}).items()), file=sys.stderr, flush=True)  # fmt: skip
    lines = table(runs)
    write_text_atomic(Path(args.output) / "pick_place_table.md", "\n".join(lines) + "\n")
    print("\n".join(lines))
    if args.html:
        first = next((r for r in runs if len(r.get("legs", {})) == 3
                      and all(leg["solved"] for leg in r["legs"].values())), None)  # fmt: skip
        if first is None:
            print("--html: no problem was solved to the end", file=sys.stderr)
        else:
            write_view(first, args.html, ROBOTS[args.robot][2])
            print(f"view of {first['name']} written to {args.html}", file=sys.stderr)
    colliding = sum(leg.get("colliding", False) for r in runs for leg in r.get("legs", {}).values())
    print(f"{len(runs)} problems in {time.perf_counter() - start:.0f} s", file=sys.stderr)
    return 1 if colliding else 0


if __name__ == "__main__":
    sys.exit(main())
