"""Import Moving AI grid maps (``.map``, ``.scen``) into 2D kcplan scenarios.

Format (movingai.com/benchmarks/formats.html): a ``.map`` file has the lines
``type octile``, ``height H``, ``width W``, ``map`` and then H rows of W characters,
``.``, ``G``, ``S`` passable and anything else (``@``, ``O``, ``T``, ``W``) blocked; a
``.scen`` file has ``version 1`` and tab-separated rows ``bucket, map, width, height,
start_x, start_y, goal_x, goal_y, optimal_length`` with x the column and y the row
counted from the top.

Conversion: cell ``(row r, column c)`` is the square ``[c s, (c+1) s] x [(H-r-1) s,
(H-r) s]`` (y up, cell size ``s``). Blocked cells become boxes, merged greedily into
rectangles (each as wide as its run of cells, then as tall as the rows below repeat
that run), which covers exactly the blocked cells; four walls just outside the map keep
the robot on it. The default robot is the ellipse ``a = [0.7 w s, 0.4 w s]`` for the
map's narrowest corridor ``w`` cells wide: its minor diameter fits across the corridor,
its major diameter does not, so the planner must orient it. Start and goal yaw: the
first of 0, 90, 45 and 135 degrees at which the robot there is free; a ``.scen`` cell
where the robot fits at none of them is replaced by the nearest (4-connected) free cell
where it does, and the description says so.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from kcplan.maps import MapImportError

__all__ = [
    "read_grid",
    "read_scenario_rows",
    "merge_rectangles",
    "free_square_sizes",
    "narrowest_corridor",
    "import_movingai",
]

PASSABLE = frozenset(".GS")


def read_grid(path: str | os.PathLike) -> np.ndarray:
    """The map's blocked cells, a boolean array of shape (H, W), row 0 at the top."""
    p = Path(path)
    try:
        lines = p.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as err:
        raise MapImportError(f"{p}: cannot read the map: {err}") from None
    header: dict[str, str] = {}
    for i, line in enumerate(lines):
        key, _, value = line.strip().partition(" ")
        if key == "map":
            rows = lines[i + 1 :]
            break
        header[key] = value.strip()
    else:
        raise MapImportError(f"{p}: map: expected a line 'map' before the grid, got none")
    try:
        height, width = int(header["height"]), int(header["width"])
    except (KeyError, ValueError):
        raise MapImportError(
            f"{p}: height/width: expected integer 'height H' and 'width W' lines, got {header}"
        ) from None
    rows = [r.rstrip("\r\n") for r in rows if r.strip()]
    if len(rows) != height or any(len(r) != width for r in rows):
        raise MapImportError(
            f"{p}: map: expected {height} rows of {width} cells, got {len(rows)} rows of "
            f"lengths {sorted({len(r) for r in rows})}"
        )
    return np.array([[ch not in PASSABLE for ch in r] for r in rows])


def read_scenario_rows(path: str | os.PathLike) -> list[tuple[int, int, int, int, float]]:
    """``(start_x, start_y, goal_x, goal_y, optimal_length)`` of each row of a ``.scen``."""
    p = Path(path)
    try:
        lines = p.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as err:
        raise MapImportError(f"{p}: cannot read the scenario file: {err}") from None
    out = []
    for n, line in enumerate(lines, start=1):
        if not line.strip() or line.startswith("version"):
            continue
        f = line.split("\t")
        try:
            out.append((int(f[4]), int(f[5]), int(f[6]), int(f[7]), float(f[8])))
        except (IndexError, ValueError):
            raise MapImportError(
                f"{p}: line {n}: expected 9 tab-separated fields (bucket, map, width, height, "
                f"start_x, start_y, goal_x, goal_y, length), got {line!r}"
            ) from None
    return out


def merge_rectangles(blocked: np.ndarray) -> list[tuple[int, int, int, int]]:
    """Rectangles ``(row, column, height, width)`` that exactly tile the blocked cells."""
    used = np.zeros_like(blocked)
    H, W = blocked.shape
    rects = []
    for r in range(H):
        c = 0
        while c < W:
            if not blocked[r, c] or used[r, c]:
                c += 1
                continue
            w = 1
            while c + w < W and blocked[r, c + w] and not used[r, c + w]:
                w += 1
            h = 1
            while (
                r + h < H and blocked[r + h, c : c + w].all() and not used[r + h, c : c + w].any()
            ):
                h += 1
            used[r : r + h, c : c + w] = True
            rects.append((r, c, h, w))
            c += w
    return rects


