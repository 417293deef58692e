"""The compiled hooks of the limits on the path index: a speed bound and its binding joint.

The kernels' side of the limits seam (``spec/architecture.md`` section 3): at one waypoint of
one branch, the largest feed speed a limit allows and the joint that binds it. The map kernels
take every waypoint's bound from here and never compute one themselves; a new limit (joint
accelerations, ``motion.md``) adds its hook beside these, and the kernels the call. The numpy
pipeline's limits are :mod:`solver.path.limits`; a hook equals its numpy limit number for
number (tests/solver/test_map_kernel.py, test_free_spin_kernel.py).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from solver.families.kernels import N_JOINTS


@njit(cache=True, error_model="numpy", nogil=True)
def joint_speed_bound(qd, b, w, inverse_qdot):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Joint speeds in fixed spin, the DTF: 1 / max_j |qd_j| / qdot_max_j, and its joint j.

    Sensors 2022 eq. (30) at waypoint w of branch b, qd = J^-1 t_hat (``qd``: shape (8, 6, W),
    rad per m; ``inverse_qdot``: shape (6,), s/rad, 1 / qdot_max). The first joint at a tie.
    """
    largest = -1.0
    limiting = 0
    for j in range(N_JOINTS):
        ratio = abs(qd[b, j, w]) * inverse_qdot[j]
        if ratio > largest:
            largest = ratio
            limiting = j
    return 1.0 / largest, limiting


@njit(cache=True, error_model="numpy", nogil=True)
def two_variable_speed(qd, qs, b, w, qdot_max):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Joint speeds in free spin: the largest s with |s a_j + sigma b_j| <= qdot_max_j, and j.

    :func:`solver.core.dtf.two_variable_speed` at waypoint w of branch b (a = qd[b, :, w],
    J^-1 t_hat; b = qs[b, :, w], J^-1 [0; z_tool]; both shape (8, 6, W); ``qdot_max`` shape
    (6,), rad/s): the least pair bound, the first pair at a tie, of the pair the joint sigma
    helps less.
    """
    best = np.inf
    first, second = 0, 1
    for j in range(N_JOINTS):
        for k in range(j + 1, N_JOINTS):
            bound = (qdot_max[j] * abs(qs[b, k, w]) + qdot_max[k] * abs(qs[b, j, w])) / abs(
                qd[b, j, w] * qs[b, k, w] - qd[b, k, w] * qs[b, j, w]
            )
            if bound < best:  # a NaN bound (0 / 0) is no bound
                best = bound
                first, second = j, k
    help_first = abs(qs[b, first, w]) / qdot_max[first]
    help_second = abs(qs[b, second, w]) / qdot_max[second]
    return best, first if help_first <= help_second else second
