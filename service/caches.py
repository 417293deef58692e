"""Where the caches go when the installation and the account's home cannot be written.

The compiled kernels' folder is settled as the solver is imported
(:mod:`solver.core.cache_home`); matplotlib's here, before :mod:`service.render` imports it
(and, for the note, by :func:`cache_notes`). matplotlib keeps its settings and its font
list in ``~/.config/matplotlib`` and ``~/.cache/matplotlib``; where either cannot be written
(an account whose home is read-only) it made a new temporary folder at every start, with two
warning lines on stderr, and built its font list again each time (a warm ``dtf-place map`` took
8.4 s against 2.8 s, stop 61's CLI audit). There MPLCONFIGDIR names a private folder of the
temporary directory, kept across runs (:func:`solver.core.cache_home.private_folder`), and
:data:`FALLBACK` says so (the CLI on stderr, the service in its start log).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from solver.core import cache_home
from solver.core.cache_home import private_folder

FALLBACK: Path | None = None
"""The folder MPLCONFIGDIR was given here, None where matplotlib's own could be written."""


def _writable(folder: Path) -> bool:
    """Whether ``folder`` is (or can be made) a folder this account can write a file in."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def settle_matplotlib_folder() -> Path | None:
    """Name MPLCONFIGDIR a private temporary folder where matplotlib's own cannot be written.

    Returns the folder (the one given before, on a later call), or None where MPLCONFIGDIR is
    set or the XDG (or home) config and cache folders can be written (nothing changes).
    """
    global FALLBACK
    if FALLBACK is not None or os.environ.get("MPLCONFIGDIR"):
        return FALLBACK
    try:  # matplotlib's own rule: the XDG folders, else the home's (HOME, else the account's)
        home = Path.home()
    except RuntimeError:  # no home at all
        home = None
    if home is not None:
        config = Path(os.environ.get("XDG_CONFIG_HOME") or home / ".config") / "matplotlib"
        cache = Path(os.environ.get("XDG_CACHE_HOME") or home / ".cache") / "matplotlib"
        if _writable(config) and _writable(cache):
            return None
    folder = private_folder("dtf-placement-matplotlib")
    if folder is not None:
        os.environ["MPLCONFIGDIR"] = str(folder)
        FALLBACK = folder
    return folder


def cache_notes() -> list[str]:
    """A sentence for each cache kept in the temporary directory, not where it belongs.

    The compiled kernels' (:mod:`solver.core.cache_home`) and matplotlib's (here), moved there
    where neither the installation's folders nor the account's home could be written: the CLI
    says them on stderr, the service in its start log.
    """
    settle_matplotlib_folder()  # the same answer each call: what matplotlib would be given
    notes = (
        (cache_home.FALLBACK, "the compiled kernels are cached", "NUMBA_CACHE_DIR"),
        (FALLBACK, "matplotlib's settings and font list are kept", "MPLCONFIGDIR"),
    )
    return [
        f"{what} in {folder}: neither the installation's folders nor this account's home can "
        f"be written ({variable} names another folder)"
        for folder, what, variable in notes
        if folder is not None
    ]
