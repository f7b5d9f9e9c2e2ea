"""Array aliases used across footfall (shapes and units are stated where each array is documented)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

#: float64 array
FloatArray = NDArray[np.float64]
#: int64 array (indices)
IntArray = NDArray[np.int64]
#: boolean array (masks)
BoolArray = NDArray[np.bool_]

__all__ = ["BoolArray", "FloatArray", "IntArray"]
