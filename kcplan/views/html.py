"""An interactive 3D view of a scenario and a path, as one self-contained HTML file.

Built with plotly (its offline HTML export embeds plotly.js, so the file works without a
network): obstacles (a sensed cloud as its points, thinned for display:
:mod:`kcplan.views.clouds`), the start (green) and goal (red) robots, the path, and the
robot moving along it with a play button and a slider. 2D scenes are drawn flat in the
plane z = 0. plotly rather than MeshCat: plotly is released every few weeks and writes a
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
from kcplan.scenarios import as_scenario
from kcplan.views.clouds import (
    CLOUD_COLORMAP,
    cloud_points_for_display,
    clouds_of,
    drawn_extent,
    is_cloud,
    sensor_triad,
)
from kcplan.views.plots import body_shapes, ellipse_outline, path_poses
from kcplan.world.mesh import convex_hull
from kcplan.world.obstacles import Obstacle
from kcplan.world.scenario import Scenario
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
    """The triangle meshes that draw an obstacle; none for a cloud (:func:`_cloud_traces`)."""
    if is_cloud(ob):
        return []
    if ob.kind in ("mesh", "convex"):
        return [(ob.vertices, ob.triangles)]
    if ob.kind == "cylinder":
        from kcplan.views.arm import cylinder_mesh

        return [cylinder_mesh(ob)]
    if n == 2 and ob.kind in ("box", "polygon"):
        return [_flat(piece) for piece in ob.pieces]
    if ob.kind == "box":
        return [convex_hull(box_vertices(ob.center, ob.rotation, ob.extents))]
    return [_ellipsoid(ob.center, ob.rotation, ob.extents, n)]


def _cloud_traces(obstacles) -> tuple[list[go.Scatter3d], list[str]]:
    """The clouds among ``obstacles`` as plotly traces: each one's points thinned for
    display (:func:`kcplan.views.clouds.cloud_points_for_display`), size-2 markers
    coloured by height on one scale for all clouds, named by the label that says how
    many of its points are drawn; a depth camera's pose as three lines (x red, y green,
    z = optical axis blue). Returns the traces and the clouds' labels."""
    clouds = clouds_of(obstacles)
    if not clouds:
        return [], []
    low, high = drawn_extent(clouds, sensors=False)[:, 2]
    traces, labels = [], []
    for ob in clouds:
        points, label = cloud_points_for_display(ob)
        labels.append(label)
        marker = {"size": 2, "color": points[:, 2], "colorscale": CLOUD_COLORMAP.capitalize(),
                  "cmin": low, "cmax": high if high > low else low + 1.0}  # fmt: skip
        if not traces:  # one colour bar: the scale is shared
            marker |= {"showscale": True, "colorbar": {"title": {"text": "z"}, "thickness": 12,
                                                       "len": 0.5}}  # fmt: skip
        traces.append(
            go.Scatter3d(x=points[:, 0], y=points[:, 1], z=points[:, 2], mode="markers",
                         marker=marker, name=label, legendgroup=f"cloud {ob.index}")
        )  # fmt: skip
        triad = sensor_triad(ob)
        if triad is not None:
            for (a, b), rgb, axis in zip(*triad, "xyz", strict=True):
                traces.append(
                    go.Scatter3d(x=[a[0], b[0]], y=[a[1], b[1]], z=[a[2], b[2]], mode="lines",
                                 line={"color": _hex(rgb), "width": 5}, showlegend=False,
                                 name=f"obstacles[{ob.index}]: depth camera {axis} axis",
                                 legendgroup=f"cloud {ob.index}")
                )  # fmt: skip
    return traces, labels


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
    scenario = as_scenario(scenario)
    if getattr(scenario, "arm", None) is not None:
        raise TypeError(
            f"scenario: {scenario.source}: an arm's page is made by write_scene_html or "
            "arm_html (its script poses the meshes), not by scene_figure"
        )
    n = scenario.dimension
    traces = []
    for ob in scenario.obstacles:
        for V, F in _obstacle_meshes(ob, n):
            traces.append(_mesh(V, F, "#8c8c8c", 0.45 if n == 3 else 0.8, ob.label))
    clouds, cloud_labels = _cloud_traces(scenario.obstacles)
    traces += clouds
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
    figure.update_layout(  # the legend is off: a cloud's count goes in the title
        title=f"{scenario.name}: {scenario.robot.describe()}"
        + (f" covering {scenario.part.describe()}" if scenario.part is not None else "")
        + "".join(f"<br><sup>{label}</sup>" for label in cloud_labels),
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
    scenario: Scenario | str | os.PathLike,
    path: str | os.PathLike,
    states=None,
    show_cover: bool = False,
    meshes: str = "auto",
    frame_ms: float | None = None,
) -> str:
    """Write the scene as one self-contained HTML file (plotly.js embedded; works
    offline), atomically.

    A rigid robot's page is :func:`scene_figure`. An arm's page draws its links (the
    URDF's visual meshes when they can all be read, else its collision meshes;
    ``meshes`` chooses) moving along ``states`` (interpolated in joint space), the start
    (green) and goal (red) arms see-through, the tip joint's path, and a play button, a
    frame slider and switches for the arm and its covering ellipsoids (shown at first
    with ``show_cover``). The page poses the meshes itself from the joint frames it holds
    (:func:`arm_view_data`, in the ``<script id="kcplan-arm-data">`` block), so each mesh
    is stored once.

    With ``frame_ms`` (an arm), ``states`` are a trajectory sampled every ``frame_ms``
    milliseconds, one frame each, and the page plays them at that pace: in real time.

    Returns
    -------
    str
        What the page shows of an arm's links (e.g. ``collision meshes``), or ``""``.
    """
    scenario = as_scenario(scenario)
    if getattr(scenario, "arm", None) is not None:
        data = arm_view_data(scenario, states, meshes=meshes, timed=frame_ms is not None)
        data["frame_ms"] = 80 if frame_ms is None else float(frame_ms)
        write_text_atomic(path, arm_html(scenario, data, show_cover))
        return data["source"]
    html = scene_figure(scenario, states).to_html(include_plotlyjs=True, full_html=True)
    write_text_atomic(path, html)
    return ""


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


