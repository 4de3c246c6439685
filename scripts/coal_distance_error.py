"""Coal's distance error against exact distances, through the kernel's own queries.

The kernel (:mod:`kcplan._kernel`) trusts ``d (1 - COAL_CLEARANCE_RTOL) - atol`` of a coal
(GJK) distance ``d``, with ``atol = COAL_CLEARANCE_ATOL * s + COAL_CLEARANCE_FLOOR (1 + r)``
for a scene of size ``s`` (``r``: the largest ball obstacle's radius).
This measures the *excess* ``coal - exact`` of ``World.body_distances`` (positive: coal
overestimates, the dangerous direction) for one ellipsoid robot (largest semi-axis 0.1 to
10, aspect ratios up to 10, random orientation) against one obstacle of each kind:

* ``halfspace``: the face of a box of half side 1e3 (coal's ``Box`` when axis-aligned, a
  convex polytope of its corners when rotated; 2D: a rotated square prism), the robot
  within 10 of the face's centre;
* ``box`` (axis-aligned: ``Box``; rotated: convex), ``polytope`` (3D hull of 4 to 30 random
  points), ``polygon`` (2D prism of a random convex polygon), ``sphere``/``disc``,
  ``ellipsoid``/``ellipse``: half sides 0.005 to 5 (thin walls included), centres in
  ``[-spread/2, spread/2]^n``.

Exact distances by construction: a boundary point ``y`` of the obstacle (on a face, an
edge or a vertex) and an outward normal ``n`` in its normal cone are drawn, and the robot
``{t + R A u : |u| <= 1}`` is placed so that its support point in ``-n`` is ``y + d n``:
``t = y + d n + R A (A R^T n) / |A R^T n|``. The plane ``n . x = n . y`` separates the
two, so the distance is exactly ``d``. Every sample is checked by its dual certificate,
``n . t - |A R^T n| - h(n) = d`` with the obstacle's support function ``h`` (from its
vertices, not from the construction). ``--verify K`` brackets ``K`` samples per case
independently: SLSQP on ``min |x - y|`` gives a feasible pair (an upper bound) and its
direction ``n`` the dual lower bound above; the exact ``d`` must lie in between.

Distances are log-uniform in three bands: near contact (1e-6 to 1e-2), middle (1e-2 to
10) and far (10 to 1e4). The scene size ``s`` of a sample is the side of the cube about
the origin that holds the robot and the obstacle (of the half-space, the face point only).
The *allowance use* is ``excess / (rtol d_coal + atol s)``: the allowance holds while it
is below 1. ``--scale`` multiplies every length (coal's tolerance is absolute, so the
allowance, relative to the scene, fails in small units); ``--floor F`` adds ``F (1 + r)``
to the allowance, ``r`` the radius of a ball obstacle (a proposed fix). Prints a Markdown
table and a final line of JSON: ``max_rel_excess`` (excess / distance, far band),
``max_abs_excess`` and ``max_scene_excess`` (excess and excess / s, near band),
``max_allowance_use`` and ``violations`` (every sample)::

    python scripts/coal_distance_error.py [--samples 20000] [--seed 1] [--scale 1]
        [--floor 0] [--verify 20]
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize, nnls
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from kcplan._kernel import COAL_CLEARANCE_ATOL, COAL_CLEARANCE_FLOOR, COAL_CLEARANCE_RTOL, _core

BANDS = {"near": (1e-6, 1e-2), "middle": (1e-2, 10.0), "far": (10.0, 1e4)}
WALL = 1e3  # half side of the half-space's box
POSES_PER_WORLD = 10
CASES = (
    "halfspace aligned 3D",
    "halfspace rotated 3D",
    "halfspace 2D",
    "box aligned 3D",
    "box rotated 3D",
    "polytope 3D",
    "polygon 2D",
    "sphere 3D",
    "disc 2D",
    "ellipsoid 3D",
    "ellipse 2D",
)


@dataclass
class Obstacle:
    """One obstacle: how to add it to a world, where its boundary is, its support."""

    add: Callable[[_core.World], None]
    contact: Callable[[np.random.Generator], tuple[np.ndarray, np.ndarray]]
    vertices: np.ndarray | None = None  # a polytope (k x 3): h(n) = max V n
    ellipsoid: tuple[np.ndarray, np.ndarray] | None = None  # (c, L): {c + L v : |v| <= 1}
    halfspace: tuple[np.ndarray, float] | None = None  # (n, c): n . y <= c, for --verify
    extent: float = 0.0  # max |x|_inf over the obstacle, for the scene size
    ball: float = 0.0  # a ball's radius (coal's GJK treats a ball as its centre, inflated)

    def support(self, n: np.ndarray) -> float:
        if self.vertices is not None:
            return float(np.max(self.vertices @ n))
        c, L = self.ellipsoid
        return float(c @ n + np.linalg.norm(L.T @ n))


@dataclass
class Sample:
    band: str
    exact: float
    coal: float
    scene: float
    ball: float
    t: np.ndarray  # the robot is {t + RA u : |u| <= 1}
    RA: np.ndarray
    obstacle: Obstacle


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def log_uniform(rng: np.random.Generator, low: float, high: float, size=None):
    return np.exp(rng.uniform(np.log(low), np.log(high), size))


def rotation(rng: np.random.Generator, dim: int) -> np.ndarray:
    """A uniform random rotation (3 x 3; about z in 2D)."""
    if dim == 2:
        return Rotation.from_euler("z", rng.uniform(-np.pi, np.pi)).as_matrix()
    return Rotation.from_quat(rng.normal(size=4)).as_matrix()


def semi_axes(rng: np.random.Generator, dim: int, low: float, high: float) -> np.ndarray:
    """The largest log-uniform in [low, high], the others up to 10 times smaller."""
    big = float(log_uniform(rng, low, high))
    return np.array([big] + [big / 10 ** rng.uniform(0, 1) for _ in range(dim - 1)])


def embed3(a: np.ndarray) -> np.ndarray:
    """Semi-axes as coal's ellipsoid has them: (a1, a2, min a) in 2D."""
    return a if len(a) == 3 else np.append(a, a.min())


