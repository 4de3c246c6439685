"""MotionBenchMaker problems: a MoveIt PlanningScene and MotionPlanRequest, read.

A problem is two YAML files (``sceneNNNN.yaml``, ``requestNNNN.yaml``; see
``shared/data/external/mbm/SOURCE.md``):

* the scene's ``world.collision_objects``: primitives ``box`` (``dimensions``: full sizes
  x, y, z) and ``cylinder`` (``dimensions: [height, radius]``, axis along local z), each
  at a ``primitive_poses`` entry (``position``, ``orientation`` as a quaternion x, y, z,
  w), in the robot's base frame; its ``allowed_collision_matrix`` over the robot's links;
* the request's ``start_state.joint_state`` (names, positions) and
  ``goal_constraints[0].joint_constraints`` (one goal configuration of the planning
  group, whose joints are the goal's, in the order given).

A moving base: MoveIt names a planar virtual joint ``N``'s variables ``N/x``, ``N/y`` and
``N/theta``; a request gives the base's start as ``start_state.multi_dof_joint_state``
(``joint_names``, ``transforms``: ``translation`` x, y, z and ``rotation`` x, y, z, w; the
yaw is the rotation's about z) and its goal as joint constraints of those names, and the
base's x and y bounds are the request's ``workspace_parameters`` (MoveIt bounds a planar
joint by them). A goal that names them makes the scenario's ``robot.base``
(:mod:`kcplan.arm.description`).

Obstacles come back as :class:`kcplan.world.obstacles.Obstacle` (kinds ``box``,
``sphere`` and ``cylinder``; a cylinder's ``extents`` are ``(r, r, h / 2)``).
"""

from __future__ import annotations

import io
import os
import tarfile
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from kcplan.files import load_yaml
from kcplan.geometry.pose import quaternion_matrix
from kcplan.world.obstacles import Obstacle

__all__ = [
    "MBM_CLASSES",
    "mbm_scenario",
    "MbmError",
    "MbmProblem",
    "load_mbm_archive",
    "read_mbm_archive",
    "read_mbm_problem",
]

MBM_CLASSES = (
    "table_pick",
    "table_under_pick",
    "box",
    "bookshelf_small",
    "bookshelf_tall",
    "bookshelf_thin",
    "cage",
)
"""The seven problem classes of MotionBenchMaker, as VAMP ships them."""


class MbmError(ValueError):
    """A problem that cannot be read; ``str(err)`` is ``FILE: FIELD: expected ..., got ...``."""


@dataclass(frozen=True)
class MbmProblem:
    """One MotionBenchMaker problem.

    Attributes
    ----------
    obstacles : tuple of Obstacle
    joints : tuple of str
        The planning group: the goal's joints, in the goal's order.
    start, goal : ndarray, shape (len(joints),)
    start_state : dict of str to float
        Every joint of the request's start state (fingers included).
    allowed : frozenset of frozenset of str
        Link pairs the scene's allowed collision matrix allows to touch.
    names : tuple of str
        The scene's ``id`` of each obstacle (an object of several primitives names each),
        e.g. ``Can1``, the object a table_pick problem grasps.
    workspace : ((float, float, float), (float, float, float)) or None
        The request's ``workspace_parameters``: its min and max corners (metres).
    """

    obstacles: tuple[Obstacle, ...]
    joints: tuple[str, ...]
    start: np.ndarray
    goal: np.ndarray
    start_state: dict
    allowed: frozenset
    names: tuple[str, ...] = ()
    workspace: tuple[tuple[float, ...], tuple[float, ...]] | None = None


def _field(data, path: str, source: str):
    value = data
    for key in path.split("."):
        if not isinstance(value, dict) or key not in value:
            raise MbmError(f"{source}: {path}: expected it, found none")
        value = value[key]
    return value