# --- arms -------------------------------------------------------------------------------

_ARM_DATA_ID = "kcplan-arm-data"

_ARM_CONTROLS = """<div id="kcplan-controls" style="font:13px sans-serif;padding:6px 10px">
<button id="kc-play" type="button">play</button>
<input id="kc-frame" type="range" min="0" max="{last}" value="0" step="1"
 style="width:55%;vertical-align:middle">
<span id="kc-label"></span>
<label style="margin-left:1em"><input id="kc-arm" type="checkbox" checked> arm</label>
<label style="margin-left:1em"><input id="kc-cover" type="checkbox"{cover}>
 bodies (hulls or ellipsoids)</label>
</div>
"""

# The page poses the meshes itself: the data block holds every mesh once, in its own frame,
# with the joint frames of every frame of the animation; a mesh's world frame is
# joint_frames[frame][mesh.joint] @ mesh.placement (both 3 x 4, row-major).
_ARM_SCRIPT = """
(function () {
  var gd = document.getElementById('{plot_id}');
  var D = JSON.parse(document.getElementById('@DATA_ID@').textContent);
  D.cover.forEach(function (c) {  // an ellipsoid: the unit sphere scaled by its semi-axes
    if (c.vertices) return;  // a link's hull: its own vertices and faces
    c.vertices = D.sphere.vertices.map(function (v, i) { return v * c.semi_axes[i % 3]; });
    c.faces = D.sphere.faces;
  });
  function compose(T, P) {
    var M = new Array(12);
    for (var r = 0; r < 3; r++) {
      for (var c = 0; c < 4; c++) {
        var v = T[4 * r] * P[c] + T[4 * r + 1] * P[4 + c] + T[4 * r + 2] * P[8 + c];
        M[4 * r + c] = c === 3 ? v + T[4 * r + 3] : v;
      }
    }
    return M;
  }
  function place(meshes, frames) {
    var x = [], y = [], z = [];
    meshes.forEach(function (m) {
      var M = compose(frames[m.joint], m.placement), V = m.vertices;
      for (var p = 0; p < V.length; p += 3) {
        x.push(M[0] * V[p] + M[1] * V[p + 1] + M[2] * V[p + 2] + M[3]);
        y.push(M[4] * V[p] + M[5] * V[p + 1] + M[6] * V[p + 2] + M[7]);
        z.push(M[8] * V[p] + M[9] * V[p + 1] + M[10] * V[p + 2] + M[11]);
      }
    });
    return [x, y, z];
  }
  function topology(meshes, colour) {
    var i = [], j = [], k = [], fc = [], offset = 0;
    meshes.forEach(function (m) {
      var F = m.faces;
      for (var f = 0; f < F.length; f += 3) {
        i.push(F[f] + offset); j.push(F[f + 1] + offset); k.push(F[f + 2] + offset);
        fc.push(colour || m.palette[m.face_palette ? m.face_palette[f / 3] : 0]);
      }
      offset += m.vertices.length / 3;
    });
    return {i: [i], j: [j], k: [k], facecolor: [fc]};
  }
  function restyle(index, meshes, frames, colour) {
    var update = topology(meshes, colour), xyz = place(meshes, frames);
    update.x = [xyz[0]]; update.y = [xyz[1]]; update.z = [xyz[2]];
    return Plotly.restyle(gd, update, [index]);
  }
  var last = D.joint_frames.length - 1, current = 0, timer = null;
  var slider = document.getElementById('kc-frame'), label = document.getElementById('kc-label');
  var cover = document.getElementById('kc-cover'), arm = document.getElementById('kc-arm');
  function show(k) {
    current = k;
    slider.value = k;
    label.textContent = D.labels[k];
    var frames = D.joint_frames[k], update = {x: [], y: [], z: []}, traces = [];
    [[D.traces.arm, D.meshes, arm.checked], [D.traces.cover, D.cover, cover.checked]].forEach(
      function (group) {
        if (!group[2]) return;
        var xyz = place(group[1], frames);
        update.x.push(xyz[0]); update.y.push(xyz[1]); update.z.push(xyz[2]);
        traces.push(group[0]);
      });
    if (traces.length) Plotly.restyle(gd, update, traces);
  }
  function visibility() {
    Plotly.restyle(gd, {visible: [arm.checked, cover.checked]}, [D.traces.arm, D.traces.cover]);
    show(current);
  }
  var start = D.start_frames, goal = D.goal_frames;
  restyle(D.traces.start, D.meshes, start, '#2ca02c')
    .then(function () { return restyle(D.traces.goal, D.meshes, goal, '#d62728'); })
    .then(function () { return restyle(D.traces.arm, D.meshes, D.joint_frames[0]); })
    .then(function () { return restyle(D.traces.cover, D.cover, D.joint_frames[0]); })
    .then(function () {
      var hash = /frame=(\\d+)/.exec(window.location.hash);
      show(hash ? Math.min(parseInt(hash[1], 10), last) : 0);
    });
  slider.addEventListener('input', function () { show(parseInt(slider.value, 10)); });
  cover.addEventListener('change', visibility);
  arm.addEventListener('change', visibility);
  document.getElementById('kc-play').addEventListener('click', function () {
    var button = this;
    if (timer) { clearInterval(timer); timer = null; button.textContent = 'play'; return; }
    button.textContent = 'pause';
    if (current >= last) show(0);
    timer = setInterval(function () {
      if (current < last) { show(current + 1); return; }
      clearInterval(timer); timer = null; button.textContent = 'play';
    }, D.frame_ms);
  });
})();
""".replace("@DATA_ID@", _ARM_DATA_ID)


