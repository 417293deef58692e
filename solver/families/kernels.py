"""The compiled pose kernels of the closed-form families behind one call (for the map kernel).

A compiled function cannot take another compiled function as an argument and still be cached
on disk (numba recompiles it in every process), so the families' pose kernels are reached
through this one dispatcher on a family code. A new closed-form family adds its kernel here
(and its module to :data:`KERNEL_SOURCES`) and names its code in its
:class:`solver.families.base.ClosedFormFamily` subclass. The map kernels
(:mod:`solver.kernels`) import this module and no family.
"""

from __future__ import annotations

import sys
from types import ModuleType

import numpy as np
from numba import njit

from solver.families import lanes, pairs
from solver.families.opw import kernel as opw
from solver.families.ur import kernel as ur
from solver.families.ur.dh import UR_DH

UR_KERNEL = 0
OPW_KERNEL = 1
# The pose kernels' work space, flat: the UR kernel's rows of fixed length (ur.SCRATCH_SIZE), the
# OPW kernel's rows as long as the path (opw.SCRATCH_ROWS a waypoint).
SCRATCH_SIZE, SCRATCH_ROWS = ur.SCRATCH_SIZE, opw.SCRATCH_ROWS
# The pose kernels' out arrays are (N_BRANCHES, N_JOINTS, W): six-joint arms, eight branches.
N_BRANCHES, N_JOINTS = 8, 6
# The modules whose compiled code :func:`pose_block` takes into itself, callees first: a map
# kernel's disk cache is stale when one of them changes (solver.kernels.cache).
KERNEL_SOURCES: tuple[ModuleType, ...] = (pairs, lanes, ur, opw, sys.modules[__name__])


def warm_up_arm() -> tuple[int, np.ndarray]:
    """A UR5's kernel code and parameters: what the map kernels compile on before a request.

    Any arm will do, as the kernels have one signature for every family.
    """
    return UR_KERNEL, ur.kernel_parameters(UR_DH["ur5"])


@njit(cache=True, error_model="numpy", nogil=True)
def pose_block(family, par, poses, w0, w1, need, scratch, cq, sq, status, qd):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """IK on all branches and J^-1 t on each, for waypoints w0..w1, for the family ``family``.

    Arguments after ``family`` as :func:`solver.families.ur.kernel.ur_block`.
    """
    if family == UR_KERNEL:
        ur.ur_block(par, poses, w0, w1, need, scratch, cq, sq, status, qd)
    else:
        opw.opw_block(par, poses, w0, w1, need, scratch, cq, sq, status, qd)
