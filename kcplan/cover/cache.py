"""A per-user cache of fitted covers, so that a scenario naming a mesh fits it once.

Entries live in ``$KCPLAN_CACHE_DIR`` (default ``$XDG_CACHE_HOME/kcplan/covers``, else
``~/.cache/kcplan/covers``), one JSON file per key: the SHA-256 of the mesh file's bytes
and of the fit's parameters (bodies, scale, shape, hull, max_offset, and the version of
that kind of fit: :data:`kcplan.cover.fit.FIT_VERSION` by volume,
:data:`kcplan.cover.fit.OFFSET_FIT_VERSION` by offset). An entry is never trusted for
soundness: its bodies and cutting tree are re-derived and checked against the mesh
(:func:`kcplan.cover.fit.check_cover`, the same hull points as the fit), and a stale,
corrupt or failing entry is refitted and replaced. :data:`BUNDLED`, the covers shipped
with kcplan, is looked up first, and its entries are checked the same way. The offset
bound of a ``max_offset`` fit (:attr:`kcplan.cover.fit.Cover.offset`) is stored with the
entry and read back as stored (re-proving it takes as long as a fit; no certificate relies
on it). A cache folder that cannot be written is not an error; the cover is then fitted
every time.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from pathlib import Path

import numpy as np

from kcplan.cover.fit import FIT_VERSION, OFFSET_FIT_VERSION, Cover, check_cover, fit_cover
from kcplan.cover.solid import Solid, read_solid
from kcplan.files import write_text_atomic
from kcplan.geometry.robot import MAX_BODIES, Body

__all__ = ["BUNDLED", "cache_folder", "cached_cover"]

BUNDLED = Path(__file__).with_name("bundled")
"""Entries shipped with kcplan (read only): the default covers of the links of
MotionBenchMaker's Panda and UR5, fitted once (about 25 and 40 minutes) so that every
machine plans with the same cover, whatever ties its floating point breaks otherwise in
the greedy fit. Its README says how they were made."""


def cache_folder() -> Path:
    """Where covers are cached (see the module docstring)."""
    if os.environ.get("KCPLAN_CACHE_DIR"):
        return Path(os.environ["KCPLAN_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(Path.home(), ".cache")
    return Path(base) / "kcplan" / "covers"


def _key(solid: Solid, bodies: int | None, scale: float, shape: str, hull: bool, max_offset) -> str:
    params = {"file": solid.digest, "bodies": bodies, "scale": scale, "shape": shape}
    version = FIT_VERSION if max_offset is None else OFFSET_FIT_VERSION
    params |= {"hull": hull, "max_offset": max_offset, "version": version}
    return hashlib.sha256(json.dumps(params, sort_keys=True).encode()).hexdigest()


def _body(spec: dict, n: int) -> Body:
    a = np.asarray(spec["semi_axes"], dtype=float)
    p = np.asarray(spec["position"], dtype=float)
    turn = np.asarray([spec["yaw"]] if n == 2 else spec["quaternion"], dtype=float)
    if a.shape != (n,) or p.shape != (n,) or turn.shape != ((1,) if n == 2 else (4,)):
        raise ValueError("body: wrong shapes")
    if not (np.isfinite(a).all() and (a > 0).all() and np.isfinite(p).all()):
        raise ValueError("body: expected finite positive semi-axes")
    if n == 3:
        norm = float(np.linalg.norm(turn))
        if not abs(norm - 1.0) < 1e-9:
            raise ValueError("body: expected a unit quaternion")
        turn = turn / norm
    return Body(a, np.concatenate([p, turn]))


def _load(file: Path, key: str, solid: Solid, shape: str) -> Cover:
    data = json.loads(file.read_text())
    if data.get("key") != key:
        raise ValueError("key: another fit")
    specs = data["bodies"]
    if not isinstance(specs, list) or not 1 <= len(specs) <= MAX_BODIES:
        raise ValueError("bodies: expected a list")
    bodies = tuple(_body(s, solid.dimension) for s in specs)
    worst = check_cover(solid, data["tree"], bodies)
    if not worst < 1.0:
        raise ValueError("bodies: a hull point lies outside its body")
    offset = float(data.get("offset", math.nan))
    note = str(data.get("note", ""))
    return Cover(solid, bodies, data["tree"], shape, 0.0, note, worst, offset)


def cached_cover(
    path: str | os.PathLike,
    bodies: int | None,
    scale: float = 1.0,
    shape: str = "ellipsoid",
    hull: bool = False,
    max_offset: float | None = None,
) -> tuple[Cover, str]:
    """The cover of the part in ``path`` by ``bodies`` bodies (or, with ``max_offset``,
    by at most ``bodies`` that stick out of it by at most ``max_offset``:
    :func:`kcplan.cover.fit.fit_cover`), from :data:`BUNDLED` or else the cache if a
    valid entry exists there, else fitted (and stored in the cache).

    Returns
    -------
    cover : Cover
    origin : str
        ``cached``, ``bundled`` (:data:`BUNDLED`), ``fitted`` or ``refitted`` (an entry
        existed but failed its check).

    Raises
    ------
    kcplan.cover.SolidError
        For a part that cannot be read or covered.
    """
    solid = read_solid(path, scale, hull)
    key = _key(solid, bodies, scale, shape, hull, max_offset)
    origin = "fitted"
    # the bundled entry first: every machine then plans with the same cover
    cache = cache_folder()
    for folder, found in ((BUNDLED, "bundled"), (cache, "cached")):
        if (folder / f"{key}.json").is_file():
            try:
                return _load(folder / f"{key}.json", key, solid, shape), found
            except (OSError, ValueError, KeyError, TypeError, AttributeError):
                origin = "refitted"
    cover = fit_cover(solid, bodies=bodies, shape=shape, max_offset=max_offset)
    entry = {"key": key, "source": os.fspath(path), "note": cover.note}
    if not math.isnan(cover.offset):
        entry["offset"] = cover.offset
    entry |= {"bodies": cover.to_spec()["bodies"], "tree": cover.tree}
    try:
        cache.mkdir(parents=True, exist_ok=True)
        write_text_atomic(cache / f"{key}.json", json.dumps(entry))
    except OSError:
        pass  # an unwritable cache only costs time
    return cover, origin
