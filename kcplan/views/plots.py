"""Matplotlib figures: KC bounds, scenarios and paths.

Files are written atomically (temporary file, then rename)."""

from __future__ import annotations

import os
import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402
from scipy.spatial import ConvexHull  # noqa: E402

from kcplan.files import atomic_output  # noqa: E402
from kcplan.geometry.pose import Edge, pose_frame  # noqa: E402
from kcplan.geometry.robot import Robot  # noqa: E402
from kcplan.kc.convex import ConvexLowerBound  # noqa: E402
from kcplan.scenarios import as_scenario  # noqa: E402
from kcplan.world.scenario import Scenario

__all__ = [
    "save_figure",
    "plot_convex_bound",
    "plot_scenario",
    "draw_scenario",
    "draw_clouds",
    "path_poses",
    "plot_path",
    "body_shapes",
    "ellipse_outline",
    "ellipsoid_surface",
    "scenario_axes",
    "plot_cover",
    "part_at",
]


def save_figure(fig: plt.Figure, path: str | os.PathLike, dpi: int = 120) -> None:
    """Save ``fig`` to ``path`` atomically (no half-written file on failure) and close it."""
    try:
        with atomic_output(path) as tmp:
            fig.savefig(tmp, dpi=dpi, bbox_inches="tight", format=Path(path).suffix[1:] or "png")
    finally:
        plt.close(fig)


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


_OBSTACLE_STYLE = {"facecolor": "0.55", "edgecolor": "0.25", "linewidth": 0.6}


def ellipse_outline(center, R, axes, k: int = 72) -> np.ndarray:
    """``k`` points ``(k, 2)`` on the ellipse with centre, rotation ``R`` and semi-axes."""
    t = np.linspace(0.0, 2.0 * np.pi, k)
    return center + (np.column_stack([np.cos(t), np.sin(t)]) * axes) @ R.T


def ellipsoid_surface(center, R, axes, k: int = 16):
    """Grid ``(X, Y, Z)``, each ``(k, 2k)``, of the ellipsoid's surface (for plot_surface)."""
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 2 * k), np.linspace(0, np.pi, k))
    unit = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], axis=-1)
    pts = center + (unit * axes) @ R.T
    return pts[..., 0], pts[..., 1], pts[..., 2]


def _box_faces(center, R, half) -> list[np.ndarray]:
    s = np.array(
        [
            [-1, -1, -1],
            [1, -1, -1],
            [1, 1, -1],
            [-1, 1, -1],
            [-1, -1, 1],
            [1, -1, 1],
            [1, 1, 1],
            [-1, 1, 1],
        ]
    )
    V = center + (s * half) @ R.T
    quads = [[0, 1, 2, 3], [4, 5, 6, 7], [0, 1, 5, 4], [2, 3, 7, 6], [1, 2, 6, 5], [0, 3, 7, 4]]
    return [V[q] for q in quads]


def body_shapes(robot: Robot, pose, inflation: float = 0.0):
    """``(R, t, semi_axes)`` of every body of ``robot`` at ``pose``, each scaled by
    ``1 + inflation`` about its own centre."""
    n = robot.dimension
    for body, body_pose in zip(robot.bodies, robot.body_poses(pose), strict=True):
        R, t = pose_frame(body_pose, n)
        yield R, t, (1.0 + inflation) * body.semi_axes


def part_at(part, pose) -> np.ndarray:
    """A mesh robot's part (:class:`kcplan.cover.Solid`) at a robot pose, in the world:
    its polygon ``(k, 2)`` (2D) or its triangles ``(m, 3, 3)`` (3D)."""
    n = part.dimension
    R, t = pose_frame(np.asarray(pose, dtype=float), n)
    placed = part.vertices @ R.T + t
    return placed if n == 2 else placed[part.faces]