def _obstacles(scene: dict, source: str) -> tuple[tuple[Obstacle, ...], tuple[str, ...]]:
    """The scene's obstacles and the ``id`` of the object each belongs to."""
    out: list[Obstacle] = []
    names: list[str] = []
    objects = _field(scene, "world.collision_objects", source) or []
    for k, obj in enumerate(objects):
        where = f"world.collision_objects[{k}]"
        primitives, poses = obj.get("primitives") or [], obj.get("primitive_poses") or []
        if len(primitives) != len(poses):
            raise MbmError(f"{source}: {where}: expected a pose per primitive")
        for shape, pose in zip(primitives, poses, strict=True):
            names.append(str(obj.get("id", f"object{k}")))
            center = np.asarray(pose.get("position"), dtype=float)
            q = np.asarray(pose.get("orientation", [0, 0, 0, 1]), dtype=float)
            dims = np.asarray(shape.get("dimensions"), dtype=float)
            if center.shape != (3,) or q.shape != (4,) or not np.isfinite([*center, *q]).all():
                raise MbmError(f"{source}: {where}: expected a position and a quaternion")
            q = q / np.linalg.norm(q)
            R = quaternion_matrix(q)
            # spec: the obstacle in kcplan's scenario format (kcplan.arm.scenario)
            place = {"center": center.tolist(), "quaternion": q.tolist()}
            kind = shape.get("type")
            if kind == "box" and dims.shape == (3,) and (dims > 0).all():
                spec = {**place, "size": dims.tolist()}
                out.append(Obstacle("box", len(out), spec, center, R, 0.5 * dims))
            elif kind == "cylinder" and dims.shape == (2,) and (dims > 0).all():
                height, radius = (float(d) for d in dims)
                spec = {**place, "radius": radius, "height": height}
                extents = np.array([radius, radius, 0.5 * height])
                out.append(Obstacle("cylinder", len(out), spec, center, R, extents))
            elif kind == "sphere" and dims.shape == (1,) and dims[0] > 0:
                spec = {"center": center.tolist(), "radius": float(dims[0])}
                radii = np.full(3, dims[0])
                out.append(Obstacle("sphere", len(out), spec, center, np.eye(3), radii))
            else:
                raise MbmError(
                    f"{source}: {where}.primitives: expected a box, cylinder or sphere with "
                    f"positive dimensions, got {kind!r} {dims.tolist()}"
                )
    return tuple(out), tuple(names)


def _allowed(scene: dict) -> frozenset:
    acm = scene.get("allowed_collision_matrix") or {}
    names, rows = acm.get("entry_names") or [], acm.get("entry_values") or []
    pairs = set()
    for i, row in enumerate(rows):
        for j, value in enumerate(row):
            if value and i != j and i < len(names) and j < len(names):
                pairs.add(frozenset((names[i], names[j])))
    return frozenset(pairs)


def _problem(scene: dict, request: dict, scene_source: str, request_source: str) -> MbmProblem:
    joint_state = _field(request, "start_state.joint_state", request_source)
    names, positions = joint_state.get("name") or [], joint_state.get("position") or []
    if len(names) != len(positions):
        raise MbmError(f"{request_source}: start_state.joint_state: expected a position per name")
    start_state = {str(n): float(p) for n, p in zip(names, positions, strict=True)}
    start_state |= _base_variables(request, request_source)
    goals = request.get("goal_constraints") or []
    if not goals or not goals[0].get("joint_constraints"):
        raise MbmError(f"{request_source}: goal_constraints[0].joint_constraints: expected it")
    constraints = goals[0]["joint_constraints"]
    joints = tuple(str(c["joint_name"]) for c in constraints)
    missing = [j for j in joints if j not in start_state]
    if missing:
        raise MbmError(
            f"{request_source}: start_state: expected the goal's joints, missing {missing}"
        )
    start = np.array([start_state[j] for j in joints])
    goal = np.array([float(c["position"]) for c in constraints])
    obstacles, names = _obstacles(scene, scene_source)
    corners = request.get("workspace_parameters") or {}
    workspace = None
    try:
        low, high = corners["min_corner"], corners["max_corner"]
        workspace = (tuple(map(float, low)), tuple(map(float, high)))
    except (KeyError, TypeError, ValueError):
        pass  # none given: a moving base then has no bounds (refused by mbm_scenario)
    return MbmProblem(obstacles, joints, start, goal, start_state, _allowed(scene), names,
                      workspace)  # fmt: skip


