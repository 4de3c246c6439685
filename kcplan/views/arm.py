"""What the views draw of an arm: its links' meshes, posed along a path by Pinocchio.

The views (:mod:`kcplan.views.html`, :mod:`kcplan.views.animation`,
:mod:`kcplan.views.plots`) draw an arm from the triangles of its links and from the frames
of its joints along a path; this module computes both and nothing else (it imports
neither matplotlib nor plotly).

- :func:`arm_meshes`: one :class:`LinkMesh` per geometry of the URDF, its triangles in the
  mesh's own frame and that frame's placement in the joint that carries it, in the arm's
  reduced model (:attr:`kcplan.arm.ArmModel.model`). The *visual* geometry when every
  visual mesh of the URDF can be read, else the *collision* geometry (the meshes the
  cover and the verifier use). Visual geometry is read with Pinocchio on the full URDF
  and carried over to the reduced model through the link frames: the frame of a link has
  the same world pose in both models, so a geometry placed at ``P`` in its link's frame
  sits at ``frame.placement @ P`` in the joint that carries that frame in the reduced
  model.
- :func:`cover_meshes`: the covering ellipsoids (:attr:`kcplan.arm.ArmModel.bodies`) as
  meshes of the same kind.
- :func:`joint_path`: a path's joint vectors interpolated densely (linearly, as OMPL's
  real vector space does, every waypoint kept).
- :func:`joint_frames_along`: the world frame of every joint at every state
  (``pinocchio.forwardKinematics``); a mesh's world frame is ``frames[joint] @
  placement``, which equals ``pinocchio.updateGeometryPlacements``'s ``oMg``.

Large meshes are decimated by vertex clustering (:func:`decimate`) so that a page or a
GIF stays small and fast.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from kcplan.arm.description import read_description
from kcplan.arm.model import package_folders
from kcplan.arm.shapes import bvh_mesh

__all__ = [
    "LinkMesh",
    "arm_meshes",
    "cover_meshes",
    "cylinder_mesh",
    "obstacle_mesh",
    "decimate",
    "joint_frames_along",
    "joint_path",
    "mesh_frames",
    "posed_triangles",
    "tip_joint",
    "visual_meshes_missing",
]

COLLISION_RGB = (0.62, 0.66, 0.74)
"""Colour of a link drawn from its collision mesh (no material of its own)."""


@dataclass(frozen=True, eq=False)
class LinkMesh:
    """The triangles of one link geometry, in the geometry's frame.

    Attributes
    ----------
    name : str
        The geometry's name (Pinocchio's, e.g. ``panda_link1_0``; ``cover 3`` for a body).
    link : str
        The URDF link it belongs to.
    joint : int
        The reduced model's joint that carries it (0: the universe).
    placement : ndarray, shape (4, 4)
        The geometry's frame in that joint's frame.
    vertices : ndarray, shape (n, 3)
        In the geometry's frame, scaled (metres).
    faces : ndarray of int, shape (m, 3)
    colors : ndarray, shape (m, 3)
        RGB of every triangle, from 0 to 1.
    """

    name: str
    link: str
    joint: int
    placement: NDArray[np.float64]
    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    colors: NDArray[np.float64]


def decimate(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    max_faces: int,
    colors: NDArray[np.float64] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.float64] | None]:
    """At most ``max_faces`` triangles of a mesh, by vertex clustering (Rossignac and
    Borrel): vertices in one cell of a grid merge into their mean, triangles that lose a
    corner disappear, duplicates are dropped; the cell grows by 20 % until few enough
    triangles remain. A view's approximation, not a sound one (it may cut thin parts).

    Returns
    -------
    vertices, faces, colors
        The mesh itself when it has at most ``max_faces`` triangles; ``colors`` (one row
        per face, or None) follow their faces.
    """
    V = np.asarray(vertices, dtype=float)
    F = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(F) <= max_faces:
        return V, F, colors
    low = V.min(axis=0)
    extent = float(np.ptp(V, axis=0).max()) or 1.0
    cell = extent / 400.0
    while True:
        keys = np.floor((V - low) / cell).astype(np.int64)
        _, cluster = np.unique(keys, axis=0, return_inverse=True)
        cluster = cluster.ravel()
        G = cluster[F]
        keep = (G[:, 0] != G[:, 1]) & (G[:, 1] != G[:, 2]) & (G[:, 0] != G[:, 2])
        _, first = np.unique(np.sort(G[keep], axis=1), axis=0, return_index=True)
        chosen = np.flatnonzero(keep)[np.sort(first)]
        if len(chosen) <= max_faces or cell > extent:
            break
        cell *= 1.2
    used, G = np.unique(cluster[F[chosen]], return_inverse=True)
    counts = np.bincount(cluster, minlength=used.max() + 1)
    sums = np.zeros((used.max() + 1, 3))
    np.add.at(sums, cluster, V)
    centres = sums[used] / counts[used][:, None]
    return centres, G.reshape(-1, 3), None if colors is None else np.asarray(colors)[chosen]


def _merged(V: NDArray[np.float64], F: NDArray[np.int64]):
    """The mesh with coincident vertices merged (files often repeat a vertex per face)."""
    unique, inverse = np.unique(V, axis=0, return_inverse=True)
    return unique, inverse.ravel()[F]


def _read_mesh(path: str, scale: NDArray[np.float64]):
    """Triangles and per-face RGB of a mesh file (trimesh; a scene's parts merged with
    their transforms and the diffuse colours of their materials)."""
    import trimesh

    loaded = trimesh.load(path, process=False)
    parts = []
    if isinstance(loaded, trimesh.Scene):
        for node in loaded.graph.nodes_geometry:
            transform, name = loaded.graph[node]
            mesh = loaded.geometry[name]
            if isinstance(mesh, trimesh.Trimesh) and len(mesh.faces):
                parts.append((mesh, transform))
    elif isinstance(loaded, trimesh.Trimesh):
        parts.append((loaded, np.eye(4)))
    vertices, faces, colors, offset = [], [], [], 0
    for mesh, transform in parts:
        V = np.asarray(mesh.vertices, dtype=float) @ transform[:3, :3].T + transform[:3, 3]
        vertices.append(V * scale)
        faces.append(np.asarray(mesh.faces, dtype=np.int64) + offset)
        colors.append(_face_colors(mesh))
        offset += len(V)
    if not parts:
        raise ValueError(f"{path}: no triangles")
    return np.vstack(vertices), np.vstack(faces), np.vstack(colors)


def _face_colors(mesh) -> NDArray[np.float64]:
    """RGB per face of a trimesh mesh: its material's diffuse colour, its face colours, or
    the collision colour."""
    visual = mesh.visual
    n = len(mesh.faces)
    material = getattr(visual, "material", None)
    if material is not None:
        main = getattr(material, "main_color", None)
        if main is not None:
            return np.tile(np.asarray(main[:3], dtype=float) / 255.0, (n, 1))
    if getattr(visual, "kind", None) in ("face", "vertex"):
        return np.asarray(visual.face_colors[:, :3], dtype=float) / 255.0
    return np.tile(COLLISION_RGB, (n, 1))


def _primitive(shape):
    """Triangles of a coal primitive (box, cylinder, capsule, sphere) in its own frame,
    or None."""
    import trimesh

    kind = type(shape).__name__
    if kind == "Box":
        mesh = trimesh.creation.box(extents=2.0 * np.asarray(shape.halfSide, dtype=float))
    elif kind == "Cylinder":
        mesh = trimesh.creation.cylinder(float(shape.radius), 2.0 * float(shape.halfLength), 32)
    elif kind == "Capsule":
        mesh = trimesh.creation.capsule(2.0 * float(shape.halfLength), float(shape.radius))
    elif kind == "Sphere":
        mesh = trimesh.creation.icosphere(2, float(shape.radius))
    else:
        return None
    return np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int64)


def _geometry_meshes(
    objects, links, placements, joints, max_faces: int, own_colors: bool = True
) -> list[LinkMesh]:
    """LinkMeshes of Pinocchio geometry objects with their links, reduced joints and
    placements; ``own_colors``: the meshes' materials, else the collision colour."""
    out = []
    for obj, link, placement, joint in zip(objects, links, placements, joints, strict=True):
        primitive = _primitive(obj.geometry)  # Pinocchio's meshPath is "BOX" etc. for these
        if primitive is not None:
            V, F = primitive
            C = np.tile(COLLISION_RGB, (len(F), 1))
        else:
            try:
                V, F, C = _read_mesh(obj.meshPath, np.asarray(obj.meshScale, dtype=float))
            except (ImportError, ValueError, OSError):  # a format trimesh cannot read (a
                V, F = bvh_mesh(obj.geometry)  # .dae without pycollada): Pinocchio's copy
                C = np.tile(COLLISION_RGB, (len(F), 1))
            if not own_colors:
                C = np.tile(COLLISION_RGB, (len(F), 1))
        V, F = _merged(V, F)
        V, F, C = decimate(V, F, max_faces, C)
        out.append(LinkMesh(obj.name, link, int(joint), placement, V, F, C))
    return out