def free_square_sizes(blocked: np.ndarray) -> np.ndarray:
    """For each free cell, the side (in cells) of the largest free square containing it;
    0 for blocked cells. Shape (H, W)."""
    H, W = blocked.shape
    corner = np.zeros((H + 1, W + 1), dtype=int)  # largest free square ending at (r, c)
    for r in range(H):
        for c in range(W):
            if not blocked[r, c]:
                corner[r + 1, c + 1] = 1 + min(corner[r, c + 1], corner[r + 1, c], corner[r, c])
    best = np.zeros((H, W), dtype=int)
    for r in range(H):
        for c in range(W):
            k = corner[r + 1, c + 1]
            if k:
                view = best[r - k + 1 : r + 1, c - k + 1 : c + 1]
                np.maximum(view, k, out=view)
    return best


def narrowest_corridor(blocked: np.ndarray, quantile: float = 5.0) -> int:
    """Width in cells of the map's narrowest corridors: the ``quantile`` percentile, over
    free cells, of the largest free square containing the cell (the percentile ignores
    the few cells of one-cell pockets and strips along the map's edge)."""
    sizes = free_square_sizes(blocked)[~blocked]
    if not len(sizes):
        raise MapImportError("map: expected at least one free cell, got none")
    return max(1, int(np.percentile(sizes, quantile)))


def _nearest_fitting_cell(blocked, x, y, fits):
    """Breadth-first search over free cells (4-connected) from ``(x, y)`` for the nearest
    cell where ``fits(x, y)`` gives a pose; returns ``(x, y, pose, steps)`` or None."""
    H, W = blocked.shape
    seen = {(x, y)}
    frontier = [(x, y)]
    steps = 0
    while frontier:
        for cx, cy in frontier:
            pose = fits(cx, cy)
            if pose is not None:
                return cx, cy, pose, steps
        nxt = []
        for cx, cy in frontier:
            for nx, ny in ((cx + 1, cy), (cx - 1, cy), (cx, cy + 1), (cx, cy - 1)):
                if 0 <= nx < W and 0 <= ny < H and not blocked[ny, nx] and (nx, ny) not in seen:
                    seen.add((nx, ny))
                    nxt.append((nx, ny))
        frontier, steps = nxt, steps + 1
    return None


