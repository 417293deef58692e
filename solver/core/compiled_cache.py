"""numba's disk cache of compiled functions, dropped when a source they take in has changed.

numba keys a compiled function's disk cache (``cache=True``, files in ``__pycache__``) by its
own source file only, but compiled functions take their callees, and the module constants those
read, into themselves: after an edit of a callee in another file a caller would load its old
machine code. A marker file named by the hash of every source the cached code depends on says
which code the caches hold; a new hash drops them. The kernel groups (the map kernels, the
numeric chain, the cell) each say which sources and which caches.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from pathlib import Path


def drop_stale_caches(marker: Path, sources: Sequence[Path], cached: Sequence[Path]) -> None:
    """Delete the cached machine code of ``cached`` unless it was compiled from ``sources``.

    Args:
        marker: the marker's folder and name: ``<marker>.sources-<hash>`` is written there (the
            older ones removed).
        sources: the source files the cached code depends on (their bytes are hashed in order).
        cached: the source files whose numba caches (``__pycache__/<stem>.*.nbi`` and
            ``.nbc``) are dropped when the hash is new.

    Where the folders cannot be written (an installed copy), numba caches elsewhere or not at
    all and nothing is done.
    """
    stamp = hashlib.sha256(b"".join(path.read_bytes() for path in sources)).hexdigest()[:16]
    current = marker.parent / f"{marker.name}.sources-{stamp}"
    try:
        if current.exists():
            return
        for path in cached:
            cache = path.parent / "__pycache__"
            for stale in [*cache.glob(f"{path.stem}.*.nbi"), *cache.glob(f"{path.stem}.*.nbc")]:
                stale.unlink(missing_ok=True)
        for old in marker.parent.glob(f"{marker.name}.sources-*"):
            old.unlink(missing_ok=True)
        marker.parent.mkdir(exist_ok=True)
        current.touch()
    except OSError:
        return
