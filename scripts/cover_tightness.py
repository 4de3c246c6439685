"""How tight are kcplan's covers? Ellipsoids against spheres fitted the same way, K = 1..8.

For each mesh and each K, fits a cover by K ellipsoids and one by K spheres (the same
cutting tree search, :mod:`kcplan.cover.fit`), and estimates the union's volume over the
part's by Monte Carlo (95 % intervals). Also times ``kcplan robot fit`` on a mesh of more
than 10,000 triangles (a UR5 upper arm subdivided twice: the same surface, 16x the
triangles). Writes a markdown table, a CSV and a plot::

    python scripts/cover_tightness.py --out benchmarks/cover [--bodies 1,2,...] [--samples N]

The default meshes are the Panda hand, link0 and link3 and the UR5 upper arm and forearm
collision meshes (``../shared/data/external/example-robot-data``) and the L-bracket CAD
part of the suite; ``--meshes`` gives others. Then come the generated parts of
:mod:`kcplan.cover.profiles` (a thick ring, a U-channel made two ways, a T-profile, a
pipe, and the I, H, T, L, Z and C sections as unions of slabs), chosen by ``--profiles``.
"""

from __future__ import annotations

import argparse
import csv
import io
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from kcplan.cover import fit_cover, read_solid, union_volume
from kcplan.cover.profiles import PROFILES
from kcplan.files import write_text_atomic

ROOT = Path(__file__).resolve().parents[1]
ROBOT_DATA = ROOT.parent / "shared" / "data" / "external" / "example-robot-data"
DEFAULT_MESHES = [
    ROBOT_DATA / "panda" / "hand.stl",
    ROBOT_DATA / "panda" / "link0.stl",
    ROBOT_DATA / "panda" / "link3.stl",
    ROBOT_DATA / "ur5" / "upperarm.stl",
    ROBOT_DATA / "ur5" / "forearm.stl",
    ROOT / "scenarios" / "3d" / "meshes" / "l_bracket.stl",
]


def label(path: Path) -> str:
    return f"{path.parent.name}/{path.name}"


def write_profiles(names: list[str], folder: Path) -> list[Path]:
    """Write the generated parts ``names`` as STL files into ``folder/generated``."""
    (folder / "generated").mkdir()
    paths = [folder / "generated" / f"{name}.stl" for name in names]
    for name, path in zip(names, paths, strict=True):
        PROFILES[name]().export(path)
    return paths


def tightness(paths: list[Path], bodies: list[int], samples: int) -> list[dict]:
    rows = []
    for path in paths:
        solid = read_solid(path)
        for k in bodies:
            row = {"mesh": label(path), "triangles": len(solid.boundary), "bodies": k}
            for shape in ("ellipsoid", "sphere"):
                cover = fit_cover(solid, bodies=k, shape=shape)
                volume, error = union_volume(cover.bodies, samples)
                row[f"{shape}_ratio"] = volume / solid.volume
                row[f"{shape}_ci"] = 1.96 * error / solid.volume
                row[f"{shape}_seconds"] = cover.seconds
                row[f"{shape}_bodies"] = len(cover.bodies)
            row["excess_ratio"] = (row["sphere_ratio"] - 1) / (row["ellipsoid_ratio"] - 1)
            rows.append(row)
            print(
                f"{row['mesh']:<22} K={k}: ellipsoids {row['ellipsoid_ratio']:.3f}, spheres "
                f"{row['sphere_ratio']:.3f} ({row['ellipsoid_seconds']:.1f} s)",
                file=sys.stderr,
                flush=True,
            )
    return rows


def fit_times(path: Path, bodies: list[int]) -> list[dict]:
    """``kcplan robot fit`` as a user runs it (a new process, reading included) on the
    mesh subdivided twice (more than 10,000 triangles)."""
    import trimesh

    big = trimesh.load(path, force="mesh").subdivide().subdivide()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        mesh = Path(tmp) / f"{path.stem}_x16.stl"
        big.export(mesh)
        for k in bodies:
            t0 = time.perf_counter()
            subprocess.run(
                [sys.executable, "-m", "kcplan.cli", "robot", "fit", str(mesh), "--bodies", str(k),
                 "-o", str(Path(tmp) / "robot.yaml")],
                check=True, capture_output=True,
            )  # fmt: skip
            rows.append(
                {"mesh": f"{label(path)} x16", "triangles": len(big.faces), "bodies": k,
                 "seconds": time.perf_counter() - t0}
            )  # fmt: skip
            print(f"fit of {len(big.faces)} triangles, K={k}: {rows[-1]['seconds']:.1f} s",
                  file=sys.stderr)  # fmt: skip
    return rows


