"""Compiled kinematics of the cell sweep: link frames over a path, and its sub-steps.

The joints' frames as pinocchio's forward kinematics gives them (the model's joint placements;
revolute and prismatic joints about an axis), each robot part's capsule ends in the world, and
the path's configurations with the sub-steps between waypoints
(:meth:`solver.path.cell.checker.CellChecker.configurations`, the same floats). The robot pack
is :mod:`solver.path.cell.sweep`'s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.path.cell.kernel_cache import drop_stale_cell_kernels

drop_stale_cell_kernels()  # the kernels here take callees and constants of other modules in


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def frames(q, robot, rot, pos, turn):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The joints' world rotations (J, 3, 3) and origins (J, 3) at q, into rot and pos.

    ``turn`` (3, 3) is work space.
    """
    parent, jrot, jpos, kind, axis, qi = robot[0], robot[1], robot[2], robot[3], robot[4], robot[5]
    for i in range(3):
        pos[0, i] = 0.0
        for k in range(3):
            rot[0, i, k] = 1.0 if i == k else 0.0
    for j in range(1, len(parent)):
        p = parent[j]
        for i in range(3):
            pos[j, i] = pos[p, i]
            for k in range(3):
                pos[j, i] += rot[p, i, k] * jpos[j, k]
                rot[j, i, k] = 0.0
                for m in range(3):
                    rot[j, i, k] += rot[p, i, m] * jrot[j, m, k]
        value = q[qi[j]]
        if kind[j] == 2:
            for i in range(3):
                for k in range(3):
                    pos[j, i] += rot[j, i, k] * axis[j, k] * value
        elif kind[j] == 1:
            c, s = math.cos(value), math.sin(value)
            x, y, z = axis[j, 0], axis[j, 1], axis[j, 2]
            turn[0, 0], turn[0, 1], turn[0, 2] = (
                c + x * x * (1 - c),
                x * y * (1 - c) - z * s,
                x * z * (1 - c) + y * s,
            )
            turn[1, 0], turn[1, 1], turn[1, 2] = (
                y * x * (1 - c) + z * s,
                c + y * y * (1 - c),
                y * z * (1 - c) - x * s,
            )
            turn[2, 0], turn[2, 1], turn[2, 2] = (
                z * x * (1 - c) - y * s,
                z * y * (1 - c) + x * s,
                c + z * z * (1 - c),
            )
            for i in range(3):
                r0, r1, r2 = rot[j, i, 0], rot[j, i, 1], rot[j, i, 2]
                for k in range(3):
                    rot[j, i, k] = r0 * turn[0, k] + r1 * turn[1, k] + r2 * turn[2, k]


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def parts(q, robot, rot, pos, ends, turn):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Every robot part's capsule ends in the world at q, into ends (R, 2, 3)."""
    frames(q, robot, rot, pos, turn)
    joint, local = robot[6], robot[7]
    for r in range(len(joint)):
        j = joint[r]
        for e in range(2):
            for i in range(3):
                ends[r, e, i] = (
                    pos[j, i]
                    + rot[j, i, 0] * local[r, e, 0]
                    + rot[j, i, 1] * local[r, e, 1]
                    + rot[j, i, 2] * local[r, e, 2]
                )


@njit(cache=True, nogil=True, error_model="numpy")
def substeps(q, segment_in_pass, step):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:meth:`solver.path.cell.checker.CellChecker.configurations`, compiled (the same floats).

    Returns:
        shape (M, n), rad, the configurations; shape (M,), the waypoint each follows.
    """
    count, n = q.shape
    counts = np.ones(count, dtype=np.int64)
    for w in range(count - 1):
        if segment_in_pass[w]:
            largest = 0.0
            for j in range(n):
                largest = max(largest, abs(q[w + 1, j] - q[w, j]))
            counts[w] = max(int(np.ceil(largest / step - 1e-12)), 1)
    rows, owners = np.empty((counts.sum(), n)), np.empty(counts.sum(), dtype=np.int64)
    m = 0
    for w in range(count):
        following = min(w + 1, count - 1)
        for k in range(counts[w]):
            fraction = k / counts[w]
            for j in range(n):
                rows[m, j] = q[w, j] + fraction * (q[following, j] - q[w, j])
            owners[m] = w
            m += 1
    return rows, owners