def _visual_geometry(arm):
    """The URDF's visual geometry objects with their joints and placements in the arm's
    reduced model (see the module docstring), or a reason why there are none."""
    import pinocchio as pin

    urdf = arm.urdf
    description = arm.description or read_description(urdf)  # the tree the arm was read as
    full = description.model()
    try:
        folders = package_folders(urdf, arm.package_dirs)
        visual = description.geometry(full, pin.GeometryType.VISUAL, folders)
    except (RuntimeError, ValueError, OSError) as err:
        lines = str(err).strip().splitlines()
        return None, lines[0] if lines else type(err).__name__
    if len(visual.geometryObjects) == 0:
        return None, "the URDF has no visual geometry"
    model = arm.model
    objects, links, placements, joints = [], [], [], []
    for obj in visual.geometryObjects:
        link_frame = full.frames[obj.parentFrame]
        reduced = model.frames[model.getFrameId(link_frame.name, link_frame.type)]
        in_link = link_frame.placement.inverse() * obj.placement
        objects.append(obj)
        links.append(link_frame.name)
        placements.append(np.asarray((reduced.placement * in_link).homogeneous, dtype=float))
        joints.append(int(reduced.parentJoint))
    return (objects, links, placements, joints), ""


def visual_meshes_missing(arm) -> str:
    """Why the arm's visual meshes cannot be drawn (``""`` when they can): reads the
    URDF's visual geometry with Pinocchio, as :func:`arm_meshes` does."""
    return _visual_geometry(arm)[1]


