"""Shared hypothesis strategies for the geometry tests, and a private cover cache."""

import os
import tempfile

import numpy as np
from hypothesis import settings
from hypothesis import strategies as st

settings.register_profile("default", deadline=None, print_blob=True)
settings.load_profile("default")

# covers of mesh robots are cached per user; the tests keep theirs apart (and start cold)
os.environ["KCPLAN_CACHE_DIR"] = tempfile.mkdtemp(prefix="kcplan-test-cache-")


@st.composite
def semi_axes(draw, n: int, max_ratio: float = 5.0) -> np.ndarray:
    """Semi-axes with max/min ratio up to ``max_ratio``, largest axis in [0.5, 20]."""
    big = draw(st.floats(0.5, 20.0))
    ratios = [draw(st.floats(1.0, max_ratio)) for _ in range(n - 1)]
    return np.array(sorted([big] + [big / r for r in ratios], reverse=True))


inflations = st.floats(0.005, 1.0)