def draw_clouds(ax, obstacles, legend: bool = True) -> list:
    """Draw the sensed obstacles (``pointcloud``, ``depth``) among ``obstacles`` on 3D
    axes: each cloud's points thinned for display
    (:func:`kcplan.views.clouds.cloud_points_for_display`) as small dots coloured by
    height (one colour scale for all clouds), and a depth camera's pose as a triad (x
    red, y green, z = optical axis blue).

    Parameters
    ----------
    ax : Axes3D
    obstacles : sequence of kcplan.world.obstacles.Obstacle
    legend : bool
        Add a legend naming each cloud and how many of its points are drawn.

    Returns
    -------
    list
        The scatter artists, one per cloud.
    """
    from kcplan.views.clouds import (
        CLOUD_COLORMAP,
        cloud_points_for_display,
        clouds_of,
        drawn_extent,
        sensor_triad,
    )

    clouds = clouds_of(obstacles)
    if not clouds:
        return []
    low, high = drawn_extent(clouds, sensors=False)[:, 2]
    artists = []
    for ob in clouds:
        points, label = cloud_points_for_display(ob)
        size = float(np.clip(2000.0 / max(len(points), 1), 1.0, 12.0))  # points^2
        artists.append(
            ax.scatter(*points.T, c=points[:, 2], cmap=CLOUD_COLORMAP, vmin=low,
                       vmax=high if high > low else low + 1.0, s=size, marker="o",
                       linewidths=0, depthshade=False, label=label)
        )  # fmt: skip
        triad = sensor_triad(ob)
        if triad is not None:
            for segment, colour in zip(*triad, strict=True):
                ax.plot(*segment.T, color=colour, lw=1.5)
    if legend:
        shown = ax.legend(handles=artists, loc="upper left", fontsize=7)
        for handle in shown.legend_handles:  # one size and a mid-height colour for every cloud
            handle.set_sizes([16.0])
            handle.set_array(None)
            handle.set_facecolor(plt.get_cmap(CLOUD_COLORMAP)(0.5))
    return artists