def import_movingai(
    map_path: str | os.PathLike,
    scen_path: str | os.PathLike | None = None,
    index: int = 0,
    cell: float = 1.0,
    robot: tuple[float, float] | None = None,
    inflation: float = 0.1,
) -> dict:
    """Convert a Moving AI map (and one ``.scen`` row) into a 2D scenario dict.

    Parameters
    ----------
    map_path : path
    scen_path : path, optional
        Scenario file; row ``index`` (0-based, counting data rows) gives start and goal.
        Without it, start and goal are the free cells nearest the top-left and the
        bottom-right corners where the robot fits.
    cell : float
        Side of a cell in the scenario's length unit.
    robot : (a1, a2), optional
        Robot semi-axes; default ``[0.7 w cell, 0.4 w cell]`` for the narrowest corridor
        ``w`` (:func:`narrowest_corridor`).
    """
    from kcplan.scenarios import parse_scenario
    from kcplan.world import CollisionWorld

    blocked = read_grid(map_path)
    H, W = blocked.shape
    if not (cell > 0 and math.isfinite(cell)):
        raise MapImportError(f"--cell: expected a positive number, got {cell}")
    w = narrowest_corridor(blocked)
    semi_axes = list(robot) if robot else [round(0.7 * w * cell, 9), round(0.4 * w * cell, 9)]
    if len(semi_axes) != 2 or not all(a > 0 for a in semi_axes):
        raise MapImportError(f"--robot: expected two positive semi-axes, got {robot}")
    semi_axes = sorted((float(a) for a in semi_axes), reverse=True)
    obstacles = [
        {
            "box": {
                "center": [(c + wd / 2) * cell, (H - r - ht / 2) * cell],
                "size": [wd * cell, ht * cell],
            }
        }
        for r, c, ht, wd in merge_rectangles(blocked)
    ]
    t = 2.0 * semi_axes[0] + cell  # walls thicker than the robot, just outside the map
    Wm, Hm = W * cell, H * cell
    obstacles += [
        {"box": {"center": [Wm / 2, -t / 2], "size": [Wm + 2 * t, t]}},
        {"box": {"center": [Wm / 2, Hm + t / 2], "size": [Wm + 2 * t, t]}},
        {"box": {"center": [-t / 2, Hm / 2], "size": [t, Hm]}},
        {"box": {"center": [Wm + t / 2, Hm / 2], "size": [t, Hm]}},
    ]
    name = Path(map_path).stem
    data = {
        "name": f"movingai_{name}" + (f"_{index}" if scen_path else ""),
        "description": "",
        "dimension": 2,
        "bounds": {"low": [0.0, 0.0], "high": [Wm, Hm]},
        "robot": {"semi_axes": semi_axes, "inflation": inflation},
        "start": {"position": [0.5 * cell, Hm - 0.5 * cell], "yaw": 0.0},
        "goal": {"position": [0.5 * cell, Hm - 0.5 * cell], "yaw": 0.0},
        "obstacles": obstacles,
    }
    world = CollisionWorld(parse_scenario(data, str(map_path), Path("."), check=False))

    def centre(x: int, y: int) -> list[float]:
        return [(x + 0.5) * cell, (H - y - 0.5) * cell]

    offsets = list(
        dict.fromkeys(
            [(0.0, 0.0)] + [(dx, dy) for dx in (-0.5, 0.0, 0.5) for dy in (-0.5, 0.0, 0.5)]
        )
    )

    def fit(x: int, y: int) -> tuple[list[float], float] | None:
        """A pose in cell (x, y) or on its border where the robot is free: the centre
        first, then edge midpoints and corners (a corridor of even width has its centre
        line on cell borders)."""
        if blocked[y, x]:
            return None
        cx, cy = centre(x, y)
        for dx, dy in offsets:
            p = [cx + dx * cell, cy + dy * cell]
            for yaw in (0.0, math.pi / 2, math.pi / 4, 3 * math.pi / 4):
                if not world.in_collision(np.array([*p, yaw])):
                    return p, yaw
        return None

    if scen_path is not None:
        rows = read_scenario_rows(scen_path)
        if not 0 <= index < len(rows):
            raise MapImportError(
                f"{scen_path}: --index: expected 0 to {len(rows) - 1}, got {index}"
            )
        sx, sy, gx, gy, length = rows[index]
        ends, moved = [], []
        for what, (x, y) in (("start", (sx, sy)), ("goal", (gx, gy))):
            if not (0 <= x < W and 0 <= y < H) or blocked[y, x]:
                raise MapImportError(
                    f"{scen_path}: row {index}: {what}: expected a free cell on the map, got {x, y}"
                )
            found = _nearest_fitting_cell(blocked, x, y, fit)
            if found is None:
                raise MapImportError(
                    f"{scen_path}: row {index}: {what}: expected a reachable cell where the "
                    f"robot {semi_axes} fits near {x, y}, got none; give a smaller --robot"
                )
            fx, fy, (position, yaw), steps = found
            if steps:
                moved.append(f"{what} moved {steps} cells from {x, y} to {fx, fy} to fit the robot")
            ends.append((position, yaw))
        origin = f"{Path(scen_path).name} row {index} (grid optimum {length:g} cells)"
        if moved:
            origin += "; " + "; ".join(moved)
    else:
        cells = [(x, y) for y in range(H) for x in range(W)]
        order = sorted(cells, key=lambda xy: xy[0] + xy[1])
        first = next((f for xy in order if (f := fit(*xy)) is not None), None)
        last = next((f for xy in reversed(order) if (f := fit(*xy)) is not None), None)
        if first is None or last is None or first == last:
            raise MapImportError(f"{map_path}: map: expected two cells where the robot fits")
        ends = [first, last]
        origin = "corner cells (no .scen given)"
    (start, syaw), (goal, gyaw) = ends
    data["start"] = {"position": start, "yaw": syaw}
    data["goal"] = {"position": goal, "yaw": gyaw}
    data["description"] = (
        f"Moving AI MAPF benchmark map {Path(map_path).name} (Stern et al., SoCS 2019, "
        f"movingai.com/benchmarks/mapf; MIT licence, via github.com/nathansttt/hog2), "
        f"{W} x {H} cells of {cell:g}, {int(blocked.sum())} blocked cells as "
        f"{len(obstacles) - 4} boxes; narrowest corridor {w} cells; start and goal from "
        f"{origin}."
    )
    return data
