"""Animated GIFs of a robot moving along a path (2D top view or 3D perspective)."""

from __future__ import annotations

import os

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter

from kcplan.files import atomic_output
from kcplan.viz import (  # viz selects matplotlib's non-interactive backend
    body_shapes,
    draw_scenario,
    ellipse_outline,
    ellipsoid_surface,
    path_poses,
    scenario_axes,
)
from kcplan.world.scenario import Scenario, as_scenario

__all__ = ["animate_path"]


def animate_path(
    scenario: Scenario | str | os.PathLike,
    states,
    path: str | os.PathLike,
    frames: int = 60,
    fps: int = 12,
    dpi: int = 72,
    title: str | None = None,
) -> int:
    """Write a GIF of every body of the robot moving along ``states``.

    Parameters
    ----------
    scenario : Scenario or path-like
        The scene, or the path of its scenario file.
    states : array_like, shape (k, 3 or 7)
        The path's flat poses, interpolated between waypoints as OMPL does.
    path : path-like
        The ``.gif`` file, written atomically (a temporary file, then a rename).
    frames : int
        About this many frames, spread by the translation's arc length.
    fps, dpi : int
        Frame rate and resolution (60 frames at 72 dpi are well under 1 MB in 2D).

    Returns
    -------
    int
        The number of frames written.
    """
    scenario = as_scenario(scenario, rigid=True)
    n = scenario.dimension
    poses = path_poses(states, n, max(frames - 1, 1))
    fig, ax = scenario_axes(scenario)
    draw_scenario(ax, scenario)
    P = np.asarray(states, dtype=float)
    ax.plot(*P[:, :n].T, color="tab:blue", lw=1.0, alpha=0.6)
    ax.set_title(title or scenario.name, fontsize=9)
    moving: list = []

    def show(i: int) -> list:
        for artist in moving:
            artist.remove()
        moving.clear()
        for R, t, a in body_shapes(scenario.robot, poses[i]):
            if n == 2:
                moving.extend(ax.fill(*ellipse_outline(t, R, a).T, color="tab:blue", alpha=0.8))
            else:
                surface = ellipsoid_surface(t, R, a, 10)
                moving.append(ax.plot_surface(*surface, color="tab:blue", alpha=0.9, lw=0))
        return moving

    animation = FuncAnimation(fig, show, frames=len(poses), blit=False)
    try:
        with atomic_output(path) as tmp:
            animation.save(tmp, writer=PillowWriter(fps=fps), dpi=dpi)
    finally:
        plt.close(fig)
    return len(poses)