def draw_scenario(ax, scenario: Scenario, poses=(), guards: float | None = None) -> None:
    """Draw a scenario's obstacles, bounds, start and goal robots on ``ax``.

    Parameters
    ----------
    ax : matplotlib Axes (2D) or Axes3D (3D)
    scenario : Scenario
    poses : sequence of pose vectors, optional
        Extra robot poses to draw (e.g. along a path), in the flat pose layout.
    guards : float, optional
        Also outline the guard ``(1 + guards) a`` of every body at start and goal.

    A mesh robot (``robot.mesh``) is drawn as its part inside its see-through cover; a
    sensed obstacle as its points (:func:`draw_clouds`), the axes grown to show them all.
    """
    n, robot, part = scenario.dimension, scenario.robot, scenario.part
    cover_alpha = 0.5 if part is None else 0.2
    low, high = scenario.bounds
    if n == 2:
        from matplotlib.patches import Polygon, Rectangle

        ax.add_patch(Rectangle(low, *(high - low), fill=False, ls="--", ec="0.4", lw=0.8))
        for ob in scenario.obstacles:
            if ob.kind in ("box", "polygon"):
                for piece in ob.pieces:
                    ax.add_patch(Polygon(piece, closed=True, **{**_OBSTACLE_STYLE, "linewidth": 0}))
                outline = (
                    ob.pieces[0]
                    if ob.kind == "box"
                    else np.asarray([[float(x) for x in v] for v in ob.spec["vertices"]])
                )
                ax.add_patch(Polygon(outline, closed=True, fill=False, ec="0.25", lw=0.6))
            else:
                ax.add_patch(
                    Polygon(
                        ellipse_outline(ob.center, ob.rotation, ob.extents),
                        closed=True,
                        **_OBSTACLE_STYLE,
                    )
                )
        for pose in poses:
            for R, t, a in body_shapes(robot, pose):
                ax.plot(*ellipse_outline(t, R, a).T, color="tab:blue", lw=0.6, alpha=0.6)
            if part is not None:
                ax.add_patch(Polygon(part_at(part, pose), closed=True, fc="tab:blue", alpha=0.3))
        for pose, color, label in (
            (scenario.start, "tab:green", "start"),
            (scenario.goal, "tab:red", "goal"),
        ):
            if part is not None:
                ax.add_patch(Polygon(part_at(part, pose), closed=True, fc=color, ec="k", lw=0.5))
            for k, (R, t, a) in enumerate(body_shapes(robot, pose)):
                ax.add_patch(
                    Polygon(
                        ellipse_outline(t, R, a),
                        closed=True,
                        fc=color,
                        alpha=cover_alpha,
                        ec=color,
                        label=label if k == 0 else None,
                    )
                )
                if guards:
                    outline = ellipse_outline(t, R, (1 + guards) * a)
                    ax.plot(*outline.T, color=color, ls=":", lw=0.8)
            R, t = pose_frame(pose, 2)  # the robot's heading, from its origin
            ax.plot(*np.array([t, t + R[:, 0] * robot.reach]).T, color="k", lw=0.8)
        pad = 0.03 * (high - low).max()
        ax.set_xlim(low[0] - pad, high[0] + pad)
        ax.set_ylim(low[1] - pad, high[1] + pad)
        ax.set_aspect("equal")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        return
    from kcplan.views.clouds import drawn_extent, is_cloud

    faces, colors = [], []
    for ob in scenario.obstacles:
        if is_cloud(ob):
            continue  # draw_clouds
        if ob.kind == "box":
            faces += _box_faces(ob.center, ob.rotation, ob.extents)
            colors += ["0.6"] * 6
        elif ob.kind in ("mesh", "convex"):
            faces += list(ob.vertices[ob.triangles])
            colors += ["tab:brown"] * len(ob.triangles)
        else:
            ax.plot_surface(
                *ellipsoid_surface(ob.center, ob.rotation, ob.extents),
                color="0.6",
                alpha=0.5,
                linewidth=0,
            )
    if faces:
        ax.add_collection3d(
            Poly3DCollection(faces, facecolors=colors, edgecolors="0.3", linewidths=0.2, alpha=0.35)
        )
    for pose in poses:
        for R, t, a in body_shapes(robot, pose):
            surface = ellipsoid_surface(t, R, a, 8)
            ax.plot_wireframe(*surface, color="tab:blue", lw=0.3, alpha=0.5)
    for pose, color in ((scenario.start, "tab:green"), (scenario.goal, "tab:red")):
        if part is not None:
            ax.add_collection3d(Poly3DCollection(part_at(part, pose), facecolors=color,
                                                 edgecolors="k", linewidths=0.1))  # fmt: skip
        for R, t, a in body_shapes(robot, pose):
            ax.plot_surface(
                *ellipsoid_surface(t, R, a),
                color=color,
                alpha=0.8 if part is None else cover_alpha,
                linewidth=0,
            )
    draw_clouds(ax, scenario.obstacles)
    corners = np.array(np.meshgrid(*zip(low, high, strict=True), indexing="ij")).reshape(3, -1).T
    for i in range(8):
        for j in range(i + 1, 8):
            if np.count_nonzero(corners[i] != corners[j]) == 1:
                ax.plot(*corners[[i, j]].T, color="0.5", ls="--", lw=0.5)
    extent = drawn_extent(scenario.obstacles)
    if extent is not None:  # the bounds are the robot origin's: a cloud may reach past them
        low, high = np.minimum(low, extent[0]), np.maximum(high, extent[1])
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_zlim(low[2], high[2])
    ax.set_box_aspect(high - low)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")


def scenario_axes(scenario: Scenario):
    """A figure sized to the map: a 2D top view, or 3D axes."""
    if scenario.dimension == 2:
        low, high = scenario.bounds
        w, h = high - low
        fig, ax = plt.subplots(figsize=(8, max(3.0, 8 * h / w) + 0.6))
    else:
        fig = plt.figure(figsize=(8, 7))
        ax = fig.add_subplot(projection="3d")
    return fig, ax


