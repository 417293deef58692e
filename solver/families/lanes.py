"""The pose kernels' work space in lanes: rows of LANES waypoints, a constant distance apart.

Why: a family's pose kernel (:mod:`solver.families.kernels`) works level by level, each level one
loop over a block of waypoints. Over the path's own arrays, whose rows lie a run-time distance
apart, LLVM (through numba) kept those loops scalar ("too many memory checks"). In a flat work
space whose rows lie LANES values apart it sees that an iteration reads and writes no value of
another, and runs four waypoints in one set of AVX2 instructions: the same IEEE operations in
the same order, so the same bits (tests/solver/test_pose_kernels.py). A kernel copies the poses
in (:func:`lanes_in`), computes in the work space, and copies each branch's answers out
(:func:`lanes_out`). Indices into the path's arrays are unsigned (``np.uint64``): a signed index
may be negative for all numba knows, and the wrap-around it then computes also stops the
vectoriser.

The UR kernel works this way (2.5x faster on all eight branches). The OPW kernel does not: in
lanes it was 10-15 % slower (2026-12-03, 40 against 45 ns a pose-branch, the same bits). Its
elbow level writes two branches through the arm's offsets and signs, and its wrist cases
each take a square root and a division that vector lanes compute on every path.
"""

from __future__ import annotations

import numpy as np
from numba import njit

LANES = 32
"""Waypoints a kernel's pass works on: the length of a row of the work space."""
POSE_ROWS = 21
"""The rows of a pose (:func:`solver.kernels.cell.turned_poses`)."""
ANSWER_ROWS = 19
"""A branch's answer in the work space: cos (6), sin (6), J^-1 t (6), the status."""


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def lanes_in(poses, c0, n, t, first):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Copy the poses of waypoints c0..c0 + n into the work space's rows from ``first`` on."""
    u0 = np.uint64(c0)
    for r in range(POSE_ROWS):
        for k in range(n):
            t[(first + r) * LANES + k] = poses[r, u0 + np.uint64(k)]


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def lanes_out(t, first, n, c0, b, cq, sq, status, qd):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Copy branch b's answer (ANSWER_ROWS from row ``first`` on) to waypoints c0..c0 + n."""
    u0 = np.uint64(c0)
    for j in range(6):
        for k in range(n):
            w = u0 + np.uint64(k)
            cq[b, j, w] = t[(first + j) * LANES + k]
            sq[b, j, w] = t[(first + 6 + j) * LANES + k]
            qd[b, j, w] = t[(first + 12 + j) * LANES + k]
    for k in range(n):
        status[b, u0 + np.uint64(k)] = np.int64(t[(first + 18) * LANES + k])