def arm_meshes(arm, source: str = "auto", max_faces: int = 3000) -> tuple[list[LinkMesh], str]:
    """The meshes that draw an arm (:class:`kcplan.arm.ArmModel`).

    Parameters
    ----------
    arm : ArmModel
    source : {"auto", "visual", "collision"}
        ``auto``: the visual meshes (in their materials' colours) when every one of them
        can be read, else the collision meshes (in one colour, :data:`COLLISION_RGB`);
        ``visual`` fails instead of falling back.
    max_faces : int
        Triangles per geometry at most (:func:`decimate`).

    Returns
    -------
    meshes : list of LinkMesh
    what : str
        ``visual meshes`` or ``collision meshes``, with the reason for a fallback.

    Raises
    ------
    ValueError
        ``source`` is ``visual`` and the URDF's visual meshes cannot be read.
    """
    if source not in ("auto", "visual", "collision"):
        raise ValueError(f"source: expected auto, visual or collision, got {source!r}")
    reason = ""
    if source != "collision":
        found, reason = _visual_geometry(arm)
        if found is not None:
            held = _attached_meshes(arm, max_faces)  # not in the URDF's visual geometry
            return _geometry_meshes(*found, max_faces) + held, "visual meshes"
        if source == "visual":
            raise ValueError(f"{arm.urdf}: visual: {reason}")
    objects = list(arm.geometry.geometryObjects)
    placements = [np.asarray(o.placement.homogeneous, dtype=float) for o in objects]
    joints = [int(o.parentJoint) for o in objects]
    links = [arm.model.frames[o.parentFrame].name for o in objects]
    what = "collision meshes" + (f" (no visual meshes: {reason})" if reason else "")
    return _geometry_meshes(objects, links, placements, joints, max_faces, False), what


