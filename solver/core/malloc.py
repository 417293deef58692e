"""Keep glibc from returning the map's large temporary arrays to the kernel after every use.

glibc serves blocks over its mmap threshold (128 KiB, then adapting) with mmap and unmaps them
on free, so the chunked map code, which makes and drops arrays of a few MiB many times, pays a
page fault per page each time: measured here, the ERK-size map took 0.25 s instead of 0.16 s,
depending on what had been allocated before. Raising the mmap and trim thresholds once keeps
those blocks in the heap. Elsewhere than glibc this does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools

_M_TRIM_THRESHOLD = -1  # glibc's mallopt parameters (malloc.h)
_M_MMAP_THRESHOLD = -3
_THRESHOLD_BYTES = 256 * 1024 * 1024


@functools.cache
def raise_malloc_thresholds() -> bool:
    """Raise glibc's mmap and trim thresholds to 256 MiB once; False where that is not glibc."""
    name = ctypes.util.find_library("c")
    if name is None:
        return False
    try:
        mallopt = ctypes.CDLL(name).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    return bool(
        mallopt(_M_MMAP_THRESHOLD, _THRESHOLD_BYTES)
        and mallopt(_M_TRIM_THRESHOLD, _THRESHOLD_BYTES)
    )
