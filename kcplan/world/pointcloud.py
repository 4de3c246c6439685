"""Sensed points as obstacles: point-cloud files and depth images read into ``(N, 3)``
arrays, and the vectorised steps a cloud goes through before planning (dropping
non-finite points, cropping, a voxel filter with a distance guarantee, removing the
robot's own points).

Everything here is numpy in, numpy out, with no Python loop over points. The readers
raise :class:`PointCloudError` with a one-line message without a file prefix (the
scenario loader, :mod:`kcplan.world.scenario`, prefixes ``FILE: FIELD:``); the
libraries that parse the formats (trimesh for PLY, pypcd4 for PCD, Pillow for PNG) are
imported only when a file of theirs is read. Coordinates are in the unit of the data
(metres for depth images; a scenario's own unit otherwise).

The camera convention of :func:`unproject_depth` is ROS's optical frame: z forward
(along the optical axis), x right, y down in the image.
"""

from __future__ import annotations

import io
import math
import os
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "CLOUD_KINDS",
    "MAX_CLOUD_BYTES",
    "MAX_DEPTH_PIXELS",
    "POINT_FORMATS",
    "CloudInfo",
    "PointCloudError",
    "crop_box_mask",
    "crop_sphere_mask",
    "drop_nonfinite",
    "ellipsoid_self_filter_mask",
    "hull_self_filter_mask",
    "read_depth_image",
    "read_point_file",
    "sample_surface_points",
    "unproject_depth",
    "voxel_filter",
]

MAX_CLOUD_BYTES = 512 * 2**20
"""Largest point-cloud or depth-image file read, in bytes (a guard against exhausting
memory: 44 million float32 points of a binary PLY)."""
MAX_DEPTH_PIXELS = 50_000_000
"""Largest depth image read, in pixels (PNG compresses a constant image to almost
nothing: the size is checked before the pixels are decoded)."""
CLOUD_KINDS = ("pointcloud", "depth")
"""The scenario obstacle kinds whose points are sensed: a cloud, or a depth image's."""
POINT_FORMATS = (".ply", ".pcd", ".xyz", ".npy")
"""File extensions :func:`read_point_file` reads (case-insensitive)."""
DEPTH_FORMATS = (".png", ".npy")
"""File extensions :func:`read_depth_image` reads (case-insensitive)."""
_PAIRS_PER_CHUNK = 1 << 20
"""Point-facet pairs evaluated at once by the self filters (bounds temporary memory)."""


class PointCloudError(ValueError):
    """A point cloud or depth image that cannot be used; ``str(err)`` is one line saying
    what was expected and what was found, without the file's name (the caller adds it)."""


@dataclass(frozen=True, kw_only=True)
class CloudInfo:
    """What a cloud obstacle went through, for summaries (counts of points).

    Attributes
    ----------
    source : str
        The file as written in the scenario, ``"inline"`` for listed points, or the depth
        image's name with its size (``"d.png (640x480 depth image)"``).
    points_read : int
        Points in the file (listed, or unprojected from the image's valid pixels).
    nonfinite : int
        Points dropped because a coordinate was NaN or infinite.
    cropped : int
        Points dropped by the crop region.
    filtered : int
        Points dropped by the voxel filter.
    self_filtered : int
        Points dropped as the robot's own (the world builder's self filter; 0 before).
    point_radius : float
        The radius of one sensed point (sensor noise and the surface between samples).
    spacing : float
        The voxel filter's guarantee (every point read is within ``spacing`` of a point
        kept); 0 when unfiltered.
    radius : float
        The radius planned with around every kept point: ``point_radius + spacing``.
    read_seconds, filter_seconds : float
        Wall time spent reading (and unprojecting), and cropping and filtering.
    self_filter : float or None
        The self filter's padding the scenario asks for, None for none.
    """

    source: str
    points_read: int
    nonfinite: int
    cropped: int
    filtered: int
    self_filtered: int = 0
    point_radius: float
    spacing: float
    radius: float
    read_seconds: float
    filter_seconds: float
    self_filter: float | None = None

    @property
    def kept(self) -> int:
        """Points left for planning."""
        return self.points_read - self.nonfinite - self.cropped - self.filtered - self.self_filtered

    def summary(self) -> str:
        """One line, e.g. ``scan.ply: 120,000 points read, 3 non-finite dropped, 80,000
        kept after a 0.01 voxel filter (planned with radius 0.0125 = point radius 0.0025
        + spacing 0.01)``."""
        parts = [f"{self.source}: {self.points_read:,} points read"]
        if self.nonfinite:
            parts.append(f"{self.nonfinite:,} non-finite dropped")
        if self.cropped:
            parts.append(f"{self.cropped:,} cropped")
        if self.self_filtered:
            parts.append(f"{self.self_filtered:,} on the robot dropped")
        kept = f"{self.kept:,} kept"
        if self.spacing > 0:
            kept += f" after a {self.spacing:g} voxel filter"
            why = (
                f"radius {self.radius:g} = point radius {self.point_radius:g} "
                f"+ spacing {self.spacing:g}"
            )
        else:
            why = f"radius {self.radius:g}, the point radius"
        parts.append(kept)
        return ", ".join(parts) + f" (planned with {why})"