def plot_scenario(
    scenario: Scenario | str | os.PathLike,
    path: str | os.PathLike,
    poses=(),
    title: str | None = None,
    guards: float | None = None,
) -> None:
    """Draw a scenario (or the scenario file at a path; 2D top view or 3D perspective)
    into an image file; an arm at its start and goal (:func:`plot_arm`)."""
    scenario = as_scenario(scenario)
    if getattr(scenario, "arm", None) is not None:
        plot_arm(scenario, path, title=title)
        return
    fig, ax = scenario_axes(scenario)
    draw_scenario(ax, scenario, poses, guards)
    heading = f"{scenario.name}: {scenario.description}" if scenario.description else scenario.name
    ax.set_title(title or "\n".join(textwrap.wrap(heading, 100)), fontsize=9)
    save_figure(fig, path)


def path_poses(states, n: int, count: int = 40) -> np.ndarray:
    """About ``count`` poses spread along a path by arc length of the translation, with
    OMPL's interpolation between waypoints (waypoints included)."""
    P = np.asarray(states, dtype=float)
    if len(P) < 2:
        return P
    lengths = np.linalg.norm(np.diff(P[:, :n], axis=0), axis=1)
    total = max(lengths.sum(), 1e-12)
    out = [P[0]]
    for k, length in enumerate(lengths):
        edge = Edge(P[k], P[k + 1], n)
        steps = max(1, int(np.ceil(count * length / total)))
        out += [edge.pose(i / steps) for i in range(1, steps + 1)]
    return np.array(out)


def plot_path(
    scenario: Scenario | str | os.PathLike,
    states,
    path: str | os.PathLike,
    guards=None,
    title: str | None = None,
) -> None:
    """Draw a scenario with a path: its centre line, the robot at intervals along it and,
    if given, guards as ``(pose, inflation)`` pairs (dashed); ``scenario`` may be the
    path of a scenario file. An arm is drawn by :func:`plot_arm` (no guards)."""
    scenario = as_scenario(scenario)
    if getattr(scenario, "arm", None) is not None:
        if guards:
            raise ValueError("guards: expected none for an arm (its edges are certified per link)")
        plot_arm(scenario, path, states if len(states) else None, title=title)
        return
    n = scenario.dimension
    poses = path_poses(states, n) if len(states) else []
    fig, ax = scenario_axes(scenario)
    draw_scenario(ax, scenario, poses)
    if len(states):
        P = np.asarray(states)
        ax.plot(*P[:, :n].T, color="tab:blue", lw=1.2, marker="o", ms=3)
    for pose, eps in guards or []:
        for R, t, a in body_shapes(scenario.robot, pose, eps):
            if n == 2:
                ax.plot(*ellipse_outline(t, R, a).T, color="tab:orange", ls="--", lw=0.6)
            else:
                surface = ellipsoid_surface(t, R, a, 6)
                ax.plot_wireframe(*surface, color="tab:orange", lw=0.3, alpha=0.5)
    extra = f", {len(guards)} guards (dashed)" if guards else ""
    ax.set_title((title or scenario.name) + extra, fontsize=9)
    save_figure(fig, path)


COVER_COLOURS = plt.get_cmap("tab10").colors


