"""Convert the HRM benchmark problems used in benchmarks/RESULTS.md into a local folder.

HRM's maps are GPL-3.0 data, so their conversions are not committed; this script
recreates them: the 2D single-body maps of section 4 and the multi-body problems of the
HRM comparison (section 6: HRM's 3D superquadric maps with the rabbit, rabbit2 and tree,
the 2D superellipse map with the rabbit and the S shape)::

    python scripts/import_real_maps.py [--hrm ../shared/data/external/hrm/resources] \
        [--out build/hrm] [--maps hrm_ellipse_sparse_2d ...]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from kcplan.cli import main as kcplan

MAPS = [  # (file stem, HRM map, dimension, HRM robot)
    ("hrm_ellipse_sparse_2d", "ellipse_sparse", 2, "single_body"),
    ("hrm_ellipse_cluttered_2d", "ellipse_cluttered", 2, "single_body"),
    ("hrm_ellipse_maze_2d", "ellipse_maze", 2, "single_body"),
    ("hrm_superellipse_cluttered_2d", "superellipse_cluttered", 2, "single_body"),
    ("hrm_superellipse_maze1_2d", "superellipse_maze1", 2, "single_body"),
    ("sparse_rabbit2", "superquadrics_sparse", 3, "rabbit2"),
    ("cluttered_rabbit", "superquadrics_cluttered", 3, "rabbit"),
    ("maze_rabbit", "superquadrics_maze", 3, "rabbit"),
    ("narrow_rabbit", "superquadrics_narrow", 3, "rabbit"),
    ("home_tree", "superquadrics_home", 3, "tree"),
    ("cluttered_rabbit_2d", "superellipse_cluttered", 2, "rabbit"),
    ("cluttered_S_2d", "superellipse_cluttered", 2, "S_shape"),
]


def main() -> int:
    here = Path(__file__).resolve().parents[1]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hrm", default=str(here.parent / "shared/data/external/hrm/resources"))
    parser.add_argument("--out", default=str(here / "build" / "hrm"))
    stems = [m[0] for m in MAPS]
    parser.add_argument(
        "--maps", nargs="+", default=stems, choices=stems, help="file stems (default: all)"
    )
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for stem, name, dim, robot in (m for m in MAPS if m[0] in args.maps):
        target = out / f"{stem}.yaml"
        options = ["--map", name, "--dimension", str(dim), "--robot", robot, "-o", str(target)]
        code = kcplan(["import", "hrm", args.hrm, *options])
        if code:
            return code
    return 0


if __name__ == "__main__":
    sys.exit(main())