def polytope(points: np.ndarray, add: Callable | None = None) -> Obstacle:
    """The convex hull of ``points`` (3D), added by ``add(world)`` (default: as a convex
    polytope); faces, edges and vertices are drawn uniformly as contact features."""
    hull = ConvexHull(points)
    index = np.full(len(points), -1)
    index[hull.vertices] = np.arange(len(hull.vertices))
    V, T, N = points[hull.vertices], index[hull.simplices], hull.equations[:, :3]
    outward = T.copy()  # T keeps qhull's order, which hull.neighbors refers to
    for k, (a, b, c) in enumerate(T):
        if np.cross(V[b] - V[a], V[c] - V[a]) @ N[k] < 0:
            outward[k] = (a, c, b)

    def contact(rng):
        kind, i = int(rng.integers(3)), int(rng.integers(len(T)))
        if kind == 0:  # a face
            return rng.dirichlet(np.ones(3)) @ V[T[i]], N[i]
        if kind == 1:  # an edge: the one opposite vertex j of triangle i
            j = int(rng.integers(3))
            e, s, w = np.delete(T[i], j), rng.uniform(), rng.exponential(size=2)
            n = unit(w[0] * N[i] + w[1] * N[hull.neighbors[i, j]])
            return s * V[e[0]] + (1 - s) * V[e[1]], n
        v = T[i, int(rng.integers(3))]  # a vertex: its normal cone spans its faces' normals
        faces = np.flatnonzero((T == v).any(axis=1))
        return V[v], unit(rng.exponential(size=len(faces)) @ N[faces])

    if add is None:

        def add(world):
            world.add_convex(V.ravel().tolist(), outward.ravel().tolist())

    return Obstacle(add=add, contact=contact, vertices=V, extent=float(np.abs(V).max()))


def box(centre: np.ndarray, R: np.ndarray, half: np.ndarray) -> Obstacle:
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])

    def add(world):
        world.add_box(centre.tolist(), R.ravel().tolist(), half.tolist())

    return polytope(centre + (corners * half) @ R.T, add)


def polygon(P: np.ndarray) -> Obstacle:
    """The 2D prism over the convex counter-clockwise polygon ``P`` (k x 2)."""
    k = len(P)
    E = np.roll(P, -1, axis=0) - P
    N = np.column_stack([E[:, 1], -E[:, 0]]) / np.linalg.norm(E, axis=1)[:, None]

    def contact(rng):
        i = int(rng.integers(k))
        if rng.integers(2):  # an edge
            y, n = P[i] + rng.uniform() * E[i], N[i]
        else:  # a vertex: between the normals of its two edges
            w = rng.exponential(size=2)
            y, n = P[i], unit(w[0] * N[i - 1] + w[1] * N[i])
        return np.append(y, 0.0), np.append(n, 0.0)

    def add(world):
        world.add_prism(P.ravel().tolist())

    V = np.column_stack([P, np.zeros(k)])
    return Obstacle(add=add, contact=contact, vertices=V, extent=float(np.abs(P).max()))