def _suffix(path: str | os.PathLike) -> str:
    return Path(path).suffix.lower()


def _check_size(path: str | os.PathLike) -> None:
    try:
        size = os.path.getsize(path)
    except OSError as err:
        raise PointCloudError(f"expected a readable file, got {err.strerror or err}") from None
    if size > MAX_CLOUD_BYTES:
        raise PointCloudError(f"expected a file of at most {MAX_CLOUD_BYTES:,} bytes, got {size:,}")


def _reason(err: BaseException) -> str:
    """The first line of a library's exception, for a one-line message."""
    lines = str(err).strip().splitlines()
    text = lines[0] if lines else ""
    return f"{type(err).__name__}: {text}" if text else type(err).__name__


def _as_points(array: NDArray, what: str) -> NDArray[np.float64]:
    """``array`` as an ``(N, 3)`` float64 array (the first 3 columns of ``(N, >=3)``)."""
    if array.dtype.names is not None:  # a structured array with fields x, y, z
        names = set(array.dtype.names)
        if not {"x", "y", "z"} <= names or array.ndim != 1:
            raise PointCloudError(
                f"expected an N x 3 array or a 1-D record array with fields x, y, z, got "
                f"fields {', '.join(array.dtype.names)} of shape {array.shape}"
            )
        array = np.column_stack([array["x"], array["y"], array["z"]])
    if array.dtype.kind not in "iuf":
        raise PointCloudError(f"expected {what} of real numbers, got dtype {array.dtype}")
    if array.ndim != 2 or array.shape[1] < 3:
        raise PointCloudError(f"expected an N x 3 array, got shape {tuple(array.shape)}")
    return np.ascontiguousarray(array[:, :3], dtype=np.float64)


def read_point_file(path: str | os.PathLike) -> NDArray[np.float64]:
    """Read the points of a point-cloud file.

    Parameters
    ----------
    path : path-like
        ``.ply`` (ASCII or binary; a mesh gives its vertices, every one as written),
        ``.pcd`` (ASCII, binary or binary_compressed; fields ``x``, ``y``, ``z``, others
        ignored), ``.xyz`` (text, whitespace- or comma-separated, the first three
        columns; ``#`` starts a comment) or ``.npy`` (an ``(N, >=3)`` array, or a record
        array with fields ``x``, ``y``, ``z``; no pickles).

    Returns
    -------
    ndarray of float64, shape (N, 3)
        The points as stored (non-finite ones included: see :func:`drop_nonfinite`);
        ``N`` may be 0.

    Raises
    ------
    PointCloudError
        An unknown extension, a file too large, unreadable or malformed, or an array of
        the wrong shape; one line, without the file's name.
    """
    suffix = _suffix(path)
    if suffix not in POINT_FORMATS:
        raise PointCloudError(
            f"expected a .ply, .pcd, .xyz or .npy file, got {suffix or 'no extension'!r}"
        )
    _check_size(path)
    reader = {".ply": _read_ply, ".pcd": _read_pcd, ".xyz": _read_xyz, ".npy": _read_npy}
    try:
        return reader[suffix](path)
    except PointCloudError:
        raise
    except MemoryError:
        raise PointCloudError("expected a cloud that fits in memory, got too many points") from None
    except Exception as err:  # the parsers raise anything from KeyError to pydantic's
        name = suffix[1:].upper()
        raise PointCloudError(f"expected a valid {name} file, got {_reason(err)}") from None


