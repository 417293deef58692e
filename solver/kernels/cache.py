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
from solver.core.compiled_cache import drop_stale_caches
from solver.families.kernels import KERNEL_SOURCES


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
    drop_stale_caches(files[-1].stem, files, files)
