"""Edge certificates: sound rules that prove a stretch of an edge free from one guard.

Every certificate has a ``name`` and one method, ``reach(guard, edge, m) -> (minus,
plus)``: with the guard measured at the edge's pose ``q(m)``, every pose ``q(s)`` with
``m - minus <= s <= m + plus`` is collision-free (``s`` is OMPL's interpolation parameter,
:class:`kcplan.geometry.pose.Edge`). Certificates never query the world; they only read
the guard, whose clearances never overestimate and whose planes are exact. A certificate
that cannot prove anything returns ``(0, 0)``. The union of what several certificates
prove from one guard is an interval around ``m``, so a combination takes the largest
reach on each side (:class:`kcplan.certification.certifier.EdgeCertifier`).

============== ======================================= =================================
name           rule                                    needs
============== ======================================= =================================
``ball``       classic conservative advancement:       clearance
               points move at most
               ``|dt| + max(a) |w|`` per unit ``s``
``rotation``   the same with lever ``max(a) - min(a)`` clearance
               (support functions, see ``ball``)
``polytope``   the paper's convex lower bound          clearance, the guard ladder
               ``P_eps`` of the largest guard
               ``(1 + eps) a`` the clearance frees
``region``     separating planes of every obstacle     a region query
               piece within a horizon; an offset
               body's centre on its arc
``region-      the same with the lever rule for        a region query
lever``        offset bodies (the ablation)
============== ======================================= =================================
"""

from kcplan.certification.certificates.ball import ClearanceBall
from kcplan.certification.certificates.polytope import KCPolytope
from kcplan.certification.certificates.region import FreeRegionPlanes

__all__ = ["CERTIFICATE_NAMES", "ClearanceBall", "KCPolytope", "FreeRegionPlanes"]

CERTIFICATE_NAMES = ("ball", "rotation", "polytope", "region", "region-lever")
"""Names accepted by :class:`kcplan.certification.certifier.EdgeCertifier`."""