def _read_ply(path: str | os.PathLike) -> NDArray[np.float64]:
    import trimesh

    with open(path, "rb") as handle:
        magic = handle.read(16)
    if not magic.startswith(b"ply"):
        got = magic.split(b"\n")[0].decode("ascii", errors="replace")
        raise PointCloudError(f"expected a PLY file (starting with 'ply'), got {got!r}")

    # process=False keeps every vertex as written (processing merges duplicates and
    # drops those no face uses)
    loaded = trimesh.load(os.fspath(path), file_type="ply", process=False)
    if isinstance(loaded, trimesh.Scene):  # what trimesh makes of a PLY without vertices
        parts = [np.asarray(g.vertices) for g in loaded.geometry.values() if hasattr(g, "vertices")]
        vertices = np.concatenate(parts) if parts else np.zeros((0, 3))
    elif hasattr(loaded, "vertices"):
        vertices = np.asarray(loaded.vertices)
    else:
        raise PointCloudError(f"expected PLY vertices, got a {type(loaded).__name__}")
    return _as_points(vertices if vertices.size else np.zeros((0, 3)), "vertices")


def _read_pcd(path: str | os.PathLike) -> NDArray[np.float64]:
    from pypcd4 import PointCloud

    try:
        cloud = PointCloud.from_path(os.fspath(path))
    except Exception as err:
        if type(err).__name__ != "ValidationError":  # pydantic's, on the header
            raise
        raise PointCloudError(
            "expected a PCD header with FIELDS, SIZE, TYPE, COUNT, WIDTH, POINTS and DATA"
        ) from None
    fields = tuple(cloud.fields)
    if not {"x", "y", "z"} <= set(fields):
        raise PointCloudError(f"expected PCD fields x, y and z, got {' '.join(fields)}")
    return _as_points(np.asarray(cloud.numpy(("x", "y", "z"))), "fields x, y, z")


def _read_xyz(path: str | os.PathLike) -> NDArray[np.float64]:
    text = Path(path).read_bytes().decode("utf-8", errors="replace").replace(",", " ")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # "input contained no data"
        try:
            array = np.loadtxt(io.StringIO(text), usecols=(0, 1, 2), ndmin=2, comments="#")
        except ValueError as err:
            raise PointCloudError(
                f"expected rows of at least 3 numbers, got {_reason(err).split(': ', 1)[-1]}"
            ) from None
    return _as_points(array, "columns")


def _read_npy(path: str | os.PathLike) -> NDArray[np.float64]:
    try:
        array = np.load(os.fspath(path), allow_pickle=False)
    except ValueError as err:
        if "pickle" in str(err).lower():
            raise PointCloudError("expected a numeric array, got Python objects") from None
        raise
    if not isinstance(array, np.ndarray):
        raise PointCloudError(f"expected one array (.npy), got {type(array).__name__}")
    return _as_points(array, "an array")