def plot_cover(cover, path: str | os.PathLike, tightness: str = "") -> None:
    """Draw a part and its cover (:class:`kcplan.cover.Cover`): the polygon and its
    ellipses (2D), or the mesh and its ellipsoids from two viewpoints (3D)."""
    solid, robot = cover.solid, cover.robot
    identity = np.zeros(3) if solid.dimension == 2 else np.array([0, 0, 0, 0, 0, 0, 1.0])
    shapes = list(body_shapes(robot, identity))
    title = f"{solid.describe()}: {len(robot)} {cover.shape}s" + (
        f", {tightness}" if tightness else ""
    )
    if solid.dimension == 2:
        fig, ax = plt.subplots(figsize=(7, 6))
        ax.fill(*solid.vertices.T, color="0.6", alpha=0.8, lw=0.8, ec="k", label="part")
        for k, (R, t, a) in enumerate(shapes):
            outline = ellipse_outline(t, R, a)
            colour = COVER_COLOURS[k % len(COVER_COLOURS)]
            ax.fill(*outline.T, color=colour, alpha=0.15)
            ax.plot(*outline.T, color=colour, lw=1.2)
        ax.set_aspect("equal")
        ax.set_title(title, fontsize=9)
        save_figure(fig, path)
        return
    fig = plt.figure(figsize=(12, 6))
    corners = solid.vertices[solid.faces]
    from kcplan.cover.bodies import body_bounds

    low, high = solid.vertices.min(axis=0), solid.vertices.max(axis=0)
    for body in robot.bodies:  # the bodies stick out of the part
        box_low, box_high = body_bounds(body)
        low, high = np.minimum(low, box_low), np.maximum(high, box_high)
    for i, (elev, azim) in enumerate(((25, -60), (85, -90))):
        ax = fig.add_subplot(1, 2, i + 1, projection="3d")
        ax.add_collection3d(
            Poly3DCollection(corners, facecolor="0.55", edgecolor="0.3", linewidths=0.1)
        )
        for k, (R, t, a) in enumerate(shapes):
            colour = COVER_COLOURS[k % len(COVER_COLOURS)]
            ax.plot_wireframe(*ellipsoid_surface(t, R, a, 12), color=colour, lw=0.5, alpha=0.6)
        ax.set_xlim(low[0], high[0])
        ax.set_ylim(low[1], high[1])
        ax.set_zlim(low[2], high[2])
        ax.set_box_aspect(high - low)
        ax.view_init(elev, azim)
        ax.tick_params(labelsize=6)
        for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
            axis.set_major_locator(plt.MaxNLocator(3))
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.set_zlabel("z")
    fig.suptitle(title, fontsize=10)
    save_figure(fig, path)


# --- arms -------------------------------------------------------------------------------

_START_RGB, _GOAL_RGB, _PATH_RGB = (0.17, 0.63, 0.17), (0.84, 0.15, 0.16), (0.12, 0.47, 0.71)


def arm_view_angles(scenario) -> tuple[float, float]:
    """``(elev, azim)`` in degrees of a side view of an arm's scene: looking across the
    line from the arm's base (the world origin) to the middle of the obstacles, so that
    the arm reaching into them is seen from its side."""
    from kcplan.views.clouds import obstacle_centre

    centres = [obstacle_centre(ob)[:2] for ob in scenario.obstacles]
    towards = np.mean(centres, axis=0) if centres else np.array([1.0, 0.0])
    heading = float(np.degrees(np.arctan2(towards[1], towards[0])))
    return 20.0, heading - 70.0


def _obstacle_layer(scenario) -> tuple[np.ndarray, np.ndarray]:
    """Every obstacle's triangles ``(m, 3, 3)`` and their RGBA, see-through grey (not the
    clouds': :func:`draw_clouds`)."""
    from kcplan.views.arm import obstacle_mesh
    from kcplan.views.clouds import is_cloud

    solids = [ob for ob in scenario.obstacles if not is_cloud(ob)]
    corners = [V[F] for V, F in (obstacle_mesh(ob) for ob in solids)]
    if not corners:
        return np.zeros((0, 3, 3)), np.zeros((0, 4))
    corners = np.concatenate(corners)
    return corners, np.tile([0.55, 0.55, 0.55, 0.22], (len(corners), 1))


