"""Where an edge is decided: certificates, guards, and the certifiers that combine them.

A *guard* (:mod:`.guard`) is what one query at a pose proves about the space around it;
each certificate (:mod:`.certificates`: the clearance ball, the paper's polytope ``P_eps``
from :mod:`.ladder`, the free region) turns a guard into a stretch of the edge proved
free; :class:`~.certifier.EdgeCertifier` (rigid robots) and
:class:`~.arm_certifier.ArmEdgeCertifier` (arms) combine them, the one place each that
does so, with their compiled twins behind :mod:`.kernel`; :mod:`.certifiers` chooses a
robot's certifier once. Nothing here imports OMPL: :mod:`kcplan.planning` is where the
planners call it (and :mod:`kcplan.planning.lazy` screens a tree's edges, certifying only
the path it returns).
"""

from kcplan.certification.certifier import CERTIFICATE_SETS, EdgeCertifier
from kcplan.certification.guard import Guard, GuardCache
from kcplan.certification.ladder import DEFAULT_LADDER, GuardLadder

__all__ = [
    "CERTIFICATE_SETS",
    "DEFAULT_LADDER",
    "EdgeCertifier",
    "Guard",
    "GuardCache",
    "GuardLadder",
]