def read_depth_image(path: str | os.PathLike, depth_scale: float = 0.001) -> NDArray[np.float64]:
    """Read a depth image in metres.

    Parameters
    ----------
    path : path-like
        A 16-bit grayscale PNG (Pillow mode ``I;16``, or ``I``) of raw depth values, or a
        ``.npy`` 2-D float array already in metres.
    depth_scale : float
        Metres per raw PNG unit (0.001: millimetres, as most RGB-D cameras write); not
        applied to ``.npy`` images.

    Returns
    -------
    ndarray of float64, shape (H, W)
        Depth along the optical axis in metres (0, NaN or infinite where the sensor saw
        nothing; :func:`unproject_depth` skips those pixels).

    Raises
    ------
    PointCloudError
        An unknown extension, an unreadable image, an image of another mode (8-bit,
        colour: the message names it), too many pixels, or a non-2-D or integer array.
    """
    suffix = _suffix(path)
    if suffix not in DEPTH_FORMATS:
        raise PointCloudError(
            f"expected a 16-bit .png or a .npy depth image, got {suffix or 'no extension'!r}"
        )
    _check_size(path)
    try:
        if suffix == ".png":
            return _read_png_depth(path, depth_scale)
        array = np.load(os.fspath(path), allow_pickle=False)
    except PointCloudError:
        raise
    except MemoryError:
        raise PointCloudError("expected an image that fits in memory") from None
    except Exception as err:
        what = "16-bit PNG" if suffix == ".png" else "depth array (.npy)"
        raise PointCloudError(f"expected a valid {what}, got {_reason(err)}") from None
    if not isinstance(array, np.ndarray) or array.ndim != 2 or array.dtype.kind != "f":
        got = (
            f"shape {tuple(array.shape)} of dtype {array.dtype}"
            if isinstance(array, np.ndarray)
            else type(array).__name__
        )
        raise PointCloudError(f"expected a 2-D float array of depths in metres, got {got}")
    if array.size == 0 or array.size > MAX_DEPTH_PIXELS:
        raise PointCloudError(
            f"expected 1 to {MAX_DEPTH_PIXELS:,} pixels, got shape {tuple(array.shape)}"
        )
    return np.ascontiguousarray(array, dtype=np.float64)


_MODES = {
    "1": "1-bit black and white",
    "L": "8-bit grayscale",
    "LA": "8-bit grayscale with alpha",
    "P": "8-bit palette",
    "RGB": "8-bit colour",
    "RGBA": "8-bit colour with alpha",
}


def _read_png_depth(path: str | os.PathLike, depth_scale: float) -> NDArray[np.float64]:
    from PIL import Image

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)  # checked below
        with Image.open(os.fspath(path)) as image:
            if image.format != "PNG":
                raise PointCloudError(f"expected a PNG image, got a {image.format} image")
            mode = image.mode
            if not (mode == "I" or mode.startswith("I;16")):
                kind = f" ({_MODES[mode]})" if mode in _MODES else ""
                raise PointCloudError(
                    f"expected a 16-bit grayscale PNG (mode I;16), got mode {mode}{kind}"
                )
            width, height = image.size
            if not 0 < width * height <= MAX_DEPTH_PIXELS:
                raise PointCloudError(
                    f"expected 1 to {MAX_DEPTH_PIXELS:,} pixels, got {width}x{height}"
                )
            raw = np.asarray(image)
    return raw.astype(np.float64) * float(depth_scale)


def unproject_depth(
    depth: ArrayLike, fx: float, fy: float, cx: float, cy: float, max_range: float
) -> NDArray[np.float64]:
    """The points a depth image sees, in the camera's optical frame (pinhole model).

    The pixel in column ``u`` and row ``v`` with depth ``z`` is the point
    ``((u - cx) z / fx, (v - cy) z / fy, z)``: ROS's optical frame, z forward, x right,
    y down. Pixels whose depth is 0, negative, NaN, infinite or beyond ``max_range``
    see nothing and are skipped.

    Parameters
    ----------
    depth : array_like, shape (H, W)
        Depth along the optical axis, in metres (:func:`read_depth_image`).
    fx, fy : float
        Focal lengths in pixels (positive).
    cx, cy : float
        Principal point in pixels (column, row).
    max_range : float
        Largest depth kept, in metres.

    Returns
    -------
    ndarray of float64, shape (N, 3)
        One point per valid pixel, in row-major pixel order.
    """
    depth = np.asarray(depth, dtype=np.float64)
    if depth.ndim != 2:
        raise ValueError(f"expected a 2-D depth image, got shape {depth.shape}")
    if not (fx > 0 and fy > 0):
        raise ValueError(f"expected positive focal lengths, got fx={fx}, fy={fy}")
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(depth) & (depth > 0) & (depth <= max_range)
    v, u = np.nonzero(valid)
    z = depth[v, u]
    points = np.empty((len(z), 3))
    points[:, 0] = (u - cx) * z / fx
    points[:, 1] = (v - cy) * z / fy
    points[:, 2] = z
    return points