def _arm_layer(meshes, frames, rgb=None, alpha: float = 1.0):
    """The arm's triangles at one state's joint frames, coloured ``rgb`` (default: each
    mesh's own colours), with opacity ``alpha``."""
    from kcplan.views.arm import posed_triangles

    corners, colors = posed_triangles(meshes, frames)
    if rgb is not None:
        colors = np.tile(rgb, (len(corners), 1))
    return corners, np.column_stack([colors, np.full(len(corners), alpha)])


def _draw_layers(ax, layers) -> Poly3DCollection:
    """One shaded collection of all the layers' triangles: one collection, so that
    matplotlib orders the obstacles' and the arm's triangles by depth together."""
    from matplotlib.colors import LightSource

    corners = np.concatenate([c for c, _ in layers])
    colors = np.concatenate([k for _, k in layers])
    collection = Poly3DCollection(
        corners, facecolors=colors, linewidths=0, antialiased=False, shade=True,
        lightsource=LightSource(azdeg=225, altdeg=45),
    )  # fmt: skip
    ax.add_collection3d(collection)
    return collection


def _arm_limits(ax, points: np.ndarray, obstacles=()) -> None:
    """Axis limits around ``points`` ``(k, 3)`` and the points of the clouds among
    ``obstacles``, with equal scales on the three axes."""
    from kcplan.views.clouds import drawn_extent

    extent = drawn_extent(obstacles)
    if extent is not None:
        points = np.vstack([points.reshape(-1, 3), extent])
    low, high = points.min(axis=0), points.max(axis=0)
    pad = 0.03 * float((high - low).max())
    low, high = low - pad, high + pad
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_zlim(low[2], high[2])
    ax.set_box_aspect(high - low)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.tick_params(labelsize=6)


def plot_arm(
    scenario,
    path: str | os.PathLike,
    states=None,
    title: str | None = None,
    poses: int = 3,
    show_cover: bool = False,
    meshes: str = "auto",
    max_faces: int = 600,
    dpi: int = 90,
) -> str:
    """Draw an arm's scene: the obstacles (a cloud as its points, :func:`draw_clouds`),
    the arm at its start (green) and goal (red), and with a path ``states`` about
    ``poses`` arms along it (blue, see-through) and the tip joint's path, from two
    viewpoints (a side view and from above).

    Parameters
    ----------
    scenario : kcplan.arm.scenario.ArmScenario or path-like
    path : path-like
        The image file, written atomically.
    states : array_like, shape (k, dof), optional
    poses : int
        Intermediate arms along the path (spread by joint-space length).
    show_cover : bool
        Also draw the covering ellipsoids at the start and the goal (see-through).
    meshes : {"auto", "visual", "collision"}
        :func:`kcplan.views.arm.arm_meshes`.
    max_faces : int
        Triangles per link mesh at most.
    dpi : int
        Resolution (90: about 1080 x 540 pixels).

    Returns
    -------
    str
        Which meshes draw the links.
    """
    from kcplan.views.arm import arm_meshes, joint_frames_along, joint_path, tip_joint

    scenario = as_scenario(scenario)
    arm = scenario.arm
    links, source = arm_meshes(arm, meshes, max_faces)
    ends = joint_frames_along(arm, [scenario.start, scenario.goal])
    fixed = [m for m in links if m.joint == 0]  # drawn once: they never move
    links = [m for m in links if m.joint != 0] or links
    layers = [_obstacle_layer(scenario)] + ([_arm_layer(fixed, ends[0])] if fixed else [])
    layers += [
        _arm_layer(links, ends[0], _START_RGB, 0.9),
        _arm_layer(links, ends[1], _GOAL_RGB, 0.9),
    ]
    tip_path = None
    if states is not None and len(states) > 1:
        dense = joint_path(arm.continuous(states), 200)
        along = joint_frames_along(arm, dense)
        tip_path = along[:, tip_joint(arm), :3, 3]
        lengths = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(dense, axis=0), axis=1))]
        for s in np.linspace(0.0, lengths[-1], poses + 2)[1:-1]:
            k = int(np.argmin(np.abs(lengths - s)))
            layers.append(_arm_layer(links, along[k], _PATH_RGB, 0.25))
    if show_cover:  # see-through, in the same collection: ordered by depth with the links
        from kcplan.views.arm import cover_meshes

        cover = cover_meshes(arm, 1)
        layers += [_arm_layer(cover, ends[0], _START_RGB, 0.2),
                   _arm_layer(cover, ends[1], _GOAL_RGB, 0.2)]  # fmt: skip
    points = np.concatenate([c.reshape(-1, 3) for c, _ in layers])
    fig = plt.figure(figsize=(12, 6))
    elev, azim = arm_view_angles(scenario)
    for i, (e, a) in enumerate(((elev, azim), (65.0, azim + 40.0))):
        ax = fig.add_subplot(1, 2, i + 1, projection="3d")
        _draw_layers(ax, layers)
        draw_clouds(ax, scenario.obstacles, legend=i == 0)
        if tip_path is not None:
            ax.plot(*tip_path.T, color="tab:blue", lw=1.0)
        _arm_limits(ax, points, scenario.obstacles)
        ax.view_init(e, a)
    heading = title or scenario.name
    fig.suptitle(f"{heading}\nstart (green), goal (red); links: {source.split(' (')[0]}",
                 fontsize=10)  # fmt: skip
    fig.subplots_adjust(left=0.0, right=1.0, bottom=0.02, top=0.9, wspace=0.0)
    save_figure(fig, path, dpi=dpi)
    return source


