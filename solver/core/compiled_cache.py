"""numba's disk cache of compiled functions, dropped when a source they take in has changed.

numba keys a compiled function's disk cache (``cache=True``) by its own source file only, but
compiled functions take their callees, and the module constants those read, into themselves:
after an edit of a callee in another file a caller would load its old machine code. A marker
file named by the hash of every source the cached code depends on says which code the caches
hold; a new hash drops them. The kernel groups (the map kernels, the numeric chain, the cell)
each say which sources and which caches.

The caches are where numba puts them, found by numba's own rule (:func:`numba_cache_folder`):
``__pycache__`` beside the source, the folder ``NUMBA_CACHE_DIR`` names, or the user's cache
folder where the source's folder cannot be written (an installed copy).
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from pathlib import Path

from numba.core.caching import CompileResultCacheImpl


def numba_cache_folder(source: Path) -> Path | None:
    """The folder numba caches the compiled functions of ``source`` in; None if it cannot.

    numba's own choice (its cache locators, in its order, under the current settings), asked
    with a stand-in function whose code says it is in ``source``; numba creates the folder.
    """
    namespace: dict[str, object] = {}
    exec(compile("def stand_in():\n    pass\n", str(source), "exec"), namespace)  # noqa: S102
    try:
        cache = CompileResultCacheImpl(namespace["stand_in"])
    except (RuntimeError, OSError):  # no locator: nothing is cached
        return None
    return Path(cache.locator.get_cache_path())


def drop_stale_caches(marker: str, sources: Sequence[Path], cached: Sequence[Path]) -> None:
    """Delete the cached machine code of ``cached`` unless it was compiled from ``sources``.

    Args:
        marker: the marker's name: ``<marker>.sources-<hash>`` is written in the cache folder
            of ``cached[-1]`` (the older ones removed).
        sources: the source files the cached code depends on (their bytes are hashed in order).
        cached: the source files whose numba caches (``<stem>.*.nbi`` and ``.nbc`` in their
            cache folders) are dropped when the hash is new.

    Where numba cannot cache, or a folder cannot be written, nothing is done.
    """
    stamp = hashlib.sha256(b"".join(path.read_bytes() for path in sources)).hexdigest()[:16]
    folders = [numba_cache_folder(path) for path in cached]
    if folders[-1] is None:
        return
    current = folders[-1] / f"{marker}.sources-{stamp}"
    try:
        if current.exists():
            return
        for path, folder in zip(cached, folders, strict=True):
            if folder is None:
                continue
            for stale in [*folder.glob(f"{path.stem}.*.nbi"), *folder.glob(f"{path.stem}.*.nbc")]:
                stale.unlink(missing_ok=True)
        for old in folders[-1].glob(f"{marker}.sources-*"):
            old.unlink(missing_ok=True)
        current.touch()
    except OSError:
        return
