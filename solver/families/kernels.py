"""The compiled pose kernels of the closed-form families behind one call (for the map kernel).

A compiled function cannot take another compiled function as an argument and still be cached
on disk (numba recompiles it in every process), so the families' pose kernels are reached
through this one dispatcher on a family code. A new closed-form family adds its kernel here
and names its code in its :class:`solver.families.base.ClosedFormFamily` subclass.
"""

from __future__ import annotations

from numba import njit

from solver.families.opw.kernel import opw_pose
from solver.families.ur.kernel import ur_pose

UR_KERNEL = 0
OPW_KERNEL = 1


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def pose_kernel(family, par, rot, pos, twist, tool, need, cq, sq, status, qd):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """IK on all branches of one flange pose and J^-1 t on each, for the family ``family``.

    Arguments after ``family`` as :func:`solver.families.ur.kernel.ur_pose`.
    """
    if family == UR_KERNEL:
        ur_pose(par, rot, pos, twist, tool, need, cq, sq, status, qd)
    else:
        opw_pose(par, rot, pos, twist, tool, need, cq, sq, status, qd)
