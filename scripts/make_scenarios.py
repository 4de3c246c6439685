"""Generate kcplan's scenario suite (``scenarios/2d``, ``scenarios/3d``) and its pictures.

Everything is deterministic (fixed seeds), so rerunning reproduces the committed files::

    python scripts/make_scenarios.py --out scenarios [--no-pictures]

Shapes follow the paper: 2D robot a = [5, 3.5] (guard 1.08 a), 3D robot a = [4, 2.5, 2]
(guard 1.1 a); the thin-wall scenario uses a small robot so that OMPL's default
resolution can step over the wall.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from kcplan.scenarios import dump_scenario, load_scenario
from kcplan.world.mesh import write_stl

A2, EPS2 = [5.0, 3.5], 0.08
A3, EPS3 = [4.0, 2.5, 2.0], 0.1


def r(x: float) -> float:
    return round(float(x), 4)


def pose2(x: float, y: float, yaw: float = 0.0) -> dict:
    return {"position": [r(x), r(y)], "yaw": r(yaw)}


def pose3(x: float, y: float, z: float, q=(0.0, 0.0, 0.0, 1.0)) -> dict:
    return {"position": [r(x), r(y), r(z)], "quaternion": [r(v) for v in q]}


def box(lo, hi, **extra) -> dict:
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return {
        "box": {"center": [r(v) for v in (lo + hi) / 2], "size": [r(v) for v in hi - lo], **extra}
    }


def slab_with_hole(x0, x1, y0, y1, z0, z1, lo, hi) -> list[dict]:
    """Four boxes filling the slab ``x0..x1`` over ``lo..hi`` in y and z, except the
    rectangular hole ``y0..y1`` x ``z0..z1``."""
    return [
        box([x0, lo, lo], [x1, y0, hi]),
        box([x0, y1, lo], [x1, hi, hi]),
        box([x0, y0, lo], [x1, y1, z0]),
        box([x0, y0, z1], [x1, y1, hi]),
    ]


def scenario(
    name, description, n, low, high, start, goal, obstacles, a=None, eps=None, bodies=None
) -> dict:
    a = a or (A2 if n == 2 else A3)
    eps = eps or (EPS2 if n == 2 else EPS3)
    robot = {"bodies": bodies} if bodies else {"semi_axes": a}
    return {
        "name": name,
        "description": description,
        "dimension": n,
        "bounds": {"low": low, "high": high},
        "robot": robot | {"inflation": eps},
        "start": start,
        "goal": goal,
        "obstacles": obstacles,
    }


def open_field() -> dict:
    obstacles = [
        {"box": {"center": [30, 20], "size": [10, 6], "yaw": 0.4}},
        {"box": {"center": [55, 60], "size": [14, 5], "yaw": -0.7}},
        {"box": {"center": [85, 25], "size": [6, 16]}},
        {"circle": {"center": [45, 35], "radius": 6}},
        {"circle": {"center": [75, 55], "radius": 4}},
        {"circle": {"center": [95, 65], "radius": 5}},
        {"ellipse": {"center": [25, 60], "semi_axes": [9, 3], "yaw": 0.9}},
        {"ellipse": {"center": [65, 15], "semi_axes": [7, 4], "yaw": -0.3}},
        {"polygon": {"vertices": [[90, 45], [102, 40], [98, 52]]}},
    ]
    return scenario(
        "open_field",
        "open field with scattered boxes, discs, ellipses and a "
        "triangle: long edges in free space, where one guard certifies a lot",
        2,
        [0, 0],
        [120, 80],
        pose2(8, 40),
        pose2(112, 40, math.pi / 2),
        obstacles,
    )


def narrow_corridor() -> dict:
    half = 4.0  # robot half-width 3.5: 0.5 of clearance on each side at yaw 0
    obstacles = [box([30, 0], [90, 30 - half]), box([30, 30 + half], [90, 60])]
    return scenario(
        "narrow_corridor",
        "a 60-long corridor 8 wide for a robot 7 wide: every "
        "state in it is within 0.5 of a wall, so guards must be thin",
        2,
        [0, 0],
        [120, 60],
        pose2(10, 30),
        pose2(110, 30),
        obstacles,
    )


def slanted_gap() -> dict:
    w = 4.0 * math.sqrt(2.0)  # vertical offset of a slot 8 wide at 45 degrees
    lower = [[44, 0], [56, 0], [56, 36 - w], [44, 24 - w]]
    upper = [[44, 24 + w], [56, 36 + w], [56, 60], [44, 60]]
    obstacles = [{"polygon": {"vertices": [[r(x), r(y)] for x, y in p]}} for p in (lower, upper)]
    return scenario(
        "slanted_gap",
        "a wall 12 thick crossed by a slot 8 wide at 45 degrees: "
        "the 10 x 7 ellipse passes only after turning by about 45 degrees",
        2,
        [0, 0],
        [100, 60],
        pose2(15, 30),
        pose2(85, 30),
        obstacles,
    )


def maze(seed: int = 7) -> dict:
    cols, rows, cell, t = 6, 4, 20.0, 2.0
    rng = np.random.default_rng(seed)
    # walls: vertical wall right of (i, j); horizontal wall above (i, j)
    right = np.ones((cols, rows), bool)
    up = np.ones((cols, rows), bool)
    seen = np.zeros((cols, rows), bool)
    stack = [(0, 0)]
    seen[0, 0] = True
    while stack:  # depth-first carving
        i, j = stack[-1]
        options = [
            (i + di, j + dj)
            for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1))
            if 0 <= i + di < cols and 0 <= j + dj < rows and not seen[i + di, j + dj]
        ]
        if not options:
            stack.pop()
            continue
        ni, nj = options[rng.integers(len(options))]
        if ni != i:
            right[min(i, ni), j] = False
        else:
            up[i, min(j, nj)] = False
        seen[ni, nj] = True
        stack.append((ni, nj))
    obstacles = []
    W, H = cols * cell, rows * cell
    for i in range(cols - 1):  # interior vertical walls, runs merged
        j = 0
        while j < rows:
            if right[i, j]:
                k = j
                while k + 1 < rows and right[i, k + 1]:
                    k += 1
                x = (i + 1) * cell
                obstacles.append(
                    box([x - t / 2, j * cell - t / 2], [x + t / 2, (k + 1) * cell + t / 2])
                )
                j = k + 1
            else:
                j += 1
    for j in range(rows - 1):
        i = 0
        while i < cols:
            if up[i, j]:
                k = i
                while k + 1 < cols and up[k + 1, j]:
                    k += 1
                y = (j + 1) * cell
                obstacles.append(
                    box([i * cell - t / 2, y - t / 2], [(k + 1) * cell + t / 2, y + t / 2])
                )
                i = k + 1
            else:
                i += 1
    obstacles += [
        box([-t, -t], [W + t, 0]),
        box([-t, H], [W + t, H + t]),
        box([-t, 0], [0, H]),
        box([W, 0], [W + t, H]),
    ]
    return scenario(
        "maze",
        f"a {cols} x {rows} maze of 20-wide cells (depth-first, seed {seed}): "
        "long detours, many walls close to every edge",
        2,
        [0, 0],
        [W, H],
        pose2(10, 10),
        pose2(W - 10, H - 10, math.pi / 2),
        obstacles,
    )


def bug_trap() -> dict:
    c_shape = [
        [35, 20],
        [65, 20],
        [65, 60],
        [35, 60],
        [35, 46],
        [39, 46],
        [39, 56],
        [61, 56],
        [61, 24],
        [39, 24],
        [39, 34],
        [35, 34],
    ]
    return scenario(
        "bug_trap",
        "start inside a C-shaped trap (one non-convex polygon) whose "
        "12-wide mouth faces away from the goal: greedy growth gets stuck",
        2,
        [0, 0],
        [100, 80],
        pose2(52, 40),
        pose2(85, 40),
        [{"polygon": {"vertices": c_shape}}],
    )


def random_clutter(seed: int = 2024, count: int = 45) -> dict:
    rng = np.random.default_rng(seed)
    start, goal = np.array([8.0, 50.0]), np.array([142.0, 50.0])
    obstacles = []
    while len(obstacles) < count:
        c = rng.uniform([15, 0], [135, 100])
        if min(np.linalg.norm(c - start), np.linalg.norm(c - goal)) < 18:
            continue
        kind = rng.integers(3)
        if kind == 0:
            obstacles.append(
                {"circle": {"center": [r(v) for v in c], "radius": r(rng.uniform(2, 5))}}
            )
        elif kind == 1:
            obstacles.append(
                {
                    "box": {
                        "center": [r(v) for v in c],
                        "size": [r(v) for v in rng.uniform(3, 10, 2)],
                        "yaw": r(rng.uniform(-math.pi, math.pi)),
                    }
                }
            )
        else:
            axes = np.sort(rng.uniform(1.5, 6, 2))[::-1]
            obstacles.append(
                {
                    "ellipse": {
                        "center": [r(v) for v in c],
                        "semi_axes": [r(v) for v in axes],
                        "yaw": r(rng.uniform(-math.pi, math.pi)),
                    }
                }
            )
    return scenario(
        "random_clutter",
        f"{count} random discs, boxes and ellipses (seed {seed}): "
        "many short gaps, most of them narrower than the robot",
        2,
        [0, 0],
        [150, 100],
        pose2(*start),
        pose2(*goal),
        obstacles,
    )


def l_turn() -> dict:
    upper_left = [[0, 24], [64, 24], [64, 26], [66, 26], [66, 100], [0, 100]]
    lower_right = [
        [0, 0],
        [100, 0],
        [100, 100],
        [74, 100],
        [74, 26],
        [76, 26],
        [76, 14],
        [64, 14],
        [64, 16],
        [0, 16],
    ]
    obstacles = [{"polygon": {"vertices": upper_left}}, {"polygon": {"vertices": lower_right}}]
    return scenario(
        "l_turn",
        "an L-shaped corridor 8 wide with a 12 x 12 chamber at the corner: "
        "the 10-long ellipse must turn by 90 degrees inside the chamber",
        2,
        [0, 0],
        [100, 100],
        pose2(8, 20),
        pose2(70, 92, math.pi / 2),
        obstacles,
    )


def l_robot_door() -> dict:
    """The two-ellipse L of issue 13 through a door 7.6 wide: across the door the L is
    6.8 wide only when its long body points along the corridor."""
    bodies = [
        {"semi_axes": [5.0, 1.2], "position": [0.0, 0.0], "yaw": 0.0},
        {"semi_axes": [3.0, 1.2], "position": [-3.8, 2.6], "yaw": r(math.pi / 2)},
    ]
    obstacles = [
        box([49, 0], [51, 25.6]),
        box([49, 33.2], [51, 60]),
        box([20, 40], [30, 60]),
        {"circle": {"center": [75, 18], "radius": 6}},
    ]
    return scenario(
        "l_robot_door",
        "a robot of two ellipses (an L, 10 x 6.8) through a door 7.6 wide in a wall 2 thick: "
        "it must turn from pointing up to pointing along the corridor, pass, and turn down",
        2,
        [0, 0],
        [100, 60],
        pose2(12, 22, math.pi / 2),
        pose2(88, 40, -math.pi / 2),
        obstacles,
        bodies=bodies,
    )


def thin_wall() -> dict:
    obstacles = [box([99.95, 0], [100.05, 185]), box([99.95, 195], [100.05, 200])]
    return scenario(
        "thin_wall",
        "a wall 0.1 thick with one 10-wide door far from the straight "
        "line; a 2 x 0.8 robot in a 200 x 200 map: OMPL's default 1 % resolution "
        "(about 2.9 per step) can jump through the wall",
        2,
        [0, 0],
        [200, 200],
        pose2(50, 100),
        pose2(150, 100),
        obstacles,
        a=[1.0, 0.4],
        eps=0.1,
    )


def window_wall() -> dict:
    y0, y1, z0, z1 = 17.6, 22.4, 16.0, 24.0  # window 4.8 (y) x 8 (z)
    obstacles = slab_with_hole(39.5, 40.5, y0, y1, z0, z1, 0, 40)
    return scenario(
        "window_wall",
        "a wall 1 thick with one 4.8 x 8 window: the ellipsoid (5 wide "
        "in y at the start) must roll by 90 degrees about x to pass",
        3,
        [0, 0, 0],
        [80, 40, 40],
        pose3(15, 20, 20),
        pose3(65, 20, 20),
        obstacles,
    )


def box_field(seed: int = 11, count: int = 40) -> dict:
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(seed)
    start, goal = np.array([8.0, 30, 30]), np.array([92.0, 30, 30])
    obstacles = []
    while len(obstacles) < count:
        c = rng.uniform([18, 0, 0], [82, 60, 60])
        if min(np.linalg.norm(c - start), np.linalg.norm(c - goal)) < 15:
            continue
        q = Rotation.random(random_state=int(rng.integers(2**31))).as_quat()
        obstacles.append(
            {
                "box": {
                    "center": [r(v) for v in c],
                    "size": [r(v) for v in rng.uniform(4, 14, 3)],
                    "quaternion": [r(v) for v in q],
                }
            }
        )
    return scenario(
        "box_field",
        f"{count} randomly rotated boxes (seed {seed}) filling the "
        "middle of the volume: many gaps, few straight lines of sight",
        3,
        [0, 0, 0],
        [100, 60, 60],
        pose3(*start),
        pose3(*goal),
        obstacles,
    )


def narrow_tunnel() -> dict:
    y0, y1, z0, z1 = 16.7, 23.3, 17.2, 22.8  # tunnel 6.6 (y) x 5.6 (z): 0.8 of clearance
    obstacles = slab_with_hole(38, 62, y0, y1, z0, z1, 0, 40)
    return scenario(
        "narrow_tunnel",
        "a 24-long tunnel with 0.8 of clearance around the ellipsoid's cross-section: "
        "the robot must stay aligned with it, and every edge inside needs thin guards",
        3,
        [0, 0, 0],
        [100, 40, 40],
        pose3(15, 20, 20),
        pose3(85, 20, 20),
        obstacles,
    )


def peg_in_hole() -> dict:
    y0, y1, z0, z1 = 17.1, 22.9, 17.6, 22.4  # cavity 5.8 x 4.8, 12 deep
    obstacles = [
        box([62, 10, 10], [70, 30, 30]),
        *slab_with_hole(50, 62, y0, y1, z0, z1, 10, 30),
    ]
    s = math.sin(math.pi / 4)
    return scenario(
        "peg_in_hole",
        "insert the ellipsoid, turned by 90 degrees at the start, "
        "into a blind cavity 12 deep and 0.4 larger than its cross-section "
        "(the paper's parts-handling picture)",
        3,
        [0, 0, 0],
        [80, 40, 40],
        pose3(15, 20, 20, (0, 0, s, s)),
        pose3(57, 20, 20),
        obstacles,
    )


def icosahedron() -> tuple[np.ndarray, np.ndarray]:
    p = (1 + 5**0.5) / 2
    V = np.array(
        [
            [-1, p, 0],
            [1, p, 0],
            [-1, -p, 0],
            [1, -p, 0],
            [0, -1, p],
            [0, 1, p],
            [0, -1, -p],
            [0, 1, -p],
            [p, 0, -1],
            [p, 0, 1],
            [-p, 0, -1],
            [-p, 0, 1],
        ],
        float,
    )
    T = np.array(
        [
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ]
    )
    return V / np.linalg.norm(V[0]), T


def l_bracket() -> tuple[np.ndarray, np.ndarray]:
    """A CAD-like part: an L-shaped angle bracket 60 x 40 mm, 8 mm thick, 30 mm wide, in
    metres, as a closed mesh (the L outline extruded; caps fanned over its convex pieces,
    which share the outline's vertices, so the mesh is watertight)."""
    from kcplan.geometry.polygon import convex_pieces

    outline = np.array([[0, 0], [60, 0], [60, 8], [8, 8], [8, 40], [0, 40]], float) * 1e-3
    k, width = len(outline), 0.03
    V = np.vstack([np.column_stack([outline, np.zeros(k)]),
                   np.column_stack([outline, np.full(k, width)])])  # fmt: skip
    index = {tuple(p): i for i, p in enumerate(outline)}
    T = []
    for piece in convex_pieces(outline):
        ids = [index[tuple(p)] for p in piece]
        for i in range(1, len(ids) - 1):
            T += [[ids[0], ids[i + 1], ids[i]], [k + ids[0], k + ids[i], k + ids[i + 1]]]
    for i in range(k):
        j = (i + 1) % k
        T += [[i, j, k + j], [i, k + j, k + i]]
    return V, np.array(T)


def hand_through_slot() -> dict:
    obstacles = slab_with_hole(-0.08, 0.08, -0.18, 0.18, -0.05, 0.07, -0.5, 0.5)
    s = math.sin(math.pi / 4)
    data = scenario(
        "hand_through_slot",
        "the Franka Panda hand's collision mesh (covered by 4 ellipsoids) passes a slot "
        "0.36 x 0.12 m through a wall 0.16 m thick, starting and ending with its 0.2 m "
        "long axis upright",
        3,
        [-0.6, -0.5, -0.4],
        [0.6, 0.5, 0.4],
        pose3(-0.4, 0, 0, (s, 0, 0, s)),
        pose3(0.4, 0, 0, (s, 0, 0, s)),
        obstacles,
    )
    data["robot"] = {"mesh": "meshes/panda_hand.stl", "bodies": 4, "inflation": 0.1}
    return data


def open_space() -> dict:
    obstacles = [
        {"sphere": {"center": [30, 30, 25], "radius": 8}},
        {"sphere": {"center": [70, 70, 20], "radius": 6}},
        {
            "ellipsoid": {
                "center": [50, 50, 25],
                "semi_axes": [12, 5, 4],
                "quaternion": [0, 0, 0.3827, 0.9239],
            }
        },
        {"ellipsoid": {"center": [75, 30, 30], "semi_axes": [6, 6, 15]}},
        {
            "box": {
                "center": [30, 75, 25],
                "size": [10, 20, 30],
                "quaternion": [0.2, 0.1, 0.3, 0.9274],
            }
        },
        {
            "mesh": {
                "file": "meshes/rock.stl",
                "scale": 7.0,
                "position": [50, 20, 15],
                "quaternion": [0, 0, 0, 1],
            }
        },
    ]
    return scenario(
        "open_space",
        "a sparse volume with spheres, ellipsoids, a rotated box and an "
        "icosahedral rock mesh: long certified edges, few queries",
        3,
        [0, 0, 0],
        [100, 100, 50],
        pose3(10, 10, 25),
        pose3(90, 90, 25),
        obstacles,
    )


SUITE = {
    "2d": [
        open_field,
        narrow_corridor,
        slanted_gap,
        maze,
        bug_trap,
        random_clutter,
        l_turn,
        thin_wall,
        l_robot_door,
    ],
    "3d": [window_wall, box_field, narrow_tunnel, peg_in_hole, open_space, hand_through_slot],
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="scenarios", help="output folder (default: scenarios)")
    parser.add_argument("--no-pictures", action="store_true", help="skip the PNG files")
    args = parser.parse_args()
    out = Path(args.out)
    (out / "3d" / "meshes").mkdir(parents=True, exist_ok=True)
    (out / "2d").mkdir(parents=True, exist_ok=True)
    V, T = icosahedron()
    write_stl(out / "3d" / "meshes" / "rock.stl", V, T)
    write_stl(out / "3d" / "meshes" / "l_bracket.stl", *l_bracket())
    hand = Path(__file__).resolve().parents[1] / "scenarios" / "3d" / "meshes"
    for name in ("panda_hand.stl", "LICENSE-panda.txt"):  # committed data, not generated
        if (out / "3d" / "meshes" / name).resolve() != (hand / name).resolve():
            (out / "3d" / "meshes" / name).write_bytes((hand / name).read_bytes())
    for folder, makers in SUITE.items():
        for make in makers:
            data = make()
            path = out / folder / f"{data['name']}.yaml"
            dump_scenario(data, path)
            scen = load_scenario(path)  # validates, including start and goal collisions
            print(f"{path}: {len(scen.obstacles)} obstacles")
            if not args.no_pictures:
                from kcplan.views.plots import plot_scenario

                plot_scenario(scen, path.with_suffix(".png"), guards=scen.inflation)


if __name__ == "__main__":
    main()