def drop_nonfinite(points: ArrayLike) -> tuple[NDArray[np.float64], int]:
    """The points whose three coordinates are finite, and how many others were dropped.

    Parameters
    ----------
    points : array_like, shape (N, 3)

    Returns
    -------
    points : ndarray of float64, shape (M, 3)
        The finite points, in their order.
    dropped : int
        ``N - M``.
    """
    points = np.asarray(points, dtype=np.float64)
    finite = np.isfinite(points).all(axis=1)
    kept = points if finite.all() else points[finite]
    return np.ascontiguousarray(kept), int(len(points) - len(kept))


def voxel_filter(points: ArrayLike, spacing: float) -> NDArray[np.float64]:
    """Thin a cloud so that every input point lies within ``spacing`` of a kept point.

    The space is cut into cubes of side ``spacing / sqrt(3)`` (less a few rounding
    units) and one input point is kept per occupied cube (the first in input order).
    Proof of the guarantee: a point shares its cube with the point kept there, and two
    points of one cube are at most its diagonal, ``sqrt(3) x side <= spacing``, apart.
    Only input points are kept (no centroids), in their input order.

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Finite points.
    spacing : float
        The guarantee, positive, in the points' unit.

    Returns
    -------
    ndarray of float64, shape (M, 3)
        A subset of the rows of ``points``, ``M <= N``.
    """
    points = np.asarray(points, dtype=np.float64)
    if not (math.isfinite(spacing) and spacing > 0):
        raise ValueError(f"expected a positive spacing, got {spacing}")
    if len(points) < 2:
        return np.ascontiguousarray(points)
    low = points.min(axis=0)
    extent = float((points.max(axis=0) - low).max())
    scale = float(np.abs(points).max())
    # a cell's coordinate x / side is rounded (a relative 2^-52 of |x| / side, and of the
    # subtraction of low): shrink the side so that the rounding cannot widen a cell past
    # the guarantee
    side = spacing / math.sqrt(3.0)
    side /= 1.0 + 8.0 * np.finfo(float).eps * (2.0 + (scale + extent) / side)
    if extent / side > 2.0**52:
        raise ValueError(
            f"expected a spacing of at least {extent * 2.0**-50:g} for a cloud of extent "
            f"{extent:g}, got {spacing:g}"
        )
    cells = np.floor((points - low) / side).astype(np.int64)
    dims = cells.max(axis=0) + 1
    if float(dims[0]) * float(dims[1]) * float(dims[2]) < 2.0**62:
        keys = (cells[:, 0] * dims[1] + cells[:, 1]) * dims[2] + cells[:, 2]
        _, first = np.unique(keys, return_index=True)
    else:
        _, first = np.unique(cells, axis=0, return_index=True)
    first.sort()
    return np.ascontiguousarray(points[first])


def crop_box_mask(points: ArrayLike, lower: ArrayLike, upper: ArrayLike) -> NDArray[np.bool_]:
    """Which points lie in the closed box ``lower <= p <= upper`` (per coordinate).

    Parameters
    ----------
    points : array_like, shape (N, 3)
    lower, upper : array_like, shape (3,)
        The box's corners.

    Returns
    -------
    ndarray of bool, shape (N,)
        True for the points kept.
    """
    points = np.asarray(points, dtype=np.float64)
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    return ((points >= lower) & (points <= upper)).all(axis=1)