def ellipsoid(centre: np.ndarray, R: np.ndarray, e3: np.ndarray, dim: int) -> Obstacle:
    """An ellipsoid ``{c + R diag(e3) v}`` (2D: e3 = (e1, e2, min e), R about z); a ball
    if the semi-axes are equal."""
    L = R * e3
    M = L @ L.T

    def contact(rng):
        n = unit(np.append(rng.normal(size=dim), [0.0] * (3 - dim)))
        return centre + M @ n / np.sqrt(n @ M @ n), n

    def add(world):
        if np.all(e3 == e3[0]):
            world.add_sphere(centre.tolist(), float(e3[0]))
        else:
            world.add_ellipsoid(centre.tolist(), R.ravel().tolist(), e3.tolist())

    extent = float(np.abs(centre).max() + e3.max())
    ball = float(e3[0]) if np.all(e3 == e3[0]) else 0.0
    return Obstacle(add=add, contact=contact, ellipsoid=(centre, L), extent=extent, ball=ball)


def halfspace(rng: np.random.Generator, dim: int, aligned: bool, scale: float) -> Obstacle:
    """A box of half side WALL with the face n . x = 0 (through the origin)."""
    R = np.eye(3) if aligned else rotation(rng, dim)
    face, wall = (R[:, 2] if dim == 3 else R[:, 0]), WALL * scale
    if dim == 2:
        square = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * wall
        ob = polygon(square @ R[:2, :2].T - wall * face[:2])
    else:
        ob = box(-wall * face, R, np.full(3, wall))

    def contact(rng):  # a point of the face within 10 of its centre
        offset = rng.uniform(-10, 10, 3) * scale
        offset[2] *= dim == 3
        return offset - (offset @ face) * face, face

    ob.contact, ob.extent, ob.halfspace = contact, 0.0, (face, 0.0)
    return ob


def make_obstacle(case: str, rng: np.random.Generator, spread: float, scale: float):
    dim = 2 if case.endswith("2D") else 3
    centre = np.append(rng.uniform(-spread / 2, spread / 2, dim), [0.0] * (3 - dim)) * scale
    size = (0.005 * scale, 5.0 * scale)
    if case.startswith("halfspace"):
        return halfspace(rng, dim, "aligned" in case, scale)
    if case.startswith("box"):
        R = np.eye(3) if "aligned" in case else rotation(rng, 3)
        return box(centre, R, log_uniform(rng, *size, 3))
    if case.startswith("polytope"):
        points = rng.normal(size=(int(rng.integers(4, 31)), 3)) * log_uniform(rng, *size, 3)
        return polytope(centre + points @ rotation(rng, 3).T)
    if case.startswith("polygon"):
        points = rng.normal(size=(int(rng.integers(3, 13)), 2)) * log_uniform(rng, *size, 2)
        points = points @ rotation(rng, 2)[:2, :2].T
        return polygon(centre[:2] + points[ConvexHull(points).vertices])  # counter-clockwise
    if case.startswith(("sphere", "disc")):
        return ellipsoid(centre, np.eye(3), np.full(3, float(log_uniform(rng, *size))), dim)
    return ellipsoid(centre, rotation(rng, dim), embed3(semi_axes(rng, dim, *size)), dim)


