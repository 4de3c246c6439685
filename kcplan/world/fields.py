"""The reader every scenario format shares: a file's YAML and typed fields whose errors are
one line naming the file, the field and what was expected::

    scenarios/x.yaml: obstacles[3].box.size: expected 2 positive numbers, got [4, -1]

Below both formats: the rigid robots' (:mod:`kcplan.world.scenario`) and the arms'
(:mod:`kcplan.arm.scenario`) read their fields with :class:`FieldReader` and their
obstacles with :mod:`kcplan.world.obstacles`.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from numpy.typing import NDArray

from kcplan.files import load_yaml
from kcplan.geometry.pose import quaternion_matrix, wrap_angle
from kcplan.geometry.rotations import exp_rotation

__all__ = [
    "MAX_MAGNITUDE",
    "MAX_SCENARIO_BYTES",
    "MIN_POSITIVE",
    "QUATERNION_TOLERANCE",
    "FieldReader",
    "ScenarioError",
    "read_padding",
    "read_scenario_data",
]


MAX_SCENARIO_BYTES = 16 * 2**20
"""Largest scenario file read, in bytes (protects against inputs that exhaust memory)."""


MAX_MAGNITUDE = 1e9
"""Largest absolute value of any number in a scenario; FCL crashes on values near 1e300."""


MIN_POSITIVE = 1e-9
"""Smallest size (side, semi-axis, radius, scale, inflation) accepted."""


QUATERNION_TOLERANCE = 1e-2
"""Quaternions with | |q| - 1 | up to this are normalised; larger deviations are errors."""


class ScenarioError(ValueError):
    """An invalid scenario; ``str(err)`` is one line ``FILE: FIELD: expected ..., got ...``."""


def _show(value: Any, limit: int = 60) -> str:
    """A short one-line rendering of a YAML value for error messages."""

    def render(v: Any, depth: int = 0) -> str:
        if depth > 3:
            return "..."
        if isinstance(v, bool) or v is None:
            return str(v).lower() if v is not None else "null"
        if isinstance(v, float):
            return (
                "nan"
                if math.isnan(v)
                else ("inf" if v > 0 else "-inf")
                if math.isinf(v)
                else repr(v)
            )
        if isinstance(v, str):
            return repr(v)
        if isinstance(v, list):
            return (
                "["
                + ", ".join(render(x, depth + 1) for x in v[:8])
                + (", ...]" if len(v) > 8 else "]")
            )
        if isinstance(v, dict):
            items = [
                f"{render(k, depth + 1)}: {render(x, depth + 1)}" for k, x in list(v.items())[:6]
            ]
            return "{" + ", ".join(items) + (", ...}" if len(v) > 6 else "}")
        return repr(v)

    text = " ".join(render(value).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


class FieldReader:
    """Typed access to parsed YAML with errors that name the file and field."""

    def __init__(self, source: str):
        self.source = source

    def fail(self, where: str, expected: str, value: Any = None, got: str | None = None):
        got = got if got is not None else _show(value)
        raise ScenarioError(f"{self.source}: {where}: expected {expected}, got {got}")

    def mapping(self, value: Any, where: str, required: tuple, optional: tuple = ()) -> dict:
        if not isinstance(value, dict):
            self.fail(where, f"a mapping with keys {', '.join(required + optional)}", value)
        for key in value:
            if key not in required + optional:
                allowed = ", ".join(required + optional)
                raise ScenarioError(
                    f"{self.source}: {where}: unknown key {key!r}; expected one of {allowed}"
                )
        for key in required:
            if key not in value:
                raise ScenarioError(f"{self.source}: {where}: missing required key {key!r}")
        return value

    @staticmethod
    def _ok(x: float | None, positive: bool) -> bool:
        if x is None or not math.isfinite(x) or abs(x) > MAX_MAGNITUDE:
            return False
        return x >= MIN_POSITIVE if positive else True

    def number(self, value: Any, where: str, positive: bool = False) -> float:
        what = "a positive number" if positive else "a finite number"
        x = self._float(value)
        if not self._ok(x, positive):
            self.fail(where, what + self._range_note([x], positive), value)
        return x

    @staticmethod
    def _range_note(xs: list, positive: bool) -> str:
        """Mention the magnitude limits only when a finite number broke them."""
        finite = [x for x in xs if x is not None and math.isfinite(x) and (x > 0 or not positive)]
        if any(abs(x) > MAX_MAGNITUDE or (positive and x < MIN_POSITIVE) for x in finite):
            low = f"{MIN_POSITIVE:g} to " if positive else "at most "
            return f" (magnitude {low}{MAX_MAGNITUDE:g})"
        return ""

    @staticmethod
    def _float(value: Any) -> float | None:
        if isinstance(value, bool):
            return None
        if isinstance(value, (int, float)):
            return float(value)
        if isinstance(value, str):  # YAML 1.1 reads "1e3" as a string
            try:
                return float(value)
            except ValueError:
                return None
        return None

    def vector(self, value: Any, where: str, n: int, positive: bool = False) -> NDArray:
        kind = "positive numbers" if positive else "finite numbers"
        if not isinstance(value, list) or len(value) != n:
            self.fail(where, f"{n} {kind}", value)
        xs = [self._float(v) for v in value]
        if not all(self._ok(x, positive) for x in xs):
            self.fail(where, f"{n} {kind}" + self._range_note(xs, positive), value)
        return np.array(xs, dtype=float)

    def points(self, value: Any, where: str, n: int, least: int, most: int) -> NDArray:
        """A list of ``least`` to ``most`` points of ``n`` coordinates, shape ``(k, n)``."""
        if not isinstance(value, list) or not least <= len(value) <= most:
            coordinates = "[x, y]" if n == 2 else "[x, y, z]"
            self.fail(
                where,
                f"a list of {least} to {most} points {coordinates}",
                value,
                f"{len(value)} points" if isinstance(value, list) else None,
            )
        return np.array([self.vector(v, f"{where}[{i}]", n) for i, v in enumerate(value)])

    def text(self, value: Any, where: str) -> str:
        if not isinstance(value, str) or not value.strip():
            self.fail(where, "a non-empty string", value)
        return value

    def quaternion(self, value: Any, where: str) -> NDArray:
        q = self.vector(value, where, 4)
        norm = float(np.linalg.norm(q))
        if abs(norm - 1.0) > QUATERNION_TOLERANCE:
            self.fail(
                where,
                "a unit quaternion [qx, qy, qz, qw]",
                value,
                f"{_show(value)} with norm {norm:.4g}",
            )
        return q / norm

    def rotation(self, spec: dict, where: str, n: int) -> NDArray:
        """Rotation matrix from an optional ``yaw`` (2D) or ``quaternion`` (3D) field."""
        if n == 2:
            return exp_rotation([self.number(spec.get("yaw", 0.0), f"{where}.yaw")], 2)
        q = self.quaternion(spec.get("quaternion", [0.0, 0.0, 0.0, 1.0]), f"{where}.quaternion")
        return quaternion_matrix(q)

    def pose(self, value: Any, where: str, n: int, ignore: tuple = ()) -> NDArray:
        """``{position, yaw | quaternion}`` as a flat pose; ``ignore`` lists other keys the
        caller has read."""
        angle = "yaw" if n == 2 else "quaternion"
        spec = self.mapping(value, where, ("position",), (angle, *ignore))
        position = self.vector(spec["position"], f"{where}.position", n)
        if n == 2:  # OMPL's SO(2) holds [-pi, pi]: a yaw of 7.0 would be an invalid state
            yaw = float(wrap_angle(self.number(spec.get("yaw", 0.0), f"{where}.yaw")))
            return np.append(position, yaw)
        q = self.quaternion(spec.get("quaternion", [0.0, 0.0, 0.0, 1.0]), f"{where}.quaternion")
        return np.concatenate([position, q])


def read_padding(r: FieldReader, robot: Any) -> float:
    """``robot.padding``: a number >= 0 (default 0), the clearance kept from obstacles."""
    value = robot.get("padding", 0.0) if isinstance(robot, dict) else 0.0
    padding = r.number(value, "robot.padding")
    if padding < 0:
        r.fail("robot.padding", "a clearance of at least 0", value)
    return padding


def read_scenario_data(path: str | os.PathLike) -> tuple[Any, str, Path]:
    """Read a scenario file's YAML: ``(data, source, directory)``, ``source`` the path as
    given (for messages), ``directory`` the file's folder (mesh paths are relative to it);
    any robot's (:func:`kcplan.scenarios.load_scenario` parses it).

    Parameters
    ----------
    path : path-like
        A YAML file in the format of ``scenarios/README.md``.

    Raises
    ------
    ScenarioError
        For a file that is unreadable, too large, not YAML, or has YAML syntax errors
        (with line and column).
    """
    source = os.fspath(path)
    p = Path(path)
    try:
        size = p.stat().st_size
        if size > MAX_SCENARIO_BYTES:
            raise ScenarioError(
                f"{source}: expected a scenario file of at most {MAX_SCENARIO_BYTES} bytes, "
                f"got {size} bytes"
            )
        raw = p.read_bytes()
    except OSError as err:
        raise ScenarioError(f"{source}: cannot read the file: {err.strerror or err}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ScenarioError(f"{source}: expected a UTF-8 YAML text file, got binary data") from None
    try:
        data = load_yaml(text)
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark or err.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        problem = err.problem or err.context or "invalid YAML"
        raise ScenarioError(f"{source}: {where}YAML syntax error: {problem}") from None
    except (yaml.YAMLError, RecursionError) as err:
        raise ScenarioError(f"{source}: YAML syntax error: {type(err).__name__}") from None
    return data, source, p.resolve().parent