def crop_sphere_mask(points: ArrayLike, centre: ArrayLike, radius: float) -> NDArray[np.bool_]:
    """Which points lie in the closed ball of ``radius`` about ``centre``.

    Parameters
    ----------
    points : array_like, shape (N, 3)
    centre : array_like, shape (3,)
    radius : float

    Returns
    -------
    ndarray of bool, shape (N,)
        True for the points kept.
    """
    offsets = np.asarray(points, dtype=np.float64) - np.asarray(centre, dtype=float)
    return np.einsum("ij,ij->i", offsets, offsets) <= float(radius) ** 2


def hull_self_filter_mask(
    points: ArrayLike,
    hulls: Sequence[tuple[ArrayLike, ArrayLike]],
    padding: float,
) -> NDArray[np.bool_]:
    """Which points lie within ``padding`` of a convex hull (the robot's own points).

    A point is marked when its Euclidean distance to one of the solid hulls is at most
    ``padding``: it is inside, or within ``padding`` of the surface. A bounding box and
    the facets' planes first discard the points farther from a plane than ``padding``
    (the hull lies behind every facet's plane, so that is a lower bound of the distance)
    and mark those behind every plane (inside); the others get their exact distance to
    the triangles whose planes they are in front of (the closest point of a convex
    hull lies on such a facet) with :func:`trimesh.triangles.closest_point`, whose
    branch tolerance (1e-13 on squared lengths) is the only inexactness. A flat hull
    (every vertex in one plane) has no inside: its points get their distance to its
    triangles.

    Parameters
    ----------
    points : array_like, shape (N, 3)
        The cloud, in the hulls' frame.
    hulls : sequence of (vertices, triangles)
        Convex hulls: ``vertices`` ``(m, 3)`` and ``triangles`` ``(t, 3)``, indices of
        the hull's facets (orientation not needed).
    padding : float
        Distance, at least 0, in the points' unit.

    Returns
    -------
    ndarray of bool, shape (N,)
        True for the points within ``padding`` of some hull (to remove).
    """
    points = np.asarray(points, dtype=np.float64)
    if not (math.isfinite(padding) and padding >= 0):
        raise ValueError(f"expected a padding of at least 0, got {padding}")
    marked = np.zeros(len(points), dtype=bool)
    for vertices, triangles in hulls:
        vertices = np.asarray(vertices, dtype=np.float64)
        triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
        if len(triangles) == 0:
            continue
        near = np.flatnonzero(
            ~marked
            & crop_box_mask(points, vertices.min(axis=0) - padding, vertices.max(axis=0) + padding)
        )
        if len(near):
            marked[near[_near_hull(points[near], vertices, triangles, padding)]] = True
    return marked


