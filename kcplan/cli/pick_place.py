"""``kcplan pick-place``: the paper's pick-and-place error analysis."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

from kcplan.cli.common import InputError, finite_float, positive_float, positive_int


def _rows_csv(rows: Sequence[dict]) -> str:
    import csv
    import io

    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()


def run(args: argparse.Namespace) -> int:
    """Run the noise study and write its tables and figure."""
    from kcplan.files import write_text_atomic
    from kcplan.pickplace.analysis import noise_study
    from kcplan.pickplace.plots import plot_noise_inflation_entropy

    if any(s < 0 for s in args.sigma_deg):
        raise InputError(
            f"kcplan pick-place: --sigma-deg: expected numbers >= 0, got {args.sigma_deg}"
        )
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise InputError(f"{out}: expected an output folder, got an existing file")
    out.mkdir(parents=True, exist_ok=True)

    def report(row: dict) -> None:
        print(
            f"sigma {row['sigma_deg']:g} deg: eps exact {row['eps_exact_median']:.4g} "
            f"[{row['eps_exact_p10']:.4g}, {row['eps_exact_p90']:.4g}], geometric "
            f"{row['eps_geometric_median']:.4g}; contained at eps {args.inflation:g}: exact "
            f"{row['contained_exact_fraction']:.0%}, geometric "
            f"{row['contained_geometric_fraction']:.0%} of trials; S true "
            f"{row['entropy_true']:.3f}, S geometric {row['entropy_geometric']:.3f}",
            flush=True,
        )

    q, forward, arm_name = _arm(args)
    print(f"arm: {arm_name}, held at {args.link or 'the flange'}, joints "
          f"{', '.join(f'{v:.4g}' for v in q)} rad")  # fmt: skip
    trials, sigmas = noise_study(
        args.sigma_deg, args.trials, args.poses, args.inflation, args.seed, q=q,
        progress=report, forward=forward,
    )  # fmt: skip
    write_text_atomic(out / "trials.csv", _rows_csv(trials))
    write_text_atomic(out / "summary.csv", _rows_csv(sigmas))
    plot_noise_inflation_entropy(sigmas, args.inflation, out / "pick_place.png")
    print(f"written: {out / 'summary.csv'}, {out / 'trials.csv'}, {out / 'pick_place.png'}")
    return 0


def _arm(args: argparse.Namespace):
    """``(joint angles, forward kinematics or None, what the arm is)``: the paper's KUKA
    LWR, or ``--urdf``'s arm holding the object at ``--link`` (Pinocchio's model)."""
    import numpy as np

    from kcplan.pickplace.analysis import PAPER_JOINTS

    if args.urdf is None:
        for flag in ("link", "joints", "q"):
            if getattr(args, flag):
                raise InputError(f"kcplan pick-place: --{flag}: only with --urdf")
        return PAPER_JOINTS, None, "KUKA LWR 4 (paper Table 2, DH)"
    from kcplan.arm import ArmError, load_arm
    from kcplan.arm.kinematics import link_frames
    from kcplan.arm.model import movable_joints

    if not Path(args.urdf).is_file():
        raise InputError(f"{args.urdf}: --urdf: expected an existing URDF file")
    if not args.link:
        raise InputError(f"{args.urdf}: --link: expected the link that holds the object")
    try:
        joints = args.joints or movable_joints(args.urdf)
        arm = load_arm(args.urdf, joints, package_dirs=args.package_dir)
    except ArmError as err:
        raise InputError(str(err)) from None
    q = 0.5 * (arm.lower + arm.upper) if args.q is None else np.array(args.q, dtype=float)
    if q.shape != (arm.dof,):
        raise InputError(f"{args.urdf}: --q: expected {arm.dof} joint values "
                         f"({', '.join(arm.joints)}), got {len(q)}")  # fmt: skip
    if not arm.within_limits(q):
        raise InputError(f"{args.urdf}: --q: expected joint values within the URDF's limits")
    try:
        link_frames(arm, q[None], args.link)
    except ValueError as err:
        raise InputError(f"{args.urdf}: --{err}") from None
    return q, lambda Q: link_frames(arm, Q, args.link), f"{arm.describe()}"


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``kcplan pick-place`` on the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "pick-place",
        help="pick-and-place error analysis: required target inflation and parts entropy",
        description="The paper's Sec. 9.2 study with a KUKA LWR (Table 2 setting; or any "
        "URDF arm: --urdf, --link): for each "
        "joint noise level, TRIALS error spaces of POSES placements; the smallest target "
        "inflation containing each (exact margin, geometric lower bound), whether the "
        "target inflated by --inflation contains it, and the parts entropy log V at the "
        "median required inflation. Writes summary.csv, trials.csv and pick_place.png.",
    )
    p.add_argument(
        "--sigma-deg",
        nargs="+",
        type=finite_float,
        default=[0.0, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5],
        metavar="S",
        help="joint noise standard deviations in degrees (default 0 0.02 0.05 0.1 0.2 0.3 0.5)",
    )
    p.add_argument("--trials", type=positive_int, default=20, help="trials per level (default 20)")
    p.add_argument(
        "--poses", type=positive_int, default=100, help="placements per trial (default 100)"
    )
    p.add_argument(
        "--inflation",
        type=positive_float,
        default=0.05,
        metavar="EPS",
        help="the target's inflation for the containment question (default 0.05)",
    )
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument(
        "--urdf",
        metavar="URDF",
        help="study this arm instead of the paper's KUKA LWR (Pinocchio's kinematics)",
    )
    p.add_argument("--link", help="with --urdf: the link that holds the object (its frame)")
    p.add_argument(
        "--joints",
        nargs="+",
        metavar="JOINT",
        help="with --urdf: the joints (default: every movable one)",
    )
    p.add_argument(
        "--q",
        nargs="+",
        type=finite_float,
        metavar="Q",
        help="with --urdf: the placing configuration, rad (default: the middle of the limits)",
    )
    p.add_argument(
        "--package-dir", action="append", default=[], metavar="DIR",
        help="with --urdf: a folder of package:// meshes (repeatable)",
    )  # fmt: skip
    p.add_argument(
        "-o",
        "--output",
        default="pick-place",
        metavar="DIR",
        help="output folder (default pick-place)",
    )
    p.set_defaults(handler=run)