def plot_joint_velocities(trajectory, path: str | os.PathLike, rate: float = 1000.0) -> None:
    """Plot a timed trajectory's velocities and accelerations against their limits (one
    panel each, the limits dashed), sampled at ``rate`` per second: an arm's joints, or a
    rigid robot's translational and angular speed and acceleration (their sizes).

    Parameters
    ----------
    trajectory : kcplan.trajectory.certified.CertifiedTrajectory or RigidTimedPath
    path : path-like
        The ``.png`` file, written atomically.
    rate : float
        Samples per second drawn.
    """
    timed = trajectory.timed
    t, _, _, qd, qdd = timed.sample(rate)
    if getattr(timed, "dimension", None) is not None:  # rigid: sizes of linear and angular
        n = timed.dimension
        qd = np.column_stack([np.linalg.norm(qd[:, :n], axis=1), np.linalg.norm(qd[:, n:], axis=1)])
        qdd = np.column_stack(
            [np.linalg.norm(qdd[:, :n], axis=1), np.linalg.norm(qdd[:, n:], axis=1)]
        )
        names, units = ("translational", "angular"), ("speed", "acceleration")
    else:
        names, units = trajectory.joints, ("velocity (rad/s)", "acceleration (rad/s²)")
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    colours = plt.get_cmap("tab10")
    for ax, values, limits, unit in (
        (axes[0], qd, timed.velocity_limits, units[0]),
        (axes[1], qdd, timed.acceleration_limits, units[1]),
    ):
        for j, name in enumerate(names):
            colour = colours(j % 10)
            ax.plot(t, values[:, j], color=colour, lw=1.0, label=name)
            ax.axhline(limits[j], color=colour, lw=0.6, ls="--")
            ax.axhline(-limits[j], color=colour, lw=0.6, ls="--")
        ax.set_ylabel(unit)
        ax.grid(alpha=0.3)
    rv, ra = timed.peak_ratios()
    axes[0].set_title(
        f"{timed.duration:.2f} s ({trajectory.stop_duration:.2f} s stopping at every corner); "
        f"peaks {rv:.3f} and {ra:.3f} of the limits (dashed)",
        fontsize=9,
    )
    axes[1].set_xlabel("time (s)")
    axes[0].legend(fontsize=7, ncol=4, loc="upper right")
    fig.tight_layout()
    try:
        with atomic_output(path) as tmp:
            fig.savefig(tmp, dpi=90, format="png")
    finally:
        plt.close(fig)