def samples(case: str, count: int, rng: np.random.Generator, spread: float, scale: float):
    """``count`` samples of ``case``, ten robot poses per world of one robot, one obstacle."""
    dim = 2 if case.endswith("2D") else 3
    out: list[Sample] = []
    while len(out) < count:
        a = semi_axes(rng, dim, 0.1 * scale, 10.0 * scale)
        origin = [0.0, 0.0, 0.0] if dim == 2 else [0.0] * 6 + [1.0]
        robot = _core.Robot(dim, a.tolist(), origin)
        half_height = max(float(a.max()), 1.0 * scale)  # as kcplan.world.CollisionWorld
        world = _core.World(robot, half_height, COAL_CLEARANCE_RTOL, 0.0)
        ob = make_obstacle(case, rng, spread, scale)
        ob.add(world)
        world.finalize()
        for _ in range(min(POSES_PER_WORLD, count - len(out))):
            band = list(BANDS)[int(rng.integers(len(BANDS)))]
            d = float(log_uniform(rng, *BANDS[band])) * scale
            y, n = ob.contact(rng)
            if dim == 2:
                yaw = rng.uniform(-np.pi, np.pi)
                R = Rotation.from_euler("z", yaw).as_matrix()
            else:
                q = unit(rng.normal(size=4))
                R = Rotation.from_quat(q).as_matrix()
            RA = R * embed3(a)
            lever = np.linalg.norm(RA.T @ n)  # |A R^T n|
            t = y + d * n + RA @ (RA.T @ n) / lever
            certificate = n @ t - lever - ob.support(n)
            if abs(certificate - d) > 1e-12 * (scale + np.abs(t).max()):
                raise AssertionError(f"{case}: certificate {certificate!r}, distance {d!r}")
            pose = [t[0], t[1], yaw] if dim == 2 else [*t, *q]
            coal = world.body_distances(pose)[0]
            scene = 2 * max(np.abs(t).max() + a.max(), ob.extent, np.abs(y).max())
            out.append(Sample(band, d, coal, float(scene), ob.ball, t, RA, ob))
    return out


def ellipsoid_gap(x: np.ndarray, centre: np.ndarray, L: np.ndarray) -> float:
    """Distance from ``x`` (outside) to ``{c + L v : |v| <= 1}``, by bisection on the
    Lagrange multiplier of the nearest point."""
    U, e, _ = np.linalg.svd(L)
    z = U.T @ (x - centre)
    low, high = 0.0, e.max() * np.linalg.norm(z)
    for _ in range(200):
        lam = (low + high) / 2
        low, high = (lam, high) if np.sum((e * z / (e**2 + lam)) ** 2) > 1 else (low, lam)
    return float(np.linalg.norm(z - e**2 * z / (e**2 + high)))


def bracket(t: np.ndarray, RA: np.ndarray, ob: Obstacle) -> tuple[float, float]:
    """Bounds on the distance of the robot to ``ob``, found without the construction:
    SLSQP maximises the support-function difference ``n . t - |A R^T n| - h(n)`` over
    ``|n| <= 1`` (any ``n`` gives a lower bound); the robot's support point ``x`` in
    ``-n`` and the exact distance from ``x`` to the obstacle (a projection) give an upper
    bound."""
    if ob.halfspace is not None:
        face, c = ob.halfspace
        n = face
    elif ob.vertices is not None:
        V = ob.vertices
        n0 = unit(t - V.mean(axis=0))
        res = minimize(
            lambda z: -(z[:3] @ t - np.linalg.norm(RA.T @ z[:3]) - z[3]),
            np.append(n0, np.max(V @ n0)),
            method="SLSQP",
            constraints=[
                {"type": "ineq", "fun": lambda z: z[3] - V @ z[:3]},
                {"type": "ineq", "fun": lambda z: 1 - z[:3] @ z[:3]},
            ],
            options={"ftol": 1e-16, "maxiter": 500},
        )
        n = unit(res.x[:3])
    else:
        centre, L = ob.ellipsoid
        res = minimize(
            lambda n: -(n @ t - np.linalg.norm(RA.T @ n) - centre @ n - np.linalg.norm(L.T @ n)),
            unit(t - centre),
            method="SLSQP",
            constraints=[{"type": "ineq", "fun": lambda n: 1 - n @ n}],
            options={"ftol": 1e-16, "maxiter": 500},
        )
        n = unit(res.x)
    lower = n @ t - np.linalg.norm(RA.T @ n) - ob.support(n)
    x = t - RA @ (RA.T @ n) / np.linalg.norm(RA.T @ n)
    if ob.halfspace is not None:
        upper = face @ x - c
    elif ob.vertices is not None:  # projection on the hull: weighted sum-to-one row
        weight = 1e4 * (1 + np.abs(V).max())
        w, _ = nnls(np.vstack([V.T, np.full(len(V), weight)]), np.append(x, weight))
        upper = np.linalg.norm(x - (w / w.sum()) @ V)
    else:
        upper = ellipsoid_gap(x, centre, L)
    return float(lower), float(upper)


