"""``kcplan bounds``: KC bounds and volumes of one robot."""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Sequence

from kcplan.cli.common import InputError, finite_float


def bounds_report(semi_axes: Sequence[float], inflation: float) -> dict:
    """Vertex count and volumes of both bounds and of the true KC set, with ratios.

    Volumes are in rad^r * length^n over the identity component, exponential-coordinate
    measure (see :mod:`kcplan.kc.volume`).
    """
    from kcplan.kc import ConvexLowerBound, GeometricLowerBound, kc_volume

    t0 = time.perf_counter()
    convex = ConvexLowerBound(semi_axes, inflation)
    geometric = GeometricLowerBound(semi_axes, inflation)
    v_convex = convex.volume()
    v_geometric = geometric.volume()
    v_true = kc_volume(semi_axes, inflation)
    return {
        "semi_axes": [float(x) for x in convex.a],
        "inflation": convex.inflation,
        "convex_vertices": convex.n_vertices,
        "convex_halfspaces": int(len(convex.halfspaces[1])),
        "convex_rotation_extent": convex.rotation_extent,
        "volume_convex": v_convex,
        "volume_geometric": v_geometric,
        "volume_kc": v_true,
        "ratio_convex": v_convex / v_true,
        "ratio_geometric": v_geometric / v_true,
        "seconds": time.perf_counter() - t0,
        "_bound": convex,
    }


def run(args: argparse.Namespace) -> int:
    """Build the bounds, print the report (``--json``) and draw ``--plot``."""
    if len(args.semi_axes) not in (2, 3):
        raise InputError(
            f"kcplan bounds: --semi-axes: expected 2 or 3 numbers, got {len(args.semi_axes)}"
        )
    try:
        report = bounds_report(args.semi_axes, args.inflation)
    except ValueError as err:
        raise InputError(f"kcplan bounds: {err}") from None
    bound = report.pop("_bound")
    if args.plot:
        from kcplan.views.plots import plot_convex_bound

        plot_convex_bound(bound, args.plot)
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    n = len(report["semi_axes"])
    unit = "rad * length^2" if n == 2 else "rad^3 * length^3"
    print(f"robot semi-axes {report['semi_axes']}, inflation {report['inflation']:g}")
    print(
        f"convex lower bound : {report['convex_vertices']} vertices, "
        f"{report['convex_halfspaces']} half-spaces, rotation extent "
        f"{report['convex_rotation_extent']:.4f} rad"
    )
    print(f"volume convex      : {report['volume_convex']:.6g} {unit}")
    print(f"volume geometric   : {report['volume_geometric']:.6g} {unit}")
    print(f"volume true KC     : {report['volume_kc']:.6g} {unit}")
    print(f"convex / true      : {report['ratio_convex']:.4f}")
    print(f"geometric / true   : {report['ratio_geometric']:.4f}")
    if args.plot:
        print(f"plot written to {args.plot}")
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``kcplan bounds`` on the subcommand parsers ``sub``."""
    p = sub.add_parser(
        "bounds",
        help="volumes of the convex and geometric lower bounds and of the true KC set",
        description="Build the convex lower bound of E_a in (1 + eps) E_a and compare the "
        "volumes of both lower bounds with the true KC volume (identity component, "
        "exponential coordinates).",
    )
    p.add_argument(
        "--semi-axes",
        nargs="+",
        type=finite_float,
        required=True,
        metavar="A",
        help="robot semi-axes, 2 (ellipse) or 3 (ellipsoid) numbers",
    )
    p.add_argument(
        "--inflation",
        type=finite_float,
        required=True,
        metavar="EPS",
        help="guard inflation eps > 0; the guard is (1 + eps) times the robot",
    )
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.add_argument("--plot", metavar="FILE.png", help="draw the convex lower bound")
    p.set_defaults(handler=run)
