"""Animated GIFs of a robot moving along a path (2D top view or 3D perspective)."""

from __future__ import annotations

import os

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter

from kcplan.files import atomic_output
from kcplan.scenarios import as_scenario
from kcplan.views.plots import (  # plots selects matplotlib's non-interactive backend
    body_shapes,
    draw_scenario,
    ellipse_outline,
    ellipsoid_surface,
    path_poses,
    scenario_axes,
)
from kcplan.world.scenario import Scenario

__all__ = ["animate_arm", "animate_path"]


def animate_path(
    scenario: Scenario | str | os.PathLike,
    states,
    path: str | os.PathLike,
    frames: int = 60,
    fps: int = 12,
    dpi: int = 72,
    title: str | None = None,
) -> int:
    """Write a GIF of every body of the robot moving along ``states`` (an arm: its links,
    by :func:`animate_arm`, at most 40 frames).

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
    scenario = as_scenario(scenario)
    if getattr(scenario, "arm", None) is not None:
        return animate_arm(scenario, states, path, min(frames, 40), dpi=dpi, title=title)
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


def animate_arm(
    scenario,
    states,
    path: str | os.PathLike,
    frames: int = 40,
    fps: int = 10,
    dpi: int = 72,
    title: str | None = None,
    show_cover: bool = False,
    meshes: str = "auto",
    max_faces: int = 400,
    timed: bool = False,
) -> int:
    """Write a GIF of an arm moving along a path through its scene.

    The links' meshes (:func:`kcplan.views.arm.arm_meshes`, at most ``max_faces``
    triangles each) are posed by Pinocchio's forward kinematics at joint vectors
    interpolated along ``states`` (:func:`kcplan.views.arm.joint_path`); the start (green)
    and goal (red) arms stay see-through in place (their collision meshes, coarser), with
    the tip joint's path; a cloud is drawn as its points
    (:func:`kcplan.views.plots.draw_clouds`). Seen from the side
    (:func:`kcplan.views.plots.arm_view_angles`).

    Parameters
    ----------
    scenario : kcplan.arm.scenario.ArmScenario or path-like
    states : array_like, shape (k, dof)
        The path's joint vectors.
    path : path-like
        The ``.gif`` file, written atomically.
    frames : int
        About this many frames (every waypoint is one).
    fps, dpi : int
        Frame rate and resolution (at 72 dpi a frame is 576 x 504 pixels).
    show_cover : bool
        Draw the covering ellipsoids on the moving arm too.
    meshes : {"auto", "visual", "collision"}
    max_faces : int
    timed : bool
        ``states`` are a trajectory sampled at ``fps`` (one frame each, so that the GIF
        plays in real time), not a path to interpolate.

    Returns
    -------
    int
        The number of frames written.
    """
    from kcplan.views.arm import arm_meshes, cover_meshes, joint_frames_along, joint_path, tip_joint
    from kcplan.views.plots import (
        _arm_layer,
        _arm_limits,
        _draw_layers,
        _obstacle_layer,
        arm_view_angles,
        draw_clouds,
    )

    scenario = as_scenario(scenario)
    arm = scenario.arm
    links, _ = arm_meshes(arm, meshes, max_faces)
    ghosts, _ = arm_meshes(arm, "collision", max(max_faces // 4, 50))  # closed, coarse
    cover = cover_meshes(arm, 1) if show_cover else []
    dense = (np.asarray(states, dtype=float) if timed
             else joint_path(arm.continuous(states), max(frames - 1, 1)))  # fmt: skip
    along = joint_frames_along(arm, dense)
    ends = joint_frames_along(arm, [scenario.start, scenario.goal])
    ghosts = [m for m in ghosts if m.joint != 0]  # the fixed links are drawn moving
    static = [_obstacle_layer(scenario), _arm_layer(ghosts, ends[0], (0.17, 0.63, 0.17), 0.25),
              _arm_layer(ghosts, ends[1], (0.84, 0.15, 0.16), 0.25)]  # fmt: skip
    moving_layers = [
        [_arm_layer(links, F)] + ([_arm_layer(cover, F, None, 0.3)] if cover else []) for F in along
    ]
    points = np.concatenate(
        [c.reshape(-1, 3) for c, _ in static] + [m[0][0].reshape(-1, 3) for m in moving_layers]
    )
    fig = plt.figure(figsize=(8, 7))
    ax = fig.add_subplot(projection="3d")
    _arm_limits(ax, points, scenario.obstacles)
    draw_clouds(ax, scenario.obstacles)  # drawn once: they never move
    ax.view_init(*arm_view_angles(scenario))
    ax.plot(*along[:, tip_joint(arm), :3, 3].T, color="tab:blue", lw=1.0, alpha=0.7)
    ax.set_title(title or scenario.name, fontsize=9)
    fig.subplots_adjust(left=0.0, right=1.0, bottom=0.0, top=0.95)
    moving: list = []

    def show(i: int) -> list:
        for artist in moving:
            artist.remove()
        moving.clear()
        moving.append(_draw_layers(ax, static + moving_layers[i]))
        return moving

    animation = FuncAnimation(fig, show, frames=len(dense), blit=False)
    try:
        with atomic_output(path) as tmp:
            animation.save(tmp, writer=PillowWriter(fps=fps), dpi=dpi)
    finally:
        plt.close(fig)
    return len(dense)