def _attached_meshes(arm, max_faces: int) -> list[LinkMesh]:
    """The objects the arm holds (:mod:`kcplan.arm.attach`), from its collision geometry."""
    names = {obj.name for obj in arm.attached}
    objects = [o for o in arm.geometry.geometryObjects if o.name in names]
    placements = [np.asarray(o.placement.homogeneous, dtype=float) for o in objects]
    return _geometry_meshes(objects, [o.name for o in objects], placements,
                            [int(o.parentJoint) for o in objects], max_faces, False)  # fmt: skip


def cover_meshes(arm, subdivisions: int = 2) -> list[LinkMesh]:
    """The bodies of an arm as meshes, placed at the body's frame: a link's hull as its
    triangles, an ellipsoid as an icosphere scaled by its semi-axes."""
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions)
    U, F = np.asarray(sphere.vertices, dtype=float), np.asarray(sphere.faces, dtype=np.int64)
    palette = np.array([[0.12, 0.47, 0.71], [1.0, 0.5, 0.05], [0.17, 0.63, 0.17],
                        [0.84, 0.15, 0.16], [0.58, 0.4, 0.74], [0.55, 0.34, 0.29]])  # fmt: skip
    out = []
    for k, body in enumerate(arm.bodies):
        hull = body.hull
        V, T = (U * body.semi_axes, F) if hull is None else (hull.vertices, hull.triangles)
        out.append(LinkMesh(f"cover {k}", body.link, int(body.joint), np.asarray(body.placement),
                            V, T, np.tile(palette[k % len(palette)], (len(T), 1))))  # fmt: skip
    return out


def cylinder_mesh(ob, sections: int = 32) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """A cylinder obstacle (axis along its local z; ``extents`` = radius, radius, half
    height) as a triangle mesh: ``sections`` sides and two fans."""
    r, _, c = ob.extents
    t = np.linspace(0.0, 2.0 * np.pi, sections, endpoint=False)
    ring = np.column_stack([r * np.cos(t), r * np.sin(t)])
    bottom = np.column_stack([ring, np.full(sections, -c)])
    top = np.column_stack([ring, np.full(sections, c)])
    V = np.vstack([bottom, top, [[0.0, 0.0, -c], [0.0, 0.0, c]]])
    k = np.arange(sections)
    n = (k + 1) % sections
    F = np.vstack([
        np.column_stack([k, n, sections + k]), np.column_stack([n, sections + n, sections + k]),
        np.column_stack([np.full(sections, 2 * sections), n, k]),
        np.column_stack([np.full(sections, 2 * sections + 1), sections + k, sections + n]),
    ])  # fmt: skip
    return ob.center + V @ ob.rotation.T, F


