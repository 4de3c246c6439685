"""Planning with OMPL: the motion validator, edge certificates, planners, verification.

:mod:`.guard`, :mod:`.certificates`, :mod:`.certifier`, :mod:`.ladder` and :mod:`.verify`
do not import OMPL; :mod:`.validator`, :mod:`.states`, :mod:`.setups` (what each robot
kind puts into OMPL) and :mod:`.problem` (:func:`~.problem.plan`, the same for every
kind) are the thin OMPL adapters. :mod:`.native` runs an arm's planning loop in the
compiled kernel instead (``kc-rrtconnect-native``), with no OMPL or Python per edge.
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
