"""Where along a path its feed is limited: the bottleneck waypoint, ties to the earlier.

mu_path is the least V_max along the path (dtf.md section 5). Where several waypoints share it
to the last bits (repeated geometry: the same corner cut on several levels binds joint 1 at the
same V_max on each), the bottleneck is the earliest of them: a waypoint takes the bottleneck
over only where its V_max is below every earlier waypoint's by more than
:data:`solver.core.codes.TIE_RTOL` (relative), as the map kernels' running minimum
(solver/kernels/fixed_follow.py, free_follow.py) decides it, waypoint by waypoint. So a map
cell and an evaluation of the same placement, whose V_max may differ in the last bit, name
the same waypoint.
"""

from __future__ import annotations

import numpy as np

from solver.core.codes import TAKES_OVER

__all__ = ["bottleneck_waypoints"]


def bottleneck_waypoints(v_max: np.ndarray) -> np.ndarray:
    """The bottleneck waypoint of V_max along its last axis (an integer array of the others).

    The last waypoint whose V_max is below TAKES_OVER times the least before it (0 where none
    is). As in the kernels' comparisons, a NaN V_max is never below anything and is skipped by
    the least so far, and a NaN at the first waypoint keeps the bottleneck there.
    """
    v = np.asarray(v_max, dtype=float)
    if v.shape[-1] <= 1:
        return np.zeros(v.shape[:-1], dtype=np.int64)
    least_before = np.fmin.accumulate(v, axis=-1)[..., :-1]
    takes_over = (v[..., 1:] < least_before * TAKES_OVER) & ~np.isnan(v[..., :1])
    last = v.shape[-1] - 1 - np.argmax(takes_over[..., ::-1], axis=-1)
    return np.where(takes_over.any(axis=-1), last, 0).astype(np.int64)
