"""Convert the HRM benchmark maps used in benchmarks/RESULTS.md into a local folder.

HRM's maps are GPL-3.0 data, so their conversions are not committed; this script
recreates them (2D and 3D sparse, cluttered and maze, plus the 2D superellipse maps)::

    python scripts/import_real_maps.py [--hrm ../shared/data/external/hrm/resources] \
        [--out build/hrm]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from kcplan.cli import main as kcplan

MAPS = [
    ("ellipse_sparse", 2),
    ("ellipse_cluttered", 2),
    ("ellipse_maze", 2),
    ("superellipse_cluttered", 2),
    ("superellipse_maze1", 2),
    ("ellipsoid_sparse", 3),
    ("ellipsoid_cluttered", 3),
    ("ellipsoid_maze", 3),
]


def main() -> int:
    here = Path(__file__).resolve().parents[1]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hrm", default=str(here.parent / "shared/data/external/hrm/resources"))
    parser.add_argument("--out", default=str(here / "build" / "hrm"))
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, dim in MAPS:
        target = out / f"hrm_{name}_{dim}d.yaml"
        code = kcplan(
            ["import", "hrm", args.hrm, "--map", name, "--dimension", str(dim), "-o", str(target)]
        )
        if code:
            return code
    return 0


if __name__ == "__main__":
    sys.exit(main())
