"""numba's disk cache of the cell's compiled kernels, dropped when any of their sources changes.

numba keys a compiled function's disk cache (``cache=True``) by its own source file, but the cell's
kernels take their callees into themselves across modules (the batch takes the sweep, the sweep the
forward scan, the closed-form distances, the pair tables and the separation bounds) and freeze the
constants they read (``capsules.HALFSPACE``, ``fast.MARGIN``): after an edit of one of those, a
caller would load its old machine code. A marker named by the hash of every source of this package
says which code the caches hold; a new hash drops the cached code of every kernel module here (as
:mod:`solver.kernels.cache` does for the map kernels), wherever numba keeps them.
"""

from __future__ import annotations

from pathlib import Path

from solver.core.compiled_cache import drop_stale_caches

_PACKAGE = Path(__file__).resolve().parent
KERNEL_MODULES = (
    "advance",
    "batch",
    "closed_form",
    "kinematics",
    "pair_tables",
    "separation",
    "sweep",
)
"""The modules of this package with compiled functions (``@njit(cache=True)``)."""


def drop_stale_cell_kernels(package: Path = _PACKAGE) -> None:
    """Delete the cell kernels' cached machine code unless it was compiled from these sources.

    Args:
        package: the folder of the sources (this package's).
    """
    cached = [package / f"{stem}.py" for stem in KERNEL_MODULES]
    drop_stale_caches("cell_kernels", sorted(package.glob("*.py")), cached)