def _base_variables(request: dict, source: str) -> dict[str, float]:
    """``N/x``, ``N/y``, ``N/theta`` of every joint ``N`` of the start state's
    ``multi_dof_joint_state`` (module docstring)."""
    state = (request.get("start_state") or {}).get("multi_dof_joint_state") or {}
    names, transforms = state.get("joint_names") or [], state.get("transforms") or []
    if len(names) != len(transforms):
        raise MbmError(f"{source}: start_state.multi_dof_joint_state: expected a transform "
                       "per joint name")  # fmt: skip
    out = {}
    for name, transform in zip(names, transforms, strict=True):
        try:
            tx, ty = (float(v) for v in transform["translation"][:2])
            qx, qy, qz, qw = (float(v) for v in transform["rotation"])
        except (KeyError, TypeError, ValueError):
            raise MbmError(f"{source}: start_state.multi_dof_joint_state.transforms: "
                           "expected translation [x, y, z] and rotation [x, y, z, w]"
                           ) from None  # fmt: skip
        yaw = np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
        out |= {f"{name}/x": tx, f"{name}/y": ty, f"{name}/theta": float(yaw)}
    return out


def _load(text: str | bytes, source: str) -> dict:
    try:
        data = load_yaml(text)
    except yaml.YAMLError as err:
        raise MbmError(f"{source}: expected YAML, got: {str(err).splitlines()[0]}") from None
    if not isinstance(data, dict):
        raise MbmError(f"{source}: expected a mapping")
    return data


def read_mbm_problem(scene: str | os.PathLike, request: str | os.PathLike) -> MbmProblem:
    """Read one problem from its scene and request files."""
    texts = []
    for path in (scene, request):
        try:
            texts.append(Path(path).read_text())
        except OSError as err:
            raise MbmError(f"{os.fspath(path)}: cannot read the file: {err.strerror}") from None
    return _problem(
        _load(texts[0], os.fspath(scene)), _load(texts[1], os.fspath(request)),
        os.fspath(scene), os.fspath(request),
    )  # fmt: skip


def read_mbm_archive(archive: str | os.PathLike, problem: str, index: int) -> MbmProblem:
    """Read problem ``index`` (1 to 100) of class ``problem`` (:data:`MBM_CLASSES`) from
    VAMP's ``problems.tar.bz2`` (folders ``problems/CLASS_ROBOT/``)."""
    if problem not in MBM_CLASSES:
        raise MbmError(f"problem: expected one of {', '.join(MBM_CLASSES)}, got {problem!r}")
    try:
        with tarfile.open(archive) as tar:
            members = {m.name: m for m in tar.getmembers() if m.isfile()}
            found = {}
            for kind in ("scene", "request"):
                suffix = f"/{kind}{index:04d}.yaml"
                names = [n for n in members if f"/{problem}_" in n and n.endswith(suffix)]
                if len(names) != 1:
                    raise MbmError(
                        f"{os.fspath(archive)}: expected one {problem} {kind} {index}, "
                        f"found {len(names)}"
                    )
                data = tar.extractfile(members[names[0]]).read()
                found[kind] = (_load(io.BytesIO(data).read(), names[0]), names[0])
    except (OSError, tarfile.TarError) as err:
        raise MbmError(f"{os.fspath(archive)}: cannot read the archive: {err}") from None
    (scene, scene_name), (request, request_name) = found["scene"], found["request"]
    return _problem(scene, request, scene_name, request_name)


def load_mbm_archive(
    archive: str | os.PathLike, keys: Collection[tuple[str, int]] | None = None
) -> dict[tuple[str, int], MbmProblem]:
    """The problems of VAMP's ``problems.tar.bz2``, keyed by ``(class, index)``: every
    one, or those of ``keys`` that the archive has (only they are parsed: the YAML of all
    700 takes seconds)."""
    wanted = None if keys is None else set(keys)
    texts: dict[tuple[str, int, str], tuple[bytes, str]] = {}
    try:
        with tarfile.open(archive) as tar:
            for member in tar.getmembers():
                name = member.name.rsplit("/", 2)
                if not member.isfile() or len(name) < 2 or not name[-1].endswith(".yaml"):
                    continue
                folder, file = name[-2], name[-1]
                problem = next((c for c in MBM_CLASSES if folder.startswith(c + "_")), None)
                kind = "scene" if file.startswith("scene") else "request"
                digits = file[len(kind) : -len(".yaml")]
                if problem is None or not digits.isdigit():
                    continue
                if wanted is not None and (problem, int(digits)) not in wanted:
                    continue
                texts[problem, int(digits), kind] = (tar.extractfile(member).read(), member.name)
    except (OSError, tarfile.TarError) as err:
        raise MbmError(f"{os.fspath(archive)}: cannot read the archive: {err}") from None
    out = {}
    for (problem, index, kind), (_, _) in sorted(texts.items()):
        if kind != "scene" or (problem, index, "request") not in texts:
            continue
        (scene, scene_name), (request, request_name) = (
            texts[problem, index, "scene"],
            texts[problem, index, "request"],
        )
        out[problem, index] = _problem(
            _load(scene, scene_name), _load(request, request_name), scene_name, request_name
        )
    return out


