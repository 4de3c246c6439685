"""Planning with OMPL: the KC motion validator, edge certificates, planners, verification.

:mod:`.certificate` and :mod:`.verify` do not import OMPL; :mod:`.validator`,
:mod:`.states` and :mod:`.problem` are the thin OMPL adapters.
"""

from kcplan.planning.certificate import DEFAULT_LADDER, EdgeCertifier, GuardLadder
from kcplan.planning.validator import KCMotionValidator

__all__ = ["DEFAULT_LADDER", "EdgeCertifier", "GuardLadder", "KCMotionValidator"]
