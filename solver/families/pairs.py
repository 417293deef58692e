"""(cos, sin) pairs for the families' compiled pose kernels (dtf.md section 9)."""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, error_model="numpy", nogil=True, inline="always")  # type: ignore[untyped-decorator]
def unit_pair(x: float, y: float) -> tuple[float, float]:  # pragma: no cover - compiled
    """(cos, sin) of atan2(y, x); (1, 0) where both are 0, as atan2(0, 0) = 0.

    sqrt(x^2 + y^2), not math.hypot: libm's hypot made the UR pose kernel about 30 % slower;
    the lengths here are near 1 or metres, far from over- or underflow.
    """
    norm2 = x * x + y * y
    if norm2 == 0.0:
        return 1.0, 0.0
    inverse = 1.0 / math.sqrt(norm2)
    return x * inverse, y * inverse