def mbm_scenario(
    problem: MbmProblem,
    name: str,
    urdf: str | os.PathLike,
    srdf: str | os.PathLike | None,
    output: str | os.PathLike,
    bodies_per_link: int | None = None,
    max_offset: float | None = None,
    representation: str | None = None,
    package_dirs: Sequence[str | os.PathLike] = (),
) -> dict:
    """The arm scenario (:mod:`kcplan.arm.scenario`, as plain data) of one problem: its
    obstacles, start and goal for the goal's joints, every other joint of the URDF fixed
    at its start value, and the allowed collision matrix; robot paths relative to the
    folder of ``output``. ``representation``, ``bodies_per_link`` and ``max_offset``
    (metres) choose the links' bodies as the scenario's fields of those names do; all
    None: kcplan's default, each link its own convex hull (:mod:`kcplan.arm.hulls`).
    ``package_dirs`` (folders of ``package://`` URIs) are written relative to the folder
    of ``output``."""
    from kcplan.arm.description import PlanarBase
    from kcplan.arm.model import ArmError, urdf_model

    folder = Path(output).resolve().parent
    if not Path(urdf).is_file():
        raise MbmError(f"{os.fspath(urdf)}: urdf: expected an existing URDF file")
    bases = sorted({j.rsplit("/", 1)[0] for j in problem.joints
                    if j.endswith(("/x", "/y", "/theta"))})  # fmt: skip
    base = None
    if bases:  # the goal moves a planar virtual joint: the base drives
        if problem.workspace is None:
            raise MbmError(f"{name}: workspace_parameters: expected the bounds of the base "
                           f"{bases[0]} (min_corner, max_corner), found none")  # fmt: skip
        low, high = problem.workspace
        base = PlanarBase(bases[0], ((low[0], high[0]), (low[1], high[1])))
    try:
        model = urdf_model(urdf, base)
    except ArmError as err:
        raise MbmError(str(err)) from None
    fixed = {
        joint: value
        for joint, value in problem.start_state.items()
        if joint not in problem.joints and model.existJointName(joint)
    }
    robot: dict = {"urdf": os.path.relpath(Path(urdf).resolve(), folder)}
    if srdf is not None:
        robot["srdf"] = os.path.relpath(Path(srdf).resolve(), folder)
    robot["joints"] = list(problem.joints)
    if base is not None:
        bounds = [list(b) for b in base.bounds]
        robot["base"] = {"type": "planar", "name": base.name, "bounds": bounds}
    if package_dirs:
        robot["package_dirs"] = [os.path.relpath(Path(d).resolve(), folder) for d in package_dirs]
    if representation is not None:
        robot["representation"] = str(representation)
    if bodies_per_link is not None:
        robot["bodies_per_link"] = int(bodies_per_link)
    if max_offset is not None:
        robot["max_offset"] = float(max_offset)
    if fixed:
        robot["fixed"] = fixed
    return {
        "name": name,
        "description": "A MotionBenchMaker problem (KavrakiLab, as VAMP ships it; "
        "Apache-2.0), converted by kcplan import mbm.",
        "robot": robot,
        "start": {"joints": problem.start.tolist()},
        "goal": {"joints": problem.goal.tolist()},
        "obstacles": [{o.kind: o.spec} for o in problem.obstacles],
        "allowed": sorted(sorted(pair) for pair in problem.allowed),
    }
