"""An interactive 3D view of a scenario and a path, as one self-contained HTML file.

Built with plotly (its offline HTML export embeds plotly.js, so the file works without a
network): obstacles, the start (green) and goal (red) robots, the path, and the robot
moving along it with a play button and a slider. 2D scenes are drawn flat in the plane
z = 0. plotly rather than MeshCat: plotly is released every few weeks and writes a
static file; MeshCat's Python package is rarely released and serves its viewer from a
running server.
"""

from __future__ import annotations

import os

import numpy as np
import plotly.graph_objects as go

from kcplan.files import write_text_atomic
from kcplan.geometry.pose import pose_frame
from kcplan.maps.superquadric import unit_normals
from kcplan.viz import body_shapes, ellipse_outline, path_poses
from kcplan.world.mesh import convex_hull
from kcplan.world.scenario import Obstacle, Scenario, as_scenario
from kcplan.world.support import box_vertices

__all__ = ["cover_figure", "scene_figure", "write_cover_html", "write_scene_html"]

_SPHERE = convex_hull(unit_normals(3, 160))  # unit sphere: vertices and triangles


def _flat(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A convex planar polygon ``(k, 2)`` as a triangle fan at z = 0."""
    k = len(points)
    V = np.column_stack([points, np.zeros(k)])
    F = np.array([[0, i, i + 1] for i in range(1, k - 1)])
    return V, F


def _ellipsoid(center, R, axes, n: int) -> tuple[np.ndarray, np.ndarray]:
    if n == 2:
        return _flat(ellipse_outline(center, R, axes, 49)[:-1])  # 48 points, not closed
    V, F = _SPHERE
    return center + (V * axes) @ R.T, F


def _obstacle_meshes(ob: Obstacle, n: int) -> list[tuple[np.ndarray, np.ndarray]]:
    if ob.kind in ("mesh", "convex"):
        return [(ob.vertices, ob.triangles)]
    if n == 2 and ob.kind in ("box", "polygon"):
        return [_flat(piece) for piece in ob.pieces]
    if ob.kind == "box":
        return [convex_hull(box_vertices(ob.center, ob.rotation, ob.extents))]
    return [_ellipsoid(ob.center, ob.rotation, ob.extents, n)]


def _mesh(V: np.ndarray, F: np.ndarray, color: str, opacity: float, name: str) -> go.Mesh3d:
    return go.Mesh3d(
        x=V[:, 0], y=V[:, 1], z=V[:, 2], i=F[:, 0], j=F[:, 1], k=F[:, 2],
        color=color, opacity=opacity, name=name, flatshading=True, hoverinfo="name",
    )  # fmt: skip


def _part_mesh(part) -> tuple[np.ndarray, np.ndarray]:
    """A robot's part (:class:`kcplan.cover.Solid`) as one triangle mesh in its frame
    (2D: its convex pieces fanned at z = 0)."""
    if part.dimension == 3:
        return part.vertices, part.faces
    from kcplan.geometry.polygon import convex_pieces

    meshes = [_flat(piece) for piece in convex_pieces(part.vertices)]
    starts = np.cumsum([0] + [len(V) for V, _ in meshes[:-1]])
    return np.vstack([V for V, _ in meshes]), np.vstack(
        [F + k for (_, F), k in zip(meshes, starts, strict=True)]
    )


def _robot(scenario: Scenario, pose, color: str, name: str) -> list[go.Mesh3d]:
    """The robot's bodies at ``pose``; a mesh robot's part solid inside its see-through
    cover."""
    n = scenario.dimension
    traces = []
    if scenario.part is not None:
        V, F = _part_mesh(scenario.part)
        R, t = pose_frame(np.asarray(pose, dtype=float), n)
        R3, t3 = np.eye(3), np.zeros(3)
        R3[:n, :n], t3[:n] = R, t
        traces.append(_mesh(V @ R3.T + t3, F, color, 1.0, f"{name} (part)"))
    opacity = 0.25 if traces else 0.9
    return traces + [
        _mesh(*_ellipsoid(t, R, a, n), color, opacity, name)
        for R, t, a in body_shapes(scenario.robot, pose)
    ]


def scene_figure(
    scenario: Scenario | str | os.PathLike, states=None, frames: int = 60
) -> go.Figure:
    """The scene (a scenario, or the path of its file; and the path ``states``, shape
    ``(k, 3 or 7)``, with the robot moving along it in about ``frames`` steps) as a
    plotly figure."""
    scenario = as_scenario(scenario, rigid=True)
    n = scenario.dimension
    traces = []
    for ob in scenario.obstacles:
        for V, F in _obstacle_meshes(ob, n):
            traces.append(_mesh(V, F, "#8c8c8c", 0.45 if n == 3 else 0.8, ob.label))
    traces += _robot(scenario, scenario.start, "#2ca02c", "start")
    traces += _robot(scenario, scenario.goal, "#d62728", "goal")
    figure_frames, steps = [], []
    if states is not None and len(states):
        P = np.asarray(states, dtype=float)
        centre = np.column_stack([P[:, :n], np.zeros((len(P), 3 - n))])
        traces.append(
            go.Scatter3d(
                x=centre[:, 0],
                y=centre[:, 1],
                z=centre[:, 2],
                mode="lines+markers",
                line={"color": "#1f77b4", "width": 4},
                marker={"size": 2},
                name="path",
            )  # fmt: skip
        )
        poses = path_poses(P, n, max(frames - 1, 1))
        first = len(traces)
        traces += _robot(scenario, poses[0], "#1f77b4", "robot")
        moving = list(range(first, len(traces)))
        for i, pose in enumerate(poses):
            figure_frames.append(
                go.Frame(
                    data=_robot(scenario, pose, "#1f77b4", "robot"), traces=moving, name=str(i)
                )
            )
            steps.append(
                {"args": [[str(i)], {"frame": {"duration": 0}, "mode": "immediate"}],
                 "label": str(i), "method": "animate"}
            )  # fmt: skip
    figure = go.Figure(data=traces, frames=figure_frames)
    low, high = scenario.bounds
    figure.update_layout(
        title=f"{scenario.name}: {scenario.robot.describe()}"
        + (f" covering {scenario.part.describe()}" if scenario.part is not None else ""),
        scene={"aspectmode": "data", "xaxis_title": "x", "yaxis_title": "y", "zaxis_title": "z"},
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
        showlegend=False,
    )
    if n == 2:  # a flat scene seen from above
        pad = 0.05 * float((high - low).max())
        w, h = (high - low) + 2 * pad
        figure.update_layout(
            scene_aspectmode="manual",
            scene_aspectratio={"x": w / max(w, h), "y": h / max(w, h), "z": 0.05},
            scene_camera={"eye": {"x": 0.0, "y": -0.35, "z": 1.1}},
            scene_xaxis_range=[low[0] - pad, high[0] + pad],
            scene_yaxis_range=[low[1] - pad, high[1] + pad],
            scene_zaxis={"range": [-1.0, 1.0], "visible": False},
        )
    if figure_frames:
        play = {"frame": {"duration": 80, "redraw": True}, "fromcurrent": True}
        figure.update_layout(
            updatemenus=[
                {"type": "buttons", "x": 0.05, "y": 0.05, "buttons": [
                    {"label": "play", "method": "animate", "args": [None, play]},
                ]}
            ],
            sliders=[{"steps": steps, "x": 0.15, "len": 0.8, "y": 0.05}],
        )  # fmt: skip
    return figure


def write_scene_html(
    scenario: Scenario | str | os.PathLike, path: str | os.PathLike, states=None
) -> None:
    """Write :func:`scene_figure` as one self-contained HTML file (plotly.js embedded;
    works offline), atomically."""
    html = scene_figure(scenario, states).to_html(include_plotlyjs=True, full_html=True)
    write_text_atomic(path, html)


def cover_figure(cover) -> go.Figure:
    """A part (:class:`kcplan.cover.Cover`'s solid) and its bodies as a plotly figure."""
    solid, robot = cover.solid, cover.robot
    n = solid.dimension
    if n == 2:
        V = np.column_stack([solid.vertices, np.zeros(len(solid.vertices))])
        from kcplan.geometry.polygon import convex_pieces

        traces = [_mesh(*_flat(p), "#8c8c8c", 0.9, "part") for p in convex_pieces(V[:, :2])]
        identity = np.zeros(3)
    else:
        traces = [_mesh(solid.vertices, solid.faces, "#8c8c8c", 1.0, "part")]
        identity = np.array([0, 0, 0, 0, 0, 0, 1.0])
    palette = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2")
    for k, (R, t, a) in enumerate(body_shapes(robot, identity)):
        traces.append(_mesh(*_ellipsoid(t, R, a, n), palette[k % 7], 0.3, f"body {k}"))
    figure = go.Figure(data=traces)
    figure.update_layout(
        title=f"{solid.describe()}: {len(robot)} {cover.shape}s",
        scene={"aspectmode": "data"},
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
    )
    return figure


def write_cover_html(cover, path: str | os.PathLike) -> None:
    """Write :func:`cover_figure` as one self-contained HTML file, atomically."""
    write_text_atomic(path, cover_figure(cover).to_html(include_plotlyjs=True, full_html=True))