def _hex(rgb) -> str:
    r, g, b = (int(round(255 * float(c))) for c in rgb)
    return f"#{r:02x}{g:02x}{b:02x}"


def _mesh_data(mesh) -> dict:
    """One :class:`kcplan.views.arm.LinkMesh` for the page: vertices rounded to 1 µm, faces,
    and its colours as a palette with an index per face (none when it has one colour)."""
    palette, index = np.unique(np.round(mesh.colors, 3), axis=0, return_inverse=True)
    out = {
        "name": mesh.name,
        "link": mesh.link,
        "joint": mesh.joint,
        "placement": mesh.placement[:3].ravel().tolist(),
        "vertices": np.round(mesh.vertices, 6).ravel().tolist(),
        "faces": mesh.faces.ravel().tolist(),
        "palette": [_hex(c) for c in palette],
    }
    if len(palette) > 1:
        out["face_palette"] = index.ravel().tolist()
    return out


def arm_view_data(
    scenario,
    states=None,
    frames: int = 60,
    meshes: str = "auto",
    max_faces: int = 2000,
    timed: bool = False,
) -> dict:
    """What the page of an arm holds (:func:`write_scene_html`): the meshes, the covering
    ellipsoids and the joint frames of every animation frame.

    Parameters
    ----------
    scenario : kcplan.arm.scenario.ArmScenario
    states : array_like, shape (k, dof), optional
        The path; interpolated in joint space into about ``frames`` frames
        (:func:`kcplan.views.arm.joint_path`). Without it the frames are the start and the
        goal.
    meshes : {"auto", "visual", "collision"}
        Which of the URDF's meshes draw the links (:func:`kcplan.views.arm.arm_meshes`).
    max_faces : int
        Triangles per link mesh at most.
    timed : bool
        ``states`` are a sampled trajectory: one frame each, not interpolated.

    Returns
    -------
    dict
        ``states`` (the frames' joint vectors), ``joint_frames`` (per frame, per joint of
        the reduced model: the top three rows of its world frame, row-major), ``labels``,
        ``start_frames``, ``goal_frames``, ``meshes`` (a list of ``{name, link, joint,
        placement, vertices, faces, palette[, face_palette]}``), ``cover`` (the same with
        ``semi_axes`` that scale the unit ``sphere``'s vertices instead of vertices and
        faces), ``source`` (which meshes) and ``path`` (the tip joint's origin per
        frame). Frames are rounded to 12 decimals, vertices to 1 µm.
    """
    from kcplan.views.arm import arm_meshes, cover_meshes, joint_frames_along, joint_path, tip_joint

    arm = scenario.arm
    if states is not None and len(states):
        path = (np.asarray(states, dtype=float) if timed
                else joint_path(arm.continuous(states), max(frames - 1, 1)))  # fmt: skip
        last = len(path) - 1
        labels = [f"frame {k} of {last}" + (" (start)" if k == 0 else " (goal)" if k == last
                  else "") for k in range(len(path))]  # fmt: skip
    else:
        path = np.stack([scenario.start, scenario.goal])
        labels = ["start", "goal"]
    links, source = arm_meshes(arm, meshes, max_faces)
    frames_ = joint_frames_along(arm, path)
    ends = joint_frames_along(arm, [scenario.start, scenario.goal])
    tip = tip_joint(arm)

    def rows(F: np.ndarray) -> list:  # 12 decimals: within 1e-12 of Pinocchio's frames
        return np.round(F[..., :3, :].reshape(len(F), 12), 12).tolist()

    import trimesh

    sphere = trimesh.creation.icosphere(2)  # cover_meshes' unit sphere, stored once
    palette = [_mesh_data(m)["palette"] for m in cover_meshes(arm, 0)]
    cover = [
        {"name": f"cover {k}", "link": b.link, "joint": int(b.joint),
         "placement": np.asarray(b.placement)[:3].ravel().tolist(),
         "semi_axes": np.asarray(b.semi_axes).tolist(), "palette": palette[k]}
        | ({} if b.hull is None else {"vertices": np.round(b.hull.vertices, 6).ravel().tolist(),
                                      "faces": b.hull.triangles.ravel().tolist()})
        for k, b in enumerate(arm.bodies)
    ]  # fmt: skip

    return {
        "scenario": scenario.name,
        "source": source,
        "joints": list(arm.joints),
        "states": path.tolist(),
        "labels": labels,
        "joint_frames": [rows(F) for F in frames_],
        "start_frames": rows(ends[0]),
        "goal_frames": rows(ends[1]),
        "meshes": [_mesh_data(m) for m in links],
        "sphere": {
            "vertices": np.round(sphere.vertices, 6).ravel().tolist(),
            "faces": np.asarray(sphere.faces).ravel().tolist(),
        },
        "cover": cover,
        "path": frames_[:, tip, :3, 3].tolist() if states is not None and len(states) else [],
    }


