"""Where a path is made: OMPL's planners with the KC motion validator, and the compiled loop.

:mod:`.validator`, :mod:`.states`, :mod:`.setups` (what each robot kind puts into OMPL)
and :mod:`.problem` (:func:`~.problem.plan`, the same for every kind) are the thin OMPL
adapters; :mod:`.lazy` screens a tree's edges and certifies only the path it returns;
:mod:`.native` runs an arm's planning loop in the compiled kernel instead
(``kc-rrtconnect-native``), with no OMPL or Python per edge; :mod:`.names` lists the
planners without loading OMPL; :mod:`.verify` checks a path gap-free, independent of the
certificates. Where an edge is decided is :mod:`kcplan.certification`; what is done to a
path once found (blends, timing) is :mod:`kcplan.trajectory`.
"""

from kcplan.certification import (
    CERTIFICATE_SETS,
    DEFAULT_LADDER,
    EdgeCertifier,
    Guard,
    GuardCache,
    GuardLadder,
)
from kcplan.planning.validator import KCMotionValidator

# the certification's names, where they were before it had a package of its own
__all__ = [
    "CERTIFICATE_SETS",
    "DEFAULT_LADDER",
    "EdgeCertifier",
    "Guard",
    "GuardCache",
    "GuardLadder",
    "KCMotionValidator",
]
