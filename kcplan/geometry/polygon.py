"""Simple planar polygons: validity checks and decomposition into convex pieces.

FCL's convex primitives need convex pieces, so a non-convex obstacle polygon is split by
ear clipping into triangles, and adjacent triangles are merged greedily while the union
stays convex (Hertel and Mehlhorn, "Fast triangulation of simple polygons", 1983: the
result has at most four times the minimum number of convex pieces). Coordinates are in
the scenario's length unit; polygons are ``(k, 2)`` arrays of vertices in order.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["polygon_area", "simple_polygon", "convex_pieces"]


def polygon_area(vertices: ArrayLike) -> float:
    """Signed area of a polygon (shoelace formula), positive for counter-clockwise order."""
    p = np.asarray(vertices, dtype=float)
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _cross(o: NDArray, a: NDArray, b: NDArray) -> NDArray:
    return (a[..., 0] - o[..., 0]) * (b[..., 1] - o[..., 1]) - (a[..., 1] - o[..., 1]) * (
        b[..., 0] - o[..., 0]
    )


def _segments_cross(p: NDArray, q: NDArray, r: NDArray, s: NDArray, tol: float) -> bool:
    """Whether closed segments pq and rs share a point (collinear overlaps included)."""
    d1, d2 = _cross(r, s, p), _cross(r, s, q)
    d3, d4 = _cross(p, q, r), _cross(p, q, s)
    if ((d1 > tol and d2 < -tol) or (d1 < -tol and d2 > tol)) and (
        (d3 > tol and d4 < -tol) or (d3 < -tol and d4 > tol)
    ):
        return True

    def on_segment(a, b, c, d) -> bool:  # c on segment ab, given |cross| <= tol
        return (
            abs(d) <= tol
            and min(a[0], b[0]) - tol <= c[0] <= max(a[0], b[0]) + tol
            and min(a[1], b[1]) - tol <= c[1] <= max(a[1], b[1]) + tol
        )

    return (
        on_segment(r, s, p, d1)
        or on_segment(r, s, q, d2)
        or on_segment(p, q, r, d3)
        or on_segment(p, q, s, d4)
    )


def simple_polygon(vertices: ArrayLike) -> NDArray[np.float64]:
    """Validate a simple polygon and return it counter-clockwise without collinear vertices.

    Parameters
    ----------
    vertices : array_like, shape (k, 2)
        Vertices in order (either orientation); the closing edge is implied.

    Returns
    -------
    ndarray, shape (m, 2)
        The same polygon, counter-clockwise, with repeated and collinear vertices removed.

    Raises
    ------
    ValueError
        With a message ``expected ..., got ...`` when fewer than 3 distinct vertices
        remain, the area is (numerically) zero, or two edges intersect.
    """
    p = np.asarray(vertices, dtype=float)
    scale = max(float(np.ptp(p, axis=0).max()) if len(p) else 0.0, 1e-300)
    tol = 1e-12 * scale * scale
    # drop repeated and collinear vertices (they add nothing and confuse ear clipping)
    if len(p):
        step = np.linalg.norm(p - np.roll(p, 1, axis=0), axis=1)
        p = p[step > 1e-12 * scale] if len(p) > 1 else p
    while len(p) >= 3:
        turn = _cross(np.roll(p, 1, axis=0), p, np.roll(p, -1, axis=0))
        keep = np.abs(turn) > tol
        if keep.all():
            break
        p = p[keep]
    if len(p) < 3:
        raise ValueError("expected a polygon with at least 3 non-collinear vertices")
    k = len(p)
    for i in range(k if not _turns_once(p) else 0):
        for j in range(i + 1, k):
            if j == i + 1 or (i == 0 and j == k - 1):
                continue  # neighbouring edges share a vertex by construction
            if _segments_cross(p[i], p[(i + 1) % k], p[j], p[(j + 1) % k], tol):
                raise ValueError(f"expected a simple polygon, got edges {i} and {j} that intersect")
    area = polygon_area(p)
    if abs(area) <= 1e-9 * scale * scale:
        raise ValueError(f"expected a polygon with non-zero area, got area {area:.3g}")
    if area < 0:
        p = p[::-1].copy()
    return p


def _turns_once(p: NDArray) -> bool:
    """True when every corner turns the same way and the turns add up to one full turn:
    a convex polygon, necessarily simple, so the O(k^2) edge-pair test can be skipped."""
    edge = np.roll(p, -1, axis=0) - p
    nxt = np.roll(edge, -1, axis=0)
    cross = edge[:, 0] * nxt[:, 1] - edge[:, 1] * nxt[:, 0]
    if not ((cross > 0).all() or (cross < 0).all()):
        return False
    turning = np.arctan2(cross, (edge * nxt).sum(axis=1)).sum()
    return bool(abs(abs(turning) - 2.0 * np.pi) < 1e-6)


def _is_convex(p: NDArray) -> bool:
    turn = _cross(np.roll(p, 1, axis=0), p, np.roll(p, -1, axis=0))
    return bool((turn >= -1e-12 * float(np.ptp(p, axis=0).max()) ** 2).all())


def convex_pieces(vertices: ArrayLike) -> list[NDArray[np.float64]]:
    """Split a simple polygon into convex counter-clockwise pieces covering it exactly.

    Parameters
    ----------
    vertices : array_like, shape (k, 2)
        A simple polygon, as accepted by :func:`simple_polygon`.

    Returns
    -------
    list of ndarray, each shape (m_i, 2)
        Convex polygons with disjoint interiors whose union is the input polygon; a convex
        input is returned as one piece.
    """
    p = simple_polygon(vertices)
    if _is_convex(p):
        return [p]
    # ear clipping on vertex indices
    remaining = list(range(len(p)))
    triangles: list[list[int]] = []
    guard = 0
    while len(remaining) > 3:
        guard += 1
        if guard > 10 * len(p) ** 2:  # pragma: no cover - impossible for a simple polygon
            raise ValueError("expected a simple polygon, ear clipping did not terminate")
        m = len(remaining)
        for t in range(m):
            i0, i1, i2 = remaining[t - 1], remaining[t], remaining[(t + 1) % m]
            a, b, c = p[i0], p[i1], p[i2]
            if _cross(a, b, c) <= 0:
                continue  # reflex vertex
            others = p[[r for r in remaining if r not in (i0, i1, i2)]]
            inside = (
                (_cross(a, b, others) >= 0)
                & (_cross(b, c, others) >= 0)
                & (_cross(c, a, others) >= 0)
            )
            if not inside.any():
                triangles.append([i0, i1, i2])
                remaining.pop(t)
                break
    triangles.append(remaining)
    # Hertel-Mehlhorn: remove diagonals while both sides stay convex
    pieces = [list(t) for t in triangles]
    merged = True
    while merged:
        merged = False
        for u in range(len(pieces)):
            for v in range(u + 1, len(pieces)):
                joined = _join(pieces[u], pieces[v])
                if joined is not None and _is_convex(p[joined]):
                    pieces[u] = joined
                    pieces.pop(v)
                    merged = True
                    break
            if merged:
                break
    return [p[q] for q in pieces]


def _join(a: list[int], b: list[int]) -> list[int] | None:
    """Union of two CCW index polygons sharing exactly one edge, or None."""
    na, nb = len(a), len(b)
    for i in range(na):
        x, y = a[i], a[(i + 1) % na]
        for j in range(nb):
            if b[j] == y and b[(j + 1) % nb] == x:
                # walk a from y round to x, then b from x round to y (excluding shared ends)
                out = [a[(i + 1 + k) % na] for k in range(na)]  # starts at y, ends at x
                out += [b[(j + 2 + k) % nb] for k in range(nb - 2)]
                return out
    return None
