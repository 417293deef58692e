"""A folder for numba's disk cache where its own rule finds none (a locked-down installation).

numba caches compiled functions (``cache=True``) beside their sources, else in the user's cache
folder (``~/.cache/numba``); where neither can be written (the package installed read-only and
run by an account whose home cannot be written: a service account, a locked-down CAM
workstation), it raised at the first decorated function's import, so every command and the
service's start ended in a traceback (exit 1), ``--help`` included (stop 61's CLI audit). There
this module gives numba a private folder of the temporary directory (named NUMBA_CACHE_DIR for
the process and its children, such as the kernel compiler's), kept across runs where it can
be: the caller says so (:data:`FALLBACK`; the CLI on stderr, the service in its start log).
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
import threading
from collections.abc import Callable, Iterator
from pathlib import Path

import numba.core.config
import numba.core.event

from solver.core.compiled_cache import numba_cache_folder

FALLBACK: Path | None = None
"""The folder given to numba by :func:`settle_cache_folder`, None where numba's rule found one."""


def settle_cache_folder(source: Path, temporary: Path | None = None) -> Path | None:
    """Give numba a cache folder where it finds none for ``source``; return it, else None.

    Nothing changes where NUMBA_CACHE_DIR is set or numba's own rule finds a folder it can
    write (:func:`numba_cache_folder`). Otherwise the folder is ``dtf-placement-kernels-<uid>``
    in the temporary directory (:func:`private_folder`: never another account's, whose cached
    machine code would be run).

    Args:
        source: a source file of the package whose functions numba caches.
        temporary: the temporary directory (default :func:`tempfile.gettempdir`).
    """
    global FALLBACK
    if os.environ.get("NUMBA_CACHE_DIR") or numba_cache_folder(source) is not None:
        return None
    folder = private_folder("dtf-placement-kernels", temporary)
    if folder is None:
        return None  # no temporary directory either: numba says so at the first function
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
    numba.core.config.CACHE_DIR = str(folder)  # numba read its settings at its import
    FALLBACK = folder
    return folder


def private_folder(name: str, temporary: Path | None = None) -> Path | None:
    """``<name>-<uid>`` in the temporary directory, private to this account; None if none.

    Made with mode 0700 where missing; one that exists but is not a folder of this account, or
    can be written by others, is not used (what it holds would be run or read as this
    account's), and a new private folder (``tempfile.mkdtemp``, not kept) is made instead.

    Args:
        name: the folder's name, before the account's number.
        temporary: the temporary directory (default :func:`tempfile.gettempdir`).
    """
    base = temporary if temporary is not None else Path(tempfile.gettempdir())
    uid = os.getuid() if hasattr(os, "getuid") else 0
    folder = base / f"{name}-{uid}"
    try:
        folder.mkdir(mode=0o700, exist_ok=True)
        status = folder.lstat()
        private = stat.S_ISDIR(status.st_mode) and status.st_uid == uid
        if not private or status.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
            folder = Path(tempfile.mkdtemp(prefix=f"{name}-", dir=base))
    except OSError:
        return None
    return folder


class _FirstCompile(numba.core.event.Listener):  # type: ignore[misc]  # numba has no stubs
    """Calls ``say`` once, when numba starts compiling a function (not loading it from a cache)."""

    def __init__(self, say: Callable[[], None]) -> None:
        self.say, self.said, self.lock = say, False, threading.Lock()

    def on_start(self, event: numba.core.event.Event) -> None:
        with self.lock:
            first, self.said = not self.said, True
        if first:
            self.say()

    def on_end(self, event: numba.core.event.Event) -> None:
        pass


@contextlib.contextmanager
def on_first_compile(say: Callable[[], None]) -> Iterator[None]:
    """Within the block, ``say()`` once if numba compiles anything (a cache it did not find).

    numba's ``numba:compile`` event is broadcast only when a function is compiled, not when
    its machine code is loaded from the disk cache: the first use of the kernels in an
    installation or an account compiles them for one to two minutes, which a command then says.
    """
    listener = _FirstCompile(say)
    numba.core.event.register("numba:compile", listener)
    try:
        yield
    finally:
        numba.core.event.unregister("numba:compile", listener)
