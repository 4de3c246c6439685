"""Matplotlib figures of KC bounds. Files are written atomically (temporary file, then rename)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402
from scipy.spatial import ConvexHull  # noqa: E402

from kcplan.kc.convex import ConvexLowerBound  # noqa: E402

__all__ = ["save_figure", "plot_convex_bound"]


def save_figure(fig: plt.Figure, path: str | os.PathLike, dpi: int = 120) -> None:
    """Save ``fig`` to ``path`` atomically (no half-written file on failure) and close it."""
    target = Path(path)
    suffix = target.suffix or ".png"
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=suffix, dir=target.parent or ".")
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=dpi, bbox_inches="tight")
        os.replace(tmp, target)
    finally:
        plt.close(fig)
        if os.path.exists(tmp):
            os.unlink(tmp)


def _hull_faces(ax, points: np.ndarray, color: str, alpha: float = 0.25) -> None:
    hull = ConvexHull(points)
    faces = [points[s] for s in hull.simplices]
    ax.add_collection3d(
        Poly3DCollection(faces, facecolor=color, edgecolor="k", linewidths=0.2, alpha=alpha)
    )
    ax.scatter(*points[hull.vertices].T, color="k", s=6)
    lo, hi = points.min(0), points.max(0)
    pad = 0.05 * (hi - lo)
    ax.set_xlim(lo[0] - pad[0], hi[0] + pad[0])
    ax.set_ylim(lo[1] - pad[1], hi[1] + pad[1])
    ax.set_zlim(lo[2] - pad[2], hi[2] + pad[2])


def plot_convex_bound(bound: ConvexLowerBound, path: str | os.PathLike) -> None:
    """Draw the convex lower bound: in 2D the polytope in (x, y, theta) as in the paper's
    Fig. 4a; in 3D its projections onto the rotation and the translation coordinates."""
    a = bound.a
    title = f"convex lower bound, a = {a.tolist()}, eps = {bound.inflation:g}"
    if bound.n == 2:
        fig = plt.figure(figsize=(6, 5))
        ax = fig.add_subplot(projection="3d")
        V = bound.vertices[:, [1, 2, 0]]
        _hull_faces(ax, V, "tab:blue")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.set_zlabel("theta [rad]")
        ax.set_title(f"{title}\n{bound.n_vertices} vertices, {len(bound.halfspaces[1])} facets")
    else:
        fig = plt.figure(figsize=(11, 5))
        for i, (cols, labels, color) in enumerate(
            [
                ([0, 1, 2], ("w1 [rad]", "w2 [rad]", "w3 [rad]"), "tab:orange"),
                ([3, 4, 5], ("x", "y", "z"), "tab:blue"),
            ]
        ):
            ax = fig.add_subplot(1, 2, i + 1, projection="3d")
            _hull_faces(ax, bound.vertices[:, cols], color)
            ax.set_xlabel(labels[0])
            ax.set_ylabel(labels[1])
            ax.set_zlabel(labels[2])
            ax.set_title(["rotation projection", "translation projection"][i])
        fig.suptitle(f"{title}: {bound.n_vertices} vertices, {len(bound.halfspaces[1])} facets")
    save_figure(fig, path)
