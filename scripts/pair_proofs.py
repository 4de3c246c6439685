"""Which self pairs of an arm can touch: proofs over the joint box, beside the SRDF (issue 38).

For each robot (the MBM Panda and UR5 with their SRDFs, or ``--urdf``/``--srdf``/
``--joints``), the links as their hulls (kcplan's default), three pair sets are proved
(:mod:`kcplan.arm.pairs`: a pair proven apart can never touch within the joint limits, a
touching one has a witness configuration): the pairs the SRDF leaves checked, every pair
of links not joined by a joint (no SRDF), and the SRDF's disabled pairs among those
(MoveIt's setup assistant disables a pair it never saw touch in random samples: a
"Never" pair found touching here is one it missed). Prints a Markdown table, one row per
robot, and the SRDF-disabled pairs that touch with their witnesses::

    python scripts/pair_proofs.py [--robot panda,ur5] [--max-boxes 4000]
"""

from __future__ import annotations

import argparse
import collections
import sys
import time
from pathlib import Path

from kcplan.arm import load_arm
from kcplan.arm.pairs import MAX_BOXES, prove_pairs

ROOT = Path(__file__).resolve().parents[1]
MBM = ROOT.parent / "shared" / "data" / "external" / "mbm"


GROUPS = {  # the planning groups of MBM's problems
    "panda": tuple(f"panda_joint{i}" for i in range(1, 8)),
    "ur5": ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
            "wrist_2_joint", "wrist_3_joint"),
}  # fmt: skip


def robot_files(name: str) -> tuple[Path, Path, tuple[str, ...]]:
    """URDF, SRDF and planning group of one MBM robot."""
    urdf = MBM / name / f"{name}.urdf"
    if name == "panda":  # the bundled copy: the same URDF, its meshes beside it
        urdf = ROOT / "scenarios" / "arm" / "panda" / "panda.urdf"
    return urdf, urdf.with_suffix(".srdf"), GROUPS[name]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="panda,ur5", help="MBM robots: panda, ur5")
    parser.add_argument("--max-boxes", type=int, default=MAX_BOXES)
    args = parser.parse_args(argv)
    print("| robot | links | pairs (no SRDF) | proven apart | touch | unknown | SRDF checks "
          "| of those apart | SRDF disables | of those touching | proof time s |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    missed = []
    for name in args.robot.split(","):
        urdf, srdf, joints = robot_files(name)
        with_srdf = load_arm(urdf, joints, srdf=srdf)
        bare = load_arm(urdf, joints)
        t0 = time.perf_counter()
        every = prove_pairs(bare, max_boxes=args.max_boxes)
        checked = prove_pairs(with_srdf, max_boxes=args.max_boxes)
        seconds = time.perf_counter() - t0
        kept = {p.links for p in checked} | {p.links[::-1] for p in checked}
        disabled = [p for p in every if p.links not in kept]
        v_all = collections.Counter(p.verdict for p in every)
        v_checked = collections.Counter(p.verdict for p in checked)
        v_disabled = collections.Counter(p.verdict for p in disabled)
        print(f"| {name} | {len(bare.bodies)} | {len(every)} | {v_all['apart']} | "
              f"{v_all['touches']} | {v_all['unknown']} | {len(checked)} | "
              f"{v_checked['apart']} | {len(disabled)} | {v_disabled['touches']} | "
              f"{seconds:.2f} |")  # fmt: skip
        missed += [(name, p) for p in disabled if p.verdict == "touches"]
    print()
    for name, p in missed:
        witness = ", ".join(f"{v:.3f}" for v in p.witness)
        print(f"- {name}: the SRDF disables {p.links[0]} / {p.links[1]}, which touch at "
              f"[{witness}]")
    if not missed:
        print("- no pair the SRDFs disable was found touching")
    return 0


if __name__ == "__main__":
    sys.exit(main())
