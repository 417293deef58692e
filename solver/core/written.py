"""Values stepped from a start in the decimals they are written in, not in binary floats.

A request says ``"min": -0.25, "step": 0.02``; the floats' own sum -0.25 + 15 * 0.02 is
0.04999999999999999, which an answer then prints as X 49.999999999999986 mm. The grids of
:mod:`solver.path.capability_map` and the optimisers' coarse maps
(:mod:`solver.optimise.coarse_search`) step the same way.
"""

from __future__ import annotations

from decimal import Decimal

import numpy as np

__all__ = ["stepped_as_written"]


def stepped_as_written(first: float, step: float, count: int) -> np.ndarray:
    """``first + i * step`` for i < ``count``, each the float nearest the decimal value.

    The decimals are the floats' shortest repr (what a request's JSON says). The integers
    ``first`` and ``step`` are in their last decimal are summed exactly and divided once (IEEE
    division rounds to the nearest); where they cannot be (more than 22 decimals, or a sum or
    the stride past 2^53), the floats' sum.

    The stride counts even where only ``first`` is asked for: on a one-value axis whose bound
    is written to many decimals (``min 1e-16, step 1000``: a stride of 10^19) it is still
    multiplied into the int64 steps, and past 2^63 that was an OverflowError, a 500 on
    /v1/map, /v1/optimize and their jobs (audit 22).
    """
    written = [Decimal(repr(float(v))) for v in (first, step)]
    decimals = max(0, -min(int(w.as_tuple().exponent) for w in written))
    start, stride = (int(w.scaleb(decimals)) for w in written)
    if decimals > 22 or abs(start) + abs(stride) * max(count - 1, 1) > 2**53:  # 10^22: exact
        return first + step * np.arange(count)
    scale = float(10**decimals)  # exact
    return (start + stride * np.arange(count, dtype=np.int64)).astype(np.float64) / scale
