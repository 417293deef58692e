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
TILTED = 2
"""Added to a family's code where it solves in a frame {A} tilted from {B} (an arm on a wall, a
slope or a ceiling, :class:`solver.core.spatial.BaseTurn`): its parameters are then R_A_B row by
row (9) and {A}'s origin in {B} (3, m) before the family's own (:data:`TILT_PARAMETERS`), and
:func:`pose_block` writes each block's poses in {A} before the family's kernel solves them."""
TILT_PARAMETERS = 12
POSE_ROWS = 21  # the rows of a path's poses (solver.kernels.cell.turned_poses)
# The pose kernels' work space, flat: the UR kernel's rows of fixed length (ur.SCRATCH_SIZE), the
# OPW kernel's rows as long as the path (opw.SCRATCH_ROWS a waypoint), then POSE_ROWS a waypoint
# at its end for a tilted family's poses (:func:`pose_block`).
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


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def scratch_size(n_waypoints):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The length of :func:`pose_block`'s work space for a path of ``n_waypoints``."""
    return max(SCRATCH_SIZE, SCRATCH_ROWS * n_waypoints) + POSE_ROWS * n_waypoints


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def _turned(par, x, y, z):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """R_A_B (``par``'s first nine values, row by row) times the vector (x, y, z)."""
    return (
        par[0] * x + par[1] * y + par[2] * z,
        par[3] * x + par[4] * y + par[5] * z,
        par[6] * x + par[7] * y + par[8] * z,
    )


@njit(cache=True, error_model="numpy", nogil=True, inline="always")
def _tilted(par, poses, w0, w1, scratch):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Waypoints w0..w1 of ``poses`` (in {B}) in a tilted family's frame {A}, in scratch's end.

    R_A_F = R_A_B R_B_F, p_A = R_A_B (p_B - s) for the flange and the tool point, the twist's
    two parts turned (:meth:`solver.core.spatial.BaseTurn.vectors_in` and ``points_in``, the
    same products in another order). Returns those rows as a (POSE_ROWS, W) array.
    """
    n_waypoints = poses.shape[1]
    start = scratch.shape[0] - POSE_ROWS * n_waypoints
    out = scratch[start:].reshape((POSE_ROWS, n_waypoints))
    sx, sy, sz = par[9], par[10], par[11]
    for w in range(w0, w1):
        for k in range(3):  # column k of R_B_F
            out[k, w], out[3 + k, w], out[6 + k, w] = _turned(
                par, poses[k, w], poses[3 + k, w], poses[6 + k, w]
            )
        for row in range(9, POSE_ROWS, 3):  # the flange, the twist's two parts, the tool point
            x, y, z = poses[row, w], poses[row + 1, w], poses[row + 2, w]
            if row == 9 or row == 18:  # points
                x, y, z = x - sx, y - sy, z - sz
            out[row, w], out[row + 1, w], out[row + 2, w] = _turned(par, x, y, z)
    return out


@njit(cache=True, error_model="numpy", nogil=True)
def pose_block(family, par, poses, w0, w1, need, scratch, cq, sq, status, qd):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """IK on all branches and J^-1 t on each, for waypoints w0..w1, for the family ``family``.

    Arguments after ``family`` as :func:`solver.families.ur.kernel.ur_block`; ``scratch`` of
    :func:`scratch_size`. A tilted family (``family`` >= :data:`TILTED`) solves the block's
    poses written in its frame first.
    """
    if family >= TILTED:
        turned = _tilted(par, poses, w0, w1, scratch)
        own = par[TILT_PARAMETERS:]
        if family - TILTED == UR_KERNEL:
            ur.ur_block(own, turned, w0, w1, need, scratch, cq, sq, status, qd)
        else:
            opw.opw_block(own, turned, w0, w1, need, scratch, cq, sq, status, qd)
    elif family == UR_KERNEL:
        ur.ur_block(par, poses, w0, w1, need, scratch, cq, sq, status, qd)
    else:
        opw.opw_block(par, poses, w0, w1, need, scratch, cq, sq, status, qd)
