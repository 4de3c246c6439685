"""Importers of public benchmark maps into kcplan scenarios.

:mod:`~kcplan.maps.hrm` (Highway RoadMap CSV maps), :mod:`~kcplan.maps.movingai` (Moving AI
grid maps), :mod:`~kcplan.maps.superquadric` (outer and inner polytopes of superquadrics).
"""


class MapImportError(ValueError):
    """A map cannot be imported; the one-line message names the file and the field."""
