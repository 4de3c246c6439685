"""What the vertices' trees buy a cover (issue 41, item 2; the ablation).

Fits each part with K ellipsoids twice in one process: with the cutting trees whose cuts
sit at quantiles of the part's curvature measure alone (``kcplan.cover.fit.VERTEX_CUTS =
False``) and with the trees whose cuts sit at quantiles of the mesh's triangle corners
grown beside them (the default). The table gives the union's volume over the part's of
each (Monte Carlo, 95 % intervals) and the seconds of each fit. The default keeps the
smallest union of all its trees on the fit's own score, so it is never larger than the
curvature's alone but for the Monte Carlo's noise::

    python scripts/vertex_cuts.py [--meshes A.stl B.stl ...] [--profiles u_channel,...]
        [--bodies 4,8] [--samples N]

The default parts are :mod:`scripts.cover_tightness`'s (the Panda hand, link0 and link3,
the UR5 upper arm and forearm, the L-bracket, and every generated part of
:mod:`kcplan.cover.profiles`).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import kcplan.cover.fit as cover_fit
from kcplan.cover import fit_cover, read_solid, union_volume

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cover_tightness import add_part_options, chosen_parts, label  # noqa: E402


def run(path: Path, bodies: int, vertex_cuts: bool, samples: int) -> tuple[float, float, float]:
    """One fit with ``VERTEX_CUTS = vertex_cuts``: its union / part volume, the 95 %
    half-width of that, and its seconds."""
    solid = read_solid(path)
    saved = cover_fit.VERTEX_CUTS
    cover_fit.VERTEX_CUTS = vertex_cuts
    try:
        cover = fit_cover(solid, bodies=bodies)
    finally:
        cover_fit.VERTEX_CUTS = saved
    volume, error = union_volume(cover.bodies, samples)
    return volume / solid.volume, 1.96 * error / solid.volume, cover.seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_part_options(parser, "4,8", "4,8")
    parser.add_argument("--samples", type=int, default=200_000, help="Monte Carlo samples")
    args = parser.parse_args()
    lines = [
        "| part | K | curvature's trees alone | with the vertices' trees | seconds alone "
        "| seconds with | time ratio |",
        "|---|---|---|---|---|---|---|",
    ]
    total = [0.0, 0.0]
    with tempfile.TemporaryDirectory() as tmp:
        paths, bodies = chosen_parts(args, Path(tmp))
        for path in paths:
            for k in bodies:
                (r0, e0, t0), (r1, e1, t1) = (run(path, k, v, args.samples) for v in (False, True))
                total[0] += t0
                total[1] += t1
                lines.append(
                    f"| {label(path)} | {k} | {r0:.3f} +- {e0:.3f} | {r1:.3f} +- {e1:.3f} "
                    f"| {t0:.1f} | {t1:.1f} | {t1 / t0:.2f} |"
                )
                print(lines[-1], file=sys.stderr, flush=True)
    lines.append(f"| all | | | | {total[0]:.1f} | {total[1]:.1f} | {total[1] / total[0]:.2f} |")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
