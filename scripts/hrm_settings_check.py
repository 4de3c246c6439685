"""Are HRM's start and goal poses free for a given robot, in HRM's own geometry?

Independent of kcplan's collision world and of its polytope approximations: samples the
surface of every body of the robot at the start and goal of a 3D superquadric map and
evaluates the exact superquadric level of the arena (> 1: the point is outside the arena)
and of every obstacle (< 1: the point is inside an obstacle)::

    python scripts/hrm_settings_check.py [--hrm ../shared/data/external/hrm/resources]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from kcplan.geometry.pose import pose_frame
from kcplan.geometry.robot import Body, Robot
from kcplan.maps.hrm import HRM_ROBOTS, _axis_angle_quaternion, _rows
from kcplan.maps.superquadric import superquadric_level

MAPS = ("sparse", "cluttered", "maze", "narrow", "home", "tunnel")


def robot(folder: Path, name: str) -> Robot:
    rows = _rows(folder / f"robot_{name}_3D.csv", 12)
    return Robot(
        [Body(r[:3], np.array([*r[5:8], *_axis_angle_quaternion(r[8:11], r[11])])) for r in rows]
    )


def surface(body_robot: Robot, pose: np.ndarray, count: int = 4000) -> np.ndarray:
    u = np.random.default_rng(0).normal(size=(count, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    points = []
    for body, body_pose in zip(body_robot.bodies, body_robot.body_poses(pose), strict=True):
        R, t = pose_frame(body_pose, 3)
        points.append(t + (u * body.semi_axes) @ R.T)
    return np.vstack(points)


def main() -> None:
    here = Path(__file__).resolve().parents[1]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hrm", default=str(here.parent / "shared/data/external/hrm/resources"))
    folder = Path(parser.parse_args().hrm) / "3D"
    print("| map | robot | start: arena level, obstacle level | goal: arena, obstacle | free |")
    print("|---|---|---|---|---|")
    for name in MAPS:
        arena = _rows(folder / f"env_superquadrics_{name}_3D_arena.csv", 12)[0]
        obstacles = _rows(folder / f"env_superquadrics_{name}_3D_obstacle.csv", 12)
        setting = _rows(folder / f"setting_superquadrics_{name}_3D.csv", 7, extra=True)
        for robot_name in HRM_ROBOTS[3]:
            cells, free = [], True
            for row in setting[:2]:
                pose = np.array([*row[:3], *_axis_angle_quaternion(row[3:6], row[6])])
                P = surface(robot(folder, robot_name), pose)
                outside = superquadric_level(P - arena[5:8], arena[:3], tuple(arena[3:5])).max()
                inside = min(
                    superquadric_level(
                        (P - o[5:8])
                        @ pose_frame([0, 0, 0, *_axis_angle_quaternion(o[8:11], o[11])], 3)[0],
                        o[:3],
                        tuple(o[3:5]),
                    ).min()
                    for o in obstacles
                )
                free &= outside <= 1.0 and inside >= 1.0
                cells.append(f"{outside:.3g}, {inside:.3g}")
            print(
                f"| {name} | {robot_name} | {cells[0]} | {cells[1]} | {'yes' if free else 'no'} |"
            )


if __name__ == "__main__":
    main()
