"""What the views draw of a sensed obstacle (``pointcloud`` or ``depth``): its points,
thinned for display, with a label that says how many are drawn.

Every view (:mod:`kcplan.views.plots`, :mod:`kcplan.views.animation`,
:mod:`kcplan.views.html`) draws a cloud as points coloured by their height, from
:func:`cloud_points_for_display`; the thinning is for the picture only (planning uses
every point of :attr:`kcplan.world.obstacles.Obstacle.vertices`). This module imports
neither matplotlib nor plotly.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from kcplan.world.pointcloud import CLOUD_KINDS

__all__ = [
    "CLOUD_COLORMAP",
    "MAX_DRAWN_POINTS",
    "cloud_points_for_display",
    "clouds_of",
    "drawn_extent",
    "is_cloud",
    "obstacle_centre",
    "sensor_triad",
]

MAX_DRAWN_POINTS = 20_000
"""Most points drawn of one cloud (a deterministic subsample beyond: a page or a picture
of millions of points is slow to draw and no clearer)."""
CLOUD_COLORMAP = "viridis"
"""The colour map of a cloud's points by height (matplotlib's name; plotly's ``Viridis``)."""


def is_cloud(ob) -> bool:
    """Whether an obstacle is sensed points (``pointcloud`` or ``depth``)."""
    return ob.kind in CLOUD_KINDS


def clouds_of(obstacles) -> list:
    """The sensed obstacles among ``obstacles``, in order."""
    return [ob for ob in obstacles if is_cloud(ob)]


def cloud_points_for_display(ob, limit: int = MAX_DRAWN_POINTS) -> tuple[NDArray[np.float64], str]:
    """The points of a cloud obstacle to draw, and the label that says how many.

    Parameters
    ----------
    ob : kcplan.world.obstacles.Obstacle
        Of kind ``pointcloud`` or ``depth``: its ``vertices`` are the points planned with.
    limit : int
        Most points returned: beyond it, ``limit`` of them drawn at random without
        replacement by a generator of fixed seed (the same points every time), kept in
        their order.

    Returns
    -------
    points : ndarray, shape (m, 3)
        ``m = min(N, limit)`` of the ``N`` points.
    label : str
        E.g. ``cloud: 20,000 of 120,000 points (obstacles[3]: scan.ply)``.
    """
    if not is_cloud(ob):
        raise ValueError(f"{ob.label}: expected a pointcloud or depth obstacle")
    points = np.asarray(ob.vertices, dtype=float).reshape(-1, 3)
    total = len(points)
    if total > limit:
        keep = np.sort(np.random.default_rng(0).choice(total, size=limit, replace=False))
        points = points[keep]
    source = getattr(ob.cloud, "source", None) or ob.kind
    label = f"cloud: {len(points):,} of {total:,} points (obstacles[{ob.index}]: {source})"
    return points, label


def drawn_extent(obstacles, sensors: bool = True) -> NDArray[np.float64] | None:
    """``(2, 3)``: the lowest and highest coordinates of every cloud's points (all of
    them, not only those drawn) and, with ``sensors``, of every depth camera's position
    (:func:`sensor_triad`), or None without clouds: axis limits that show them."""
    clouds = []
    for ob in clouds_of(obstacles):
        clouds.append(np.asarray(ob.vertices, dtype=float).reshape(-1, 3))
        if sensors and ob.kind == "depth":
            clouds.append(np.asarray(ob.center, dtype=float).reshape(1, 3))
    clouds = [c for c in clouds if len(c)]
    if not clouds:
        return None
    return np.array([np.min([c.min(axis=0) for c in clouds], axis=0),
                     np.max([c.max(axis=0) for c in clouds], axis=0)])  # fmt: skip


def obstacle_centre(ob) -> NDArray[np.float64]:
    """Where an obstacle is, for choosing a viewpoint: its centre, a cloud's points' mean
    (a cloud's ``center`` is its sensor's position)."""
    if is_cloud(ob) and ob.vertices is not None and len(ob.vertices):
        return np.asarray(ob.vertices, dtype=float).mean(axis=0)
    return np.asarray(ob.center, dtype=float)


def sensor_triad(ob, size: float | None = None) -> tuple[NDArray[np.float64], NDArray] | None:
    """A depth camera's pose as three segments (its x, y and z axes; z is the optical
    axis), or None for other obstacles (a ``pointcloud``'s frame is where its file's
    coordinates start, not necessarily a sensor).

    Parameters
    ----------
    ob : kcplan.world.obstacles.Obstacle
    size : float, optional
        The segments' length; default 0.15 of the cloud's largest extent (at least 4
        planning radii).

    Returns
    -------
    segments : ndarray, shape (3, 2, 3)
        Each axis's start (the sensor's position) and end.
    colours : ndarray, shape (3, 3)
        RGB of the x, y and z axes (red, green, blue).
    """
    if ob.kind != "depth":
        return None
    if size is None:
        points = np.asarray(ob.vertices, dtype=float).reshape(-1, 3)
        spread = float(np.ptp(points, axis=0).max()) if len(points) else 0.0
        size = max(0.15 * spread, 4.0 * float(np.max(ob.extents)))
    origin = np.asarray(ob.center, dtype=float)
    axes = np.asarray(ob.rotation, dtype=float).T * size  # rows: the axes in the world
    segments = np.stack([np.stack([origin, origin + axis]) for axis in axes])
    return segments, np.eye(3)
