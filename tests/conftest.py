"""Shared hypothesis strategies for the geometry tests."""

import numpy as np
from hypothesis import settings
from hypothesis import strategies as st

settings.register_profile("default", deadline=None, print_blob=True)
settings.load_profile("default")


@st.composite
def semi_axes(draw, n: int, max_ratio: float = 5.0) -> np.ndarray:
    """Semi-axes with max/min ratio up to ``max_ratio``, largest axis in [0.5, 20]."""
    big = draw(st.floats(0.5, 20.0))
    ratios = [draw(st.floats(1.0, max_ratio)) for _ in range(n - 1)]
    return np.array(sorted([big] + [big / r for r in ratios], reverse=True))


inflations = st.floats(0.005, 1.0)