def obstacle_mesh(ob) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """A 3D obstacle (:class:`kcplan.world.obstacles.Obstacle`) as one triangle mesh in the
    world: a box's 12 triangles, a cylinder's (:func:`cylinder_mesh`), a sphere's or an
    ellipsoid's icosphere, a mesh's or a convex obstacle's own triangles. A cloud
    (``pointcloud``, ``depth``) has none: the views draw its points
    (:func:`kcplan.views.clouds.cloud_points_for_display`).

    Raises
    ------
    ValueError
        ``ob`` is a cloud.
    """
    import trimesh

    from kcplan.views.clouds import is_cloud

    if is_cloud(ob):
        raise ValueError(f"{ob.label}: a cloud is drawn as points, not as a mesh")

    if ob.kind in ("mesh", "convex"):
        return np.asarray(ob.vertices, dtype=float), np.asarray(ob.triangles, dtype=np.int64)
    if ob.kind == "cylinder":
        return cylinder_mesh(ob)
    if ob.kind == "box":
        unit = trimesh.creation.box(extents=2.0 * np.asarray(ob.extents, dtype=float))
    else:  # sphere, ellipsoid: extents are the semi-axes
        unit = trimesh.creation.icosphere(2)
        unit.vertices = unit.vertices * np.asarray(ob.extents, dtype=float)
    V = np.asarray(unit.vertices, dtype=float) @ np.asarray(ob.rotation).T + ob.center
    return V, np.asarray(unit.faces, dtype=np.int64)


def joint_path(states, count: int = 60) -> NDArray[np.float64]:
    """About ``count`` joint vectors along a path: every waypoint, and each edge cut into
    steps in proportion to its joint-space (Euclidean) length, interpolated linearly.

    Parameters
    ----------
    states : array_like, shape (k, dof)
    count : int

    Returns
    -------
    ndarray, shape (m, dof)
        The first row is ``states[0]``, the last ``states[-1]``.
    """
    P = np.asarray(states, dtype=float)
    if P.ndim != 2 or len(P) == 0:
        raise ValueError(f"states: expected a (k, dof) array with k >= 1, got shape {P.shape}")
    if len(P) == 1:
        return P.copy()
    lengths = np.linalg.norm(np.diff(P, axis=0), axis=1)
    total = max(float(lengths.sum()), 1e-12)
    out = [P[:1]]
    for k, length in enumerate(lengths):
        steps = max(1, int(np.ceil(count * length / total)))
        t = np.arange(1, steps + 1)[:, None] / steps
        out.append(P[k] + t * (P[k + 1] - P[k]))
    return np.vstack(out)


def joint_frames_along(arm, states) -> NDArray[np.float64]:
    """World frames of every joint of the reduced model at every state, shape ``(k,
    njoints, 4, 4)`` (``pinocchio.forwardKinematics``; row 0 is the universe)."""
    import pinocchio as pin

    model = arm.model
    data = model.createData()
    out = np.empty((len(states), model.njoints, 4, 4))
    for k, state in enumerate(np.asarray(states, dtype=float)):
        pin.forwardKinematics(model, data, arm.configuration(state))
        for i in range(model.njoints):
            out[k, i] = data.oMi[i].homogeneous
    return out


def mesh_frames(meshes: Sequence[LinkMesh], frames: NDArray[np.float64]) -> NDArray[np.float64]:
    """World frames ``(k, len(meshes), 4, 4)`` of meshes, from joint frames ``(k, njoints,
    4, 4)``: ``frames[:, joint] @ placement``."""
    return np.stack([frames[:, m.joint] @ m.placement for m in meshes], axis=1)


def posed_triangles(meshes: Sequence[LinkMesh], frames: NDArray[np.float64]):
    """All the meshes' triangles in the world at one state's joint frames ``(njoints, 4,
    4)``: ``(m, 3, 3)`` corners and ``(m, 3)`` colours."""
    corners, colors = [], []
    for mesh in meshes:
        T = frames[mesh.joint] @ mesh.placement
        V = mesh.vertices @ T[:3, :3].T + T[:3, 3]
        corners.append(V[mesh.faces])
        colors.append(mesh.colors)
    return np.concatenate(corners), np.concatenate(colors)


def tip_joint(arm) -> int:
    """The joint of the planning group farthest down the chain (the end effector's):
    the one with the most ancestors."""
    model = arm.model

    def depth(i: int) -> int:
        d = 0
        while i:
            i, d = model.parents[i], d + 1
        return d

    ids = [model.getJointId(name) for name in arm.joints]
    return max(ids, key=depth)