def markdown(rows: list[dict], timing: list[dict], samples: int) -> str:
    out = [
        f"Union volume / part volume (Monte Carlo, {samples} samples, +- 95 %); excess "
        "ratio = (spheres - 1) / (ellipsoids - 1), above 2 where ellipsoids leave at most "
        "half the spheres' excess.",
        "",
        "| mesh | triangles | K | ellipsoids | spheres | excess ratio | fit (s) |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    stopped = False
    for r in rows:
        cells = []
        for shape in ("ellipsoid", "sphere"):
            cell = f"{r[f'{shape}_ratio']:.3f} +- {r[f'{shape}_ci']:.3f}"
            if r[f"{shape}_bodies"] < r["bodies"]:
                cell += f" ({r[f'{shape}_bodies']} bodies)"
                stopped = True
            cells.append(cell)
        out.append(
            f"| {r['mesh']} | {r['triangles']} | {r['bodies']} | {cells[0]} | {cells[1]} | "
            f"{r['excess_ratio']:.2f} | {r['ellipsoid_seconds']:.1f} |"
        )
    if stopped:
        out += ["", "(N bodies): the fit stopped there (see `Cover.note`): no cut, nor any "
                "sequence of two cuts, made the union smaller."]  # fmt: skip
    if timing:
        out += [
            "",
            "| `kcplan robot fit` on | triangles | K | wall time (s) |",
            "|---|---:|---:|---:|",
        ]
        out += [f"| {t['mesh']} | {t['triangles']} | {t['bodies']} | {t['seconds']:.1f} |"
                for t in timing]  # fmt: skip
    return "\n".join(out) + "\n"


def plot(rows: list[dict], path: Path) -> None:
    from kcplan.views.plots import plt, save_figure

    meshes = list(dict.fromkeys(r["mesh"] for r in rows))
    fig, ax = plt.subplots(figsize=(8, 5))
    for i, mesh in enumerate(meshes):
        sub = [r for r in rows if r["mesh"] == mesh]
        k = [r["bodies"] for r in sub]
        colour = plt.get_cmap("tab20").colors[(2 * i) % 20 + (i // 10) % 2]  # 20 apart
        ax.plot(k, [r["ellipsoid_ratio"] - 1 for r in sub], "-o", color=colour, label=mesh)
        ax.plot(k, [r["sphere_ratio"] - 1 for r in sub], "--s", color=colour, alpha=0.6)
    ax.set_yscale("log")
    ax.set_xticks(sorted({r["bodies"] for r in rows}))  # K is a count: no 4.5 between
    ax.set_xlabel("bodies K")
    ax.set_ylabel("excess volume (union / part - 1)")
    ax.set_title("covers by K ellipsoids (solid) and K spheres (dashed)", fontsize=10)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))  # off the lines
    ax.grid(alpha=0.3)
    save_figure(fig, path)


def add_part_options(parser: argparse.ArgumentParser, bodies: str, meaning: str) -> None:
    """The options that choose the parts and the numbers of bodies: ``--meshes``,
    ``--profiles`` and ``--bodies`` (default ``bodies``, described as ``meaning``)."""
    parser.add_argument("--meshes", nargs="+", type=Path, help="meshes (default: see above)")
    parser.add_argument(
        "--profiles",
        default=",".join(PROFILES),
        help=f"generated parts, comma-separated, or '' (default {','.join(PROFILES)})",
    )
    parser.add_argument("--bodies", default=bodies, help=f"K values (default {meaning})")


def chosen_parts(args: argparse.Namespace, folder: Path) -> tuple[list[Path], list[int]]:
    """The meshes :func:`add_part_options` chose, the generated parts written into
    ``folder`` after them, and the numbers of bodies."""
    paths = args.meshes or [p for p in DEFAULT_MESHES if p.is_file()]
    paths += write_profiles([n for n in args.profiles.split(",") if n], folder)
    return paths, [int(k) for k in args.bodies.split(",")]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_part_options(parser, "1,2,3,4,5,6,7,8", "1..8")
    parser.add_argument("--samples", type=int, default=400_000, help="Monte Carlo samples")
    parser.add_argument("--timing", default="4,8", help="K values for the fit-time runs, or ''")
    parser.add_argument(
        "--timing-mesh",
        type=Path,
        default=ROBOT_DATA / "ur5" / "upperarm.stl",
        help="mesh subdivided for the fit-time runs (default: the UR5 upper arm, or the "
        "first mesh if it is absent)",
    )
    parser.add_argument("--out", type=Path, help="folder for cover.md, cover.csv, cover.png")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        paths, bodies = chosen_parts(args, Path(tmp))
        rows = tightness(paths, bodies, args.samples)
        big = args.timing_mesh if args.timing_mesh.is_file() else paths[0]
        timing = fit_times(big, [int(k) for k in args.timing.split(",") if k])
    table = markdown(rows, timing, args.samples)
    print(table)
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
        write_text_atomic(args.out / "cover.md", table)
        text = io.StringIO()
        writer = csv.DictWriter(text, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows({k: (round(v, 5) if isinstance(v, float) else v) for k, v in r.items()}
                         for r in rows)  # fmt: skip
        write_text_atomic(args.out / "cover.csv", text.getvalue())
        plot(rows, args.out / "cover.png")
        print(f"written to {args.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
