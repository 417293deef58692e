"""numba's disk cache of the compiled kernels, and the marker that says when it is stale."""

from __future__ import annotations

import sys
from pathlib import Path

import solver.kernels.acc_cells
import solver.kernels.acc_free
import solver.kernels.acc_scan
import solver.kernels.accelerations
import solver.kernels.borrow
import solver.kernels.cell
import solver.kernels.fixed_follow
import solver.kernels.free_follow
import solver.kernels.limits
import solver.kernels.positions
import solver.kernels.spin_schedule
from solver.core import codes, spatial, task
from solver.core.compiled_cache import drop_stale_caches
from solver.families.kernels import KERNEL_SOURCES
from solver.families.opw import ik as opw_ik
from solver.families.opw import parameters as opw_parameters
from solver.families.ur import dh as ur_dh
from solver.families.ur import ik as ur_ik

TAKEN_IN = (codes, spatial, task, ur_dh, ur_ik, opw_ik, opw_parameters)
"""Modules with no compiled function whose constants (or numba-compiled helpers' constants) the
map kernels build in: the reasons and ties of :mod:`solver.core.codes`, the half-turn and path
tolerances of :mod:`~solver.core.spatial` and :mod:`~solver.core.task`, the families' own. An
edit of one changes the machine code without changing any kernel's file: they are hashed too
(the upgrade audit of stop 62 changed ``codes.TAKES_OVER`` alone and got the old code's map,
59 of 126 cells with another bottleneck waypoint). tests/solver/test_compiled_caches.py holds
every marker to the modules its kernels import."""


def drop_stale_compiled_code(name: str) -> None:
    """Delete the cached machine code of module ``name``'s kernels when a callee has changed.

    numba's disk cache (``cache=True``) is keyed by the source file
    of the cached function only, but the compiled functions take their callees into themselves
    (the dispatcher :func:`solver.families.kernels.pose_block` the families' pose kernels,
    whose modules it lists in :data:`~solver.families.kernels.KERNEL_SOURCES`, and the map
    kernels the dispatcher and the helpers of :mod:`solver.kernels`): after an edit of a
    callee they would load the old code. A marker named by the hash of all those sources says
    which code the caches hold; a new hash drops the cached code of every one of them, wherever
    numba keeps it (:func:`solver.core.compiled_cache.numba_cache_folder`).
    """
    modules = (
        *KERNEL_SOURCES,
        solver.kernels.borrow,
        solver.kernels.positions,
        solver.kernels.limits,
        solver.kernels.cell,
        solver.kernels.fixed_follow,
        solver.kernels.free_follow,
        solver.kernels.accelerations,
        solver.kernels.acc_cells,
        solver.kernels.acc_free,
        solver.kernels.acc_scan,
        solver.kernels.spin_schedule,
        sys.modules[name],
    )
    files = [Path(str(module.__file__)) for module in modules]
    taken_in = [Path(str(module.__file__)) for module in TAKEN_IN]
    drop_stale_caches(files[-1].stem, [*files, *taken_in], files)
