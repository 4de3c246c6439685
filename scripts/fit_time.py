"""What a cover fit costs with Khachiyan's rank-one updates, and without them (the ablation).

Fits each mesh with K ellipsoids twice in one process, alternating: with
``kcplan.geometry.enclosing.REFRESH = 0`` (a new inverse of ``V(u)`` and every ``g`` at
each step of Khachiyan's iteration, the textbook form) and with the default (Sherman and
Morrison's rank-one updates, afresh every ``REFRESH`` steps). Both take the same steps,
so the covers agree; the table gives the seconds of each, their ratio and the union's
volume over the part's of both (Monte Carlo, 200,000 samples)::

    python scripts/fit_time.py [--meshes A.stl B.stl ...] [--profiles u_channel,...]
        [--bodies 4,8]

The default meshes are :mod:`scripts.cover_tightness`'s (the Panda hand, link0 and link3,
the UR5 upper arm and forearm, the L-bracket) and every generated part of
:mod:`kcplan.cover.profiles`.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

from kcplan.cover import fit_cover, read_solid, union_volume
from kcplan.geometry import enclosing

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cover_tightness import add_part_options, chosen_parts, label  # noqa: E402


def fit(path: Path, bodies: int, refresh: int) -> tuple[float, float]:
    """Seconds of one fit with ``REFRESH = refresh``, and its union / part volume."""
    solid = read_solid(path)
    saved = enclosing.REFRESH
    enclosing.REFRESH = refresh
    try:
        start = time.perf_counter()
        cover = fit_cover(solid, bodies=bodies)
        seconds = time.perf_counter() - start
    finally:
        enclosing.REFRESH = saved
    return seconds, union_volume(cover.bodies, 200_000)[0] / solid.volume


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_part_options(parser, "4,8", "4,8")
    args = parser.parse_args()
    lines = [
        "| mesh | K | textbook: s | rank-one: s | ratio | union / part, textbook | rank-one |",
        "|---|---|---|---|---|---|---|",
    ]
    total = [0.0, 0.0]
    with tempfile.TemporaryDirectory() as tmp:
        paths, bodies = chosen_parts(args, Path(tmp))
        for path in paths:
            for k in bodies:
                (t0, v0), (t1, v1) = fit(path, k, 0), fit(path, k, enclosing.REFRESH)
                total[0] += t0
                total[1] += t1
                lines.append(
                    f"| {label(path)} | {k} | {t0:.1f} | {t1:.1f} | {t1 / t0:.2f} "
                    f"| {v0:.3f} | {v1:.3f} |"
                )
                print(lines[-1], file=sys.stderr, flush=True)
    lines.append(f"| all | | {total[0]:.1f} | {total[1]:.1f} | {total[1] / total[0]:.2f} | | |")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
