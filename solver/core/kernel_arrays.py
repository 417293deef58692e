"""Arrays as the compiled kernels take them: one argument type whatever the caller holds."""

from __future__ import annotations

import numpy as np


def kernel_array(a: np.ndarray, dtype: type = float) -> np.ndarray:
    """``a`` as the kernels take it: C-contiguous, writable, of ``dtype`` (a copy where not).

    numba compiles a function once per argument type, and a read-only array (a broadcast or a
    view of one, a robot's frozen limits) is another type than a writable one: arrays handed
    to the kernels are made alike, so each kernel is compiled for one signature.
    """
    return np.require(a, dtype=dtype, requirements=("C", "W"))
