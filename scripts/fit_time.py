"""What a cover fit costs with Khachiyan's iteration in three forms (the ablations).

Fits each mesh with K ellipsoids three times in one process, in turn: the textbook
iteration in Python (``kcplan.geometry.enclosing.REFRESH = 0``: a new inverse of ``V(u)``
and every ``g`` at each step), Sherman and Morrison's rank-one updates in Python
(``BACKEND = "python"``, afresh every ``REFRESH`` steps) and the same in the compiled
kernel (the default, ``kcplan/_kernel/enclosing.hpp``). All three take the same steps, so
the covers agree; the table gives the seconds of each, the ratios of each to the one
before, and the union's volume over the part's of each (Monte Carlo, 200,000 samples)::

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

VARIANTS = {"textbook": ("python", 0), "rank-one": ("python", None), "kernel": ("kernel", None)}
"""Each form of the iteration: its backend and ``REFRESH`` (None: the module's)."""


def fit(path: Path, bodies: int, backend: str, refresh: int | None) -> tuple[float, float]:
    """Seconds of one fit with the iteration on ``backend`` and ``REFRESH = refresh``, and
    its union / part volume."""
    solid = read_solid(path)
    saved = enclosing.BACKEND, enclosing.REFRESH
    enclosing.BACKEND = backend
    enclosing.REFRESH = saved[1] if refresh is None else refresh
    try:
        start = time.perf_counter()
        cover = fit_cover(solid, bodies=bodies)
        seconds = time.perf_counter() - start
    finally:
        enclosing.BACKEND, enclosing.REFRESH = saved
    return seconds, union_volume(cover.bodies, 200_000)[0] / solid.volume


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_part_options(parser, "4,8", "4,8")
    args = parser.parse_args()
    lines = [
        "| mesh | K | textbook: s | rank-one: s | kernel: s | rank-one / textbook "
        "| kernel / rank-one | union / part, textbook | rank-one | kernel |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    total = dict.fromkeys(VARIANTS, 0.0)
    with tempfile.TemporaryDirectory() as tmp:
        paths, bodies = chosen_parts(args, Path(tmp))
        for path in paths:
            for k in bodies:
                runs = {name: fit(path, k, *how) for name, how in VARIANTS.items()}
                for name, (seconds, _) in runs.items():
                    total[name] += seconds
                (t0, v0), (t1, v1), (t2, v2) = runs.values()
                lines.append(
                    f"| {label(path)} | {k} | {t0:.1f} | {t1:.1f} | {t2:.1f} | {t1 / t0:.2f} "
                    f"| {t2 / t1:.2f} | {v0:.3f} | {v1:.3f} | {v2:.3f} |"
                )
                print(lines[-1], file=sys.stderr, flush=True)
    t0, t1, t2 = total.values()
    lines.append(
        f"| all | | {t0:.1f} | {t1:.1f} | {t2:.1f} | {t1 / t0:.2f} | {t2 / t1:.2f} | | | |"
    )
    print("\n".join(lines))


if __name__ == "__main__":
    main()
