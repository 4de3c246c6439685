"""Pick-and-place error analysis with the KC bounds (paper Sec. 9.2).

:mod:`~kcplan.pickplace.kinematics` (KUKA LWR forward kinematics),
:mod:`~kcplan.pickplace.analysis` (error spaces, minimum inflation, parts entropy),
:mod:`~kcplan.pickplace.plots` (the figure of ``kcplan pick-place``).
"""

from kcplan.pickplace.analysis import (
    OBJECT_SEMI_AXES,
    PAPER_JOINTS,
    error_space,
    min_inflation,
    parts_entropy,
)
from kcplan.pickplace.kinematics import LWR_DH, forward_kinematics

__all__ = [
    "LWR_DH",
    "OBJECT_SEMI_AXES",
    "PAPER_JOINTS",
    "error_space",
    "forward_kinematics",
    "min_inflation",
    "parts_entropy",
]