def _near_hull(
    points: NDArray[np.float64], vertices: NDArray, triangles: NDArray, padding: float
) -> NDArray[np.bool_]:
    """:func:`hull_self_filter_mask` for one hull and points near its bounding box."""
    from trimesh.triangles import closest_point

    corners = vertices[triangles]  # (t, 3, 3)
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    lengths = np.linalg.norm(normals, axis=1)
    size = float(np.ptp(vertices, axis=0).max())
    proper = lengths > 1e-12 * size**2  # degenerate (zero-area) facets give no plane
    normals[proper] /= lengths[proper, None]
    normals[~proper] = 0.0
    offsets = np.einsum("ij,ij->i", normals, corners[:, 0])
    centre = vertices[np.unique(triangles)].mean(axis=0)
    side = normals @ centre - offsets  # < 0 for an outward normal
    normals[side > 0] *= -1.0
    offsets[side > 0] *= -1.0
    # the vertices' centroid is strictly behind every facet of a solid hull; a facet
    # whose plane passes through it is a flat hull's (both of its sides are outside)
    two_sided = proper & (np.abs(side) <= 1e-9 * size)
    solid = bool(proper.any()) and not two_sided.any()
    marked = np.zeros(len(points), dtype=bool)
    chunk = max(1, _PAIRS_PER_CHUNK // len(triangles))
    for start in range(0, len(points), chunk):  # a loop over blocks of points
        block = points[start : start + chunk]
        heights = block @ normals.T - offsets  # (b, t): signed distances to the planes
        heights[:, two_sided] = np.abs(heights[:, two_sided])
        heights[:, ~proper] = -np.inf
        bound = heights.max(axis=1)  # a lower bound of the distance to the hull
        inside = (bound <= 0.0) if solid else np.zeros(len(block), dtype=bool)
        candidates = np.flatnonzero(~inside & (bound <= padding))
        # the facets whose plane a candidate is in front of, the two-sided ones and the
        # degenerate ones (no plane; rare)
        front = (heights[candidates] > 0.0) | two_sided | ~proper
        rows, facets = np.nonzero(front)
        where = candidates[rows]
        closest = closest_point(corners[facets], block[where])
        distance = np.full(len(block), np.inf)
        np.minimum.at(distance, where, np.linalg.norm(block[where] - closest, axis=1))
        marked[start : start + chunk] = inside | (distance <= padding)
    return marked


def ellipsoid_self_filter_mask(
    points: ArrayLike,
    centres: ArrayLike,
    rotations: ArrayLike,
    semi_axes: ArrayLike,
    padding: float,
) -> NDArray[np.bool_]:
    """Which points lie inside one of the ellipsoids grown by ``padding`` on each axis.

    A point is marked when it is inside the ellipsoid with semi-axes ``a + padding``
    (same centre and axes), a set within ``padding`` of the ellipsoid ``E(a)``: its
    support function ``|diag(a + p) u| <= |diag(a) u| + p |u|`` (the triangle
    inequality) is at most that of ``E(a) + ball(p)``, and both are convex. So no point
    farther than ``padding`` is marked; points within ``padding`` of ``E(a)`` but outside
    ``E(a + p)`` (off the axes) are not.

    Parameters
    ----------
    points : array_like, shape (N, 3)
    centres : array_like, shape (k, 3)
    rotations : array_like, shape (k, 3, 3)
        Each ellipsoid's axes as the columns (local to world).
    semi_axes : array_like, shape (k, 3)
    padding : float
        At least 0, in the points' unit.

    Returns
    -------
    ndarray of bool, shape (N,)
        True for the points to remove.
    """
    points = np.asarray(points, dtype=np.float64)
    centres = np.asarray(centres, dtype=np.float64).reshape(-1, 3)
    rotations = np.asarray(rotations, dtype=np.float64).reshape(-1, 3, 3)
    axes = np.asarray(semi_axes, dtype=np.float64).reshape(-1, 3)
    if not (math.isfinite(padding) and padding >= 0):
        raise ValueError(f"expected a padding of at least 0, got {padding}")
    marked = np.zeros(len(points), dtype=bool)
    for centre, rotation, a in zip(centres, rotations, axes, strict=True):
        local = (points - centre) @ rotation  # rows: R^T (p - c)
        marked |= (np.square(local / (a + padding)).sum(axis=1)) <= 1.0
    return marked


def sample_surface_points(
    vertices: ArrayLike, triangles: ArrayLike, count: int, seed: int | None = None
) -> NDArray[np.float64]:
    """Points drawn uniformly (by area) on a triangle mesh's surface.

    The way VAMP turns MotionBenchMaker's scenes into clouds for its benchmarks (10,000
    points per object), with :func:`trimesh.sample.sample_surface`.

    Parameters
    ----------
    vertices : array_like, shape (v, 3)
    triangles : array_like of int, shape (t, 3)
    count : int
        Points to draw.
    seed : int, optional
        Seed of the random generator (the same seed gives the same points).

    Returns
    -------
    ndarray of float64, shape (count, 3)
    """
    import trimesh

    mesh = trimesh.Trimesh(
        np.asarray(vertices, dtype=np.float64), np.asarray(triangles), process=False
    )
    samples, _ = trimesh.sample.sample_surface(mesh, int(count), seed=seed)
    return np.ascontiguousarray(samples, dtype=np.float64)