def arm_figure(scenario, data: dict, show_cover: bool = False) -> go.Figure:
    """The plotly figure of an arm's page: the obstacles (a cloud as its points, named by
    how many are drawn: :func:`_cloud_traces`), and empty traces for the start
    and goal arms (green, red), the moving arm and its cover that the page's script fills
    from ``data`` (:func:`arm_view_data`); ``data["traces"]`` is set to their indices."""
    traces = []
    for ob in scenario.obstacles:
        for V, F in _obstacle_meshes(ob, 3):
            trace = _mesh(V, F, "#8c8c8c", 0.45, ob.label)
            trace.update(legendgroup="obstacles", showlegend=not traces, name="obstacles")
            traces.append(trace)
    traces += _cloud_traces(scenario.obstacles)[0]
    if data["path"]:
        P = np.asarray(data["path"])
        line = {"color": "#1f77b4", "width": 3}
        traces.append(
            go.Scatter3d(x=P[:, 0], y=P[:, 1], z=P[:, 2], mode="lines", line=line, name="tip path")
        )
    roles = {}
    for role, opacity, visible in (("start", 0.25, True), ("goal", 0.25, True), ("arm", 1.0, True),
                                   ("cover", 0.35, show_cover)):  # fmt: skip
        roles[role] = len(traces)
        name = {"arm": f"arm ({data['source'].split(' (')[0]})", "cover": "covering ellipsoids"}
        traces.append(go.Mesh3d(x=[], y=[], z=[], i=[], j=[], k=[], opacity=opacity,
                                flatshading=True, name=name.get(role, role), hoverinfo="name",
                                showlegend=True, visible=visible))  # fmt: skip
    data["traces"] = roles
    figure = go.Figure(data=traces)
    links = data["source"].split(" (")[0]
    figure.update_layout(
        title=f"{scenario.name}: {scenario.arm.describe()}, links: {links}",
        scene={"aspectmode": "data", "xaxis_title": "x", "yaxis_title": "y", "zaxis_title": "z"},
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
        legend={"x": 0.01, "y": 0.95},
        uirevision="arm",
    )
    return figure


def arm_html(scenario, data: dict, show_cover: bool = False) -> str:
    """One self-contained HTML page (plotly.js embedded; works offline) of an arm and its
    :func:`arm_view_data`: see :func:`write_scene_html`."""
    import json

    figure = arm_figure(scenario, data, show_cover)
    html = figure.to_html(
        include_plotlyjs=True, full_html=True, post_script=_ARM_SCRIPT, default_height="90vh"
    )
    blob = json.dumps(data, separators=(",", ":")).replace("</", "<\\/")
    controls = _ARM_CONTROLS.format(
        last=len(data["joint_frames"]) - 1, cover=" checked" if show_cover else ""
    )
    head = f'<script type="application/json" id="{_ARM_DATA_ID}">{blob}</script>\n{controls}'
    at = html.index("<body>") + len("<body>")
    return html[:at] + "\n" + head + html[at:]
