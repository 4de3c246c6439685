"""Reproduce the tables and figures of "The Kinematics of Containment for N-Dimensional
Ellipsoids" (Ruan, Ding, Ma, Chirikjian) with kcplan's exact margin and bounds.

Writes CSV files and PNG figures into --out:

* table1_confusion.csv: exact vs first-order containment over random configurations
  (Table 1), plus a targeted search on the boundary of the first-order region;
* fig7_8_volumes_2d_*.csv/png: 2D volumes vs inflation and vs aspect ratio;
* fig9_10_volumes_3d_*.csv/png: 3D volumes vs inflation and vs the two aspect ratios;
* eq38_extreme_rotation.csv: extreme rotation, closed forms vs numerical.

Usage: python scripts/reproduce_paper.py --out docs/paper [--quick] [--samples 10000]
    [--points K]
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

from kcplan.geometry import containment_margin, first_order_margin, ray_extent
from kcplan.kc import ConvexLowerBound, GeometricLowerBound, kc_volume
from kcplan.views.plots import save_figure

A2 = np.array([5.0, 3.5])
A3 = np.array([4.0, 2.5, 2.0])
VOLUME_COLUMNS = [
    "volume_convex",
    "volume_geometric",
    "volume_kc",
    "ratio_convex",
    "ratio_geometric",
]


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def write_csv(path: Path, header: list[str], rows: list[list]) -> None:
    tmp = path.with_suffix(path.suffix + ".tmp")
    with tmp.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)
    tmp.replace(path)


def exact_extreme_rotation(a: np.ndarray, eps: float) -> float:
    """Closed form: sin(theta) = ((1+eps)^2 - 1) / ((1+eps)(a1/a2 - a2/a1)) (rotation in
    the plane of a1 > a2; derived from det = 1 and trace of M^T M, see README)."""
    s = ((1 + eps) ** 2 - 1) / ((1 + eps) * (a[0] / a[1] - a[1] / a[0]))
    return float(np.arcsin(min(s, 1.0)))


def first_order_extreme_rotation(a: np.ndarray, eps: float) -> float:
    """Closed form of the first-order condition: smallest root x = theta^2 of
    x^2 + x (2 - L (p^2 + 1/p^2)) + (L - 1)^2 = 0, L = (1+eps)^2, p = a2/a1."""
    lam, p = (1 + eps) ** 2, a[1] / a[0]
    bq = 2 - lam * (p**2 + p**-2)
    x = (-bq - np.sqrt(bq**2 - 4 * (lam - 1) ** 2)) / 2
    return float(np.sqrt(x))


def table1(out: Path, samples: int, rng: np.random.Generator) -> list[list]:
    rows = []
    for a, eps in [(A2, 0.08), (A3, 0.1)]:
        n = len(a)
        b = (1 + eps) * a
        r = 1 if n == 2 else 3
        theta = (
            exact_extreme_rotation(np.sort(a)[::-1][:2], eps)
            if n == 2
            else max(
                exact_extreme_rotation(np.array([a[i], a[j]]), eps)
                for i, j in [(0, 1), (0, 2), (1, 2)]
            )
        )
        box = np.r_[np.full(r, 1.2 * theta), 1.2 * eps * a]
        X = (rng.random((samples, len(box))) * 2 - 1) * box
        exact = containment_margin(a, b, X) <= 1
        first = first_order_margin(a, b, X) <= 1
        # targeted: points on the boundary of F along random directions
        D = rng.normal(size=(samples, len(box))) * box
        t = ray_extent(lambda Y, a=a, b=b: first_order_margin(a, b, Y), D, upper=1.0)
        m_boundary = containment_margin(a, b, t[:, None] * D)
        rows.append(
            [
                n,
                a.tolist(),
                eps,
                samples,
                int(np.sum(exact & first)),
                int(np.sum(exact & ~first)),
                int(np.sum(~exact & first)),
                int(np.sum(~exact & ~first)),
                int(np.sum(m_boundary > 1 + 1e-12)),
                float(m_boundary.max()),
            ]
        )
        log(f"table 1, n = {n}: {rows[-1]}")
    write_csv(
        out / "table1_confusion.csv",
        [
            "n",
            "semi_axes",
            "inflation",
            "samples",
            "exact_in_first_in",
            "exact_in_first_out",
            "exact_out_first_in",
            "exact_out_first_out",
            "boundary_points_of_F_outside_KC",
            "max_exact_margin_on_boundary_of_F",
        ],
        rows,
    )
    return rows


def volumes(a: np.ndarray, eps: float) -> tuple[float, float, float]:
    return (
        ConvexLowerBound(a, eps).volume(),
        GeometricLowerBound(a, eps).volume(),
        kc_volume(a, eps),
    )


def sweep(out: Path, name: str, xlabel: str, xs, shapes, title: str) -> None:
    rows = []
    for x, (a, eps) in zip(xs, shapes, strict=True):
        t0 = time.perf_counter()
        vc, vg, vk = volumes(a, eps)
        rows.append([x, a.tolist(), eps, vc, vg, vk, vc / vk, vg / vk])
        log(
            f"{name}: x = {x:.4g}  convex/true {vc / vk:.4f}  geometric/true {vg / vk:.4f} "
            f"({time.perf_counter() - t0:.1f}s)"
        )
    write_csv(
        out / f"{name}.csv",
        [
            "x",
            "semi_axes",
            "inflation",
            *VOLUME_COLUMNS,
        ],
        rows,
    )
    import matplotlib.pyplot as plt

    R = np.array([[r[0], r[3], r[4], r[5], r[6], r[7]] for r in rows], dtype=float)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ax1.plot(R[:, 0], R[:, 3], "k-o", label="true KC")
    ax1.plot(R[:, 0], R[:, 2], "-s", label="geometric lower bound")
    ax1.plot(R[:, 0], R[:, 1], "-^", label="convex lower bound (sound)")
    ax1.set_yscale("log")
    ax1.set_xlabel(xlabel)
    ax1.set_ylabel("volume (exponential coordinates)")
    ax1.legend()
    ax2.plot(R[:, 0], R[:, 5], "-s", label="geometric / true")
    ax2.plot(R[:, 0], R[:, 4], "-^", label="convex / true")
    ax2.set_xlabel(xlabel)
    ax2.set_ylabel("fraction of the true KC volume")
    ax2.set_ylim(0, 1)
    ax2.legend()
    fig.suptitle(title)
    save_figure(fig, out / f"{name}.png")


def aspect_grid(out: Path, alphas) -> None:
    rows = []
    for a1 in alphas:
        for a2 in alphas:
            a = np.array([4.0, 4.0 / a1, 4.0 / a2])
            vc, vg, vk = volumes(a, 0.1)
            rows.append([a1, a2, a.tolist(), vc, vg, vk, vc / vk, vg / vk])
            log(
                f"fig 10: alpha = ({a1:.3f}, {a2:.3f})  convex/true {vc / vk:.4f}  "
                f"geometric/true {vg / vk:.4f}"
            )
    write_csv(
        out / "fig10_volumes_3d_aspect.csv",
        [
            "alpha1",
            "alpha2",
            "semi_axes",
            *VOLUME_COLUMNS,
        ],
        rows,
    )
    import matplotlib.pyplot as plt

    k = len(alphas)
    lo, hi = alphas[0], alphas[-1]
    if hi == lo:  # one point (--points 1): give the image a width
        lo, hi = lo - 0.05, hi + 0.05
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, col, label in [(axes[0], 7, "geometric / true"), (axes[1], 6, "convex / true")]:
        Z = np.array([r[col] for r in rows]).reshape(k, k)
        im = ax.imshow(
            Z.T,
            origin="lower",
            extent=[lo, hi, lo, hi],
            aspect="auto",
            cmap="viridis",
        )
        fig.colorbar(im, ax=ax)
        ax.set_xlabel("alpha1 = a1 / a2")
        ax.set_ylabel("alpha2 = a1 / a3")
        ax.set_title(label)
    fig.suptitle("3D volume ratios vs aspect, a1 = 4, eps = 0.1 (paper Fig. 10)")
    save_figure(fig, out / "fig10_volumes_3d_aspect.png")


def extreme_rotation_table(out: Path) -> None:
    rows = []
    for eps in [0.02, 0.05, 0.08, 0.1, 0.15, 0.2]:
        for a in [A2, np.array([5.0, 3.0]), np.array([4.0, 2.5])]:
            b = (1 + eps) * a
            axis = np.array([[1.0, 0, 0]])
            num_exact = ray_extent(lambda X, b=b, a=a: containment_margin(a, b, X), axis)[0]
            num_first = ray_extent(lambda X, b=b, a=a: first_order_margin(a, b, X), axis)[0]
            rows.append(
                [
                    a.tolist(),
                    eps,
                    exact_extreme_rotation(a, eps),
                    num_exact,
                    first_order_extreme_rotation(a, eps),
                    num_first,
                ]
            )
    write_csv(
        out / "eq38_extreme_rotation.csv",
        [
            "semi_axes",
            "inflation",
            "closed_form_exact",
            "numerical_exact",
            "closed_form_first_order",
            "numerical_first_order",
        ],
        rows,
    )
    err_e = max(abs(r[2] - r[3]) for r in rows)
    err_f = max(abs(r[4] - r[5]) for r in rows)
    log(f"eq. 38: closed forms vs numerical: exact {err_e:.2e}, first order {err_f:.2e}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, type=Path, help="output folder")
    parser.add_argument("--quick", action="store_true", help="fewer sweep points")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--samples", type=int, default=10_000, help="random configurations of table 1"
    )
    parser.add_argument(
        "--points",
        type=int,
        help="points of every sweep and per axis of the aspect grid (overrides --quick)",
    )
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    k = 4 if args.quick else 10
    k3, grid = (4, 3) if args.quick else (7, 4)
    if args.points is not None:
        k = k3 = grid = args.points
    table1(args.out, args.samples, rng)
    extreme_rotation_table(args.out)
    eps2 = np.linspace(0.02, 0.2, k)
    sweep(
        args.out,
        "fig7_volumes_2d_inflation",
        "inflation eps",
        eps2,
        [(A2, e) for e in eps2],
        "2D, a = [5, 3.5] (paper Fig. 7)",
    )
    ratios = np.linspace(1.1, 1.5, k)
    sweep(
        args.out,
        "fig8_volumes_2d_aspect",
        "aspect a1 / a2",
        ratios,
        [(np.array([5.0, 5.0 / r]), 0.08) for r in ratios],
        "2D, a1 = 5, eps = 0.08 (Fig. 8)",
    )
    eps3 = np.linspace(0.01, 0.2, k3)
    sweep(
        args.out,
        "fig9_volumes_3d_inflation",
        "inflation eps",
        eps3,
        [(A3, e) for e in eps3],
        "3D, a = [4, 2.5, 2] (paper Fig. 9)",
    )
    aspect_grid(args.out, np.linspace(1.0, 1.2, grid))
    return 0


if __name__ == "__main__":
    sys.exit(main())
