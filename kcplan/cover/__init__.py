"""Sound covers of parts by ellipsoids: robots from meshes and outlines.

``read_solid`` reads a closed mesh (3D) or a simple polygon (2D); ``fit_cover`` encloses
it in K ellipsoids (or spheres) whose union provably contains it
(:mod:`kcplan.cover.partition` gives the proof); ``cached_cover`` does both once per
file and parameters. Depends on :mod:`kcplan.geometry` only (and trimesh for reading).
"""

from kcplan.cover.bodies import body_matrix, inside_union, union_volume
from kcplan.cover.cache import cache_folder, cached_cover
from kcplan.cover.fit import SHAPES, Cover, check_cover, fit_cover
from kcplan.cover.solid import Solid, SolidError, read_solid

__all__ = [
    "SHAPES",
    "Cover",
    "Solid",
    "SolidError",
    "body_matrix",
    "cache_folder",
    "cached_cover",
    "check_cover",
    "fit_cover",
    "inside_union",
    "read_solid",
    "union_volume",
]