def known_answers() -> float:
    """Worst error of :func:`bracket` for a unit ball against the box [-1, 1]^3."""
    cube = box(np.zeros(3), np.eye(3), np.ones(3))
    worst = 0.0
    for t, exact in (
        ([0.0, 0.0, 5.0], 3.0),  # above a face
        ([0.3, -0.2, 2.5], 0.5),
        ([3.0, 3.0, 3.0], np.sqrt(12) - 1),  # off a corner
        ([3.0, 3.0, 0.0], np.sqrt(8) - 1),  # off an edge
    ):
        low, high = bracket(np.array(t), np.eye(3), cube)
        worst = max(worst, exact - low, high - exact)
    return worst


def summarise(case: str, band: str, rows: list[Sample], floor: float) -> dict:
    exact = np.array([s.exact for s in rows])
    coal = np.array([s.coal for s in rows])
    scene = np.array([s.scene for s in rows])
    ball = np.array([s.ball for s in rows])
    excess = coal - exact
    # the kernel's allowance (kcplan._kernel.build_kernel_world), its floor from --floor
    allowance = COAL_CLEARANCE_RTOL * coal + COAL_CLEARANCE_ATOL * scene + floor * (1 + ball)
    return {
        "case": case,
        "band": band,
        "samples": len(rows),
        "low": float(exact.min()),
        "high": float(exact.max()),
        "max_abs_excess": float(excess.max()),
        "max_rel_excess": float((excess / exact).max()),
        "max_scene_excess": float((excess / scene).max()),
        "overestimates": float(np.mean(excess > 0)),
        "max_allowance_use": float((excess / allowance).max()),
        "violations": int(np.sum(excess > allowance)),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=20_000, help="samples per case")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--scale", type=float, default=1.0, help="unit of every length")
    parser.add_argument(
        "--spread", type=float, default=20.0, help="side of the cube of obstacle centres"
    )
    parser.add_argument("--verify", type=int, default=0, help="samples per case bracketed by SLSQP")
    parser.add_argument(
        "--floor",
        type=float,
        default=COAL_CLEARANCE_FLOOR,
        help="absolute allowance F (1 + r), r a ball's radius (default the kernel's, "
        "COAL_CLEARANCE_FLOOR; 0 shows what the scene-relative part alone gives)",
    )
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=CASES)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    t0 = time.perf_counter()
    if args.verify:
        print(f"SLSQP bracket on known answers: worst error {known_answers():.1e}")
    print(
        "| case | band | samples | distance | max excess | max excess / distance "
        "| max excess / scene | coal over | max allowance use |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    rows, outside, width = [], 0.0, []
    for case in args.cases:
        drawn = samples(case, args.samples, rng, args.spread, args.scale)
        for band in BANDS:
            in_band = [s for s in drawn if s.band == band]
            if not in_band:
                continue
            r = summarise(case, band, in_band, args.floor)
            rows.append(r)
            print(
                f"| {case} | {band} | {r['samples']} | {r['low']:.0e} to {r['high']:.0e} "
                f"| {r['max_abs_excess']:.1e} | {r['max_rel_excess']:.1e} "
                f"| {r['max_scene_excess']:.1e} | {100 * r['overestimates']:.0f} % "
                f"| {r['max_allowance_use']:.2f} |",
                flush=True,
            )
        for s in drawn[: args.verify]:
            low, high = bracket(s.t, s.RA, s.obstacle)
            outside = max(outside, (low - s.exact) / s.exact, (s.exact - high) / s.exact)
            width.append((high - low) / s.exact)
    elapsed = time.perf_counter() - t0
    if args.verify:
        print(
            f"SLSQP brackets of {len(width)} exact distances: median width "
            f"{np.median(width):.1e} (relative), exact value outside by at most {outside:.1e}"
        )
    print(f"<!-- {len(args.cases)} cases x {args.samples} samples: {elapsed:.0f} s -->")
    band_rows = {b: [r for r in rows if r["band"] == b] for b in BANDS}
    summary = {
        "samples": sum(r["samples"] for r in rows),
        "scale": args.scale,
        "floor": args.floor,
        "max_rel_excess": max((r["max_rel_excess"] for r in band_rows["far"]), default=0.0),
        "max_abs_excess": max((r["max_abs_excess"] for r in band_rows["near"]), default=0.0),
        "max_scene_excess": max((r["max_scene_excess"] for r in band_rows["near"]), default=0.0),
        "max_allowance_use": max(r["max_allowance_use"] for r in rows),
        "violations": sum(r["violations"] for r in rows),
        "rtol": COAL_CLEARANCE_RTOL,
        "atol": COAL_CLEARANCE_ATOL,
        "seconds": round(elapsed, 1),
    }
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
