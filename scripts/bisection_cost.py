"""FCL queries per certified edge as a function of the edge's clearance (issue 5).

For random edges of the lengths RRT-Connect makes (from a random free state towards a
random state, cut at OMPL's default range, 0.2 x the space's maximum extent, and at a
quarter of it), counts the FCL queries the KC certifier spends on each edge it certifies
(one collision query for the end state, one distance query per guard) and the queries
OMPL's discrete validator spends on the same edge (one per state at 1 % resolution,
``validSegmentCount``), and relates both to the edge's minimum clearance (gap-free
verification), in units of the robot's largest semi-axis. ``--backend kernel`` (the
default) certifies with the compiled :class:`kcplan.certification.kernel.KernelCertifier`,
``python`` with :class:`kcplan.certification.certifier.EdgeCertifier` (the same decisions and
counters)::

    python scripts/bisection_cost.py scenarios/2d/narrow_corridor.yaml ... \
        [--edges 1500] [--plot benchmarks/bisection_cost.png] [--backend kernel]
"""

from __future__ import annotations

import argparse

import numpy as np

from kcplan.certification.certifier import EdgeCertifier
from kcplan.certification.kernel import KernelCertifier
from kcplan.planning.states import set_state, state_pose, state_space
from kcplan.planning.verify import verify_path
from kcplan.scenarios import load_scenario
from kcplan.views.plots import plt, save_figure
from kcplan.world import CollisionWorld

BINS = np.array([0.0, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0, np.inf])


def random_pose(scenario, rng: np.random.Generator) -> np.ndarray:
    low, high = scenario.bounds
    t = rng.uniform(low, high)
    if scenario.dimension == 2:
        return np.append(t, rng.uniform(-np.pi, np.pi))
    q = rng.normal(size=4)
    return np.append(t, q / np.linalg.norm(q))


def edges(scenario, count: int, fraction: float, rng: np.random.Generator):
    """Yield ``(p1, p2, stock_queries)`` for random edges with valid ends."""
    n = scenario.dimension
    world = CollisionWorld(scenario)
    space = state_space(*scenario.bounds)
    space.setup()
    step = fraction * space.getMaximumExtent()
    a, b, c = space.allocState(), space.allocState(), space.allocState()
    made = 0
    while made < count:
        p1 = random_pose(scenario, rng)
        if world.in_collision(p1):
            continue
        set_state(a, p1, n)
        set_state(b, random_pose(scenario, rng), n)
        d = space.distance(a, b)
        space.interpolate(a, b, min(1.0, step / d), c)
        p2 = state_pose(c, n)
        if world.in_collision(p2):
            continue
        made += 1
        yield p1, p2, int(space.validSegmentCount(a, c))


def measure(path: str, count: int, fraction: float, seed: int, backend: str = "kernel") -> dict:
    scenario = load_scenario(path)
    scale = float(np.max(scenario.semi_axes))
    certifier = (KernelCertifier if backend == "kernel" else EdgeCertifier)(
        CollisionWorld(scenario)
    )
    check_world = CollisionWorld(scenario)
    rows = []
    for p1, p2, stock in edges(scenario, count, fraction, np.random.default_rng(seed)):
        before = certifier.counters["guards"] + certifier.counters["collision_queries"]
        ok = certifier.check(p1, p2)
        spent = certifier.counters["guards"] + certifier.counters["collision_queries"] - before
        check = verify_path(check_world, [p1, p2])
        rows.append((check.min_clearance / scale, ok, spent, stock, check.collides))
    return {"scenario": scenario.name, "fraction": fraction, "rows": np.array(rows, dtype=float)}


def table(result: dict) -> list[str]:
    rows = result["rows"]
    out = []
    for lo, hi in zip(BINS[:-1], BINS[1:], strict=True):
        mine = rows[(rows[:, 0] >= lo) & (rows[:, 0] < hi) & (rows[:, 4] == 0)]
        if not len(mine):
            continue
        cert = mine[mine[:, 1] == 1]
        kc = f"{np.median(cert[:, 2]):.0f}" if len(cert) else "–"
        out.append(
            f"| {result['scenario']} | {result['fraction']:g} | [{lo:g}, {hi:g}) | {len(mine)} "
            f"| {len(cert) / len(mine):.0%} | {kc} | {np.median(mine[:, 3]):.0f} |"
        )
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="+")
    parser.add_argument("--edges", type=int, default=1500)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--plot", default="benchmarks/bisection_cost.png")
    parser.add_argument(
        "--backend",
        choices=("kernel", "python"),
        default="kernel",
        help="who certifies: the compiled kernel (default) or the Python certifier",
    )
    args = parser.parse_args()
    results = [
        measure(path, args.edges, fraction, args.seed, args.backend)
        for path in args.scenarios
        for fraction in (0.2, 0.05)
    ]
    print(
        "| scenario | edge length / extent | clearance / max(a) | free edges | certified "
        "| KC queries per certified edge (median) | stock queries (median) |"
    )
    print("|---|---|---|---|---|---|---|")
    for result in results:
        print("\n".join(table(result)), flush=True)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for i, result in enumerate(results):
        rows = result["rows"]
        cert = rows[(rows[:, 1] == 1) & (rows[:, 0] > 0)]
        color = plt.cm.tab10(i // 2)
        marker = "o" if result["fraction"] == 0.2 else "^"
        label = f"{result['scenario']}, length {result['fraction']:g} x extent"
        ax.scatter(cert[:, 0], cert[:, 2], s=6, alpha=0.35, color=color, marker=marker, label=label)
        centres, medians = [], []
        for lo, hi in zip(BINS[:-1], BINS[1:], strict=True):
            mine = cert[(cert[:, 0] >= lo) & (cert[:, 0] < hi)]
            if len(mine) >= 3:
                centres.append(np.median(mine[:, 0]))
                medians.append(np.median(mine[:, 2]))
        ls = "-" if result["fraction"] == 0.2 else "--"
        ax.plot(centres, medians, ls, color=color, lw=1.5)
        if result["fraction"] == 0.2:
            ax.axhline(np.median(rows[:, 3]), color=color, ls=":", lw=1)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("edge clearance / robot's largest semi-axis")
    ax.set_ylabel("FCL queries to certify the edge")
    ax.set_title(
        "Cost of the KC bisection near obstacles (lines: bin medians)\n"
        "dotted: stock validator at 1 % resolution, long edges"
    )
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, markerscale=2)
    save_figure(fig, args.plot)
    print(f"plot written to {args.plot}")


if __name__ == "__main__":
    main()
