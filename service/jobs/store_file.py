"""The job store's SQLite file: opened on first use, and refused once deleted or replaced.

The file is opened on first use, not when the store is made: importing the service creates
nothing. Whatever goes wrong with the file (corrupt, replaced or deleted while the service runs,
unreadable) is one exception, :class:`JobStoreUnavailable`, which the service answers with 503:
the job routes are down, the compute routes are not.
"""

from __future__ import annotations

import os
import sqlite3
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from service.jobs.job import JobStoreUnavailable
from service.jobs.results import make_tables
from service.logs import log

KEEPS_ITS_SIZE = (
    "the job store %s was made by a release before 2026-12-06: deleted and expired jobs' pages "
    "are reused but not given back to the disk; to give them back once, stop the service and "
    "run: sqlite3 %s 'PRAGMA auto_vacuum=INCREMENTAL; VACUUM' (README, Upgrading)"
)
"""Said once at the web process's first use of a store made without incremental auto_vacuum
(the upgrade audit of stop 62: its 68.8 MB stayed after its largest job was deleted, and nothing
said why or what to do)."""


class StoreFile:
    """An SQLite file of jobs; each call opens its own connection (safe across processes).

    The file is made by the web process's store (``create=True``) on its first use; the worker
    processes' stores never make one, so a file deleted under a running service is found out
    (503) rather than silently replaced by an empty one. Which file it is (device and inode) is
    kept at the first use, so a file replaced under the running service is found out too.
    """

    def __init__(self, path: Path, *, create: bool = True) -> None:
        """The file at ``path``, opened on first use (``create``: make the file if missing)."""
        self.path = path
        self._create = create
        self._identity: tuple[int, int] | None = None
        self._lock = threading.Lock()

    def _unavailable(self, what: str) -> JobStoreUnavailable:
        return JobStoreUnavailable(f"the job store {str(self.path)!r} {what}")

    def _open(self) -> None:
        """First use: make the directory, the file and the table; note which file it is."""
        with self._lock:
            if self._identity is not None:
                return
            try:
                if self._create:
                    self.path.parent.mkdir(parents=True, exist_ok=True)
                with self._connect(create=self._create) as db:
                    if self._create:
                        # Once, by the process that makes the file (both are kept in it): a
                        # connection that set auto_vacuum took 0.9 ms against 0.2 without.
                        # Pages that deleted and expired jobs free go back to the disk
                        # (JobStore.delete, expire): set before the first table, a no-op on a
                        # file that has tables (a store of an older release keeps its size until
                        # VACUUMed once, README); before WAL, which would keep it from taking.
                        db.execute("PRAGMA auto_vacuum = INCREMENTAL")
                        db.execute("PRAGMA journal_mode=WAL")
                    make_tables(db)
                    if self._create and db.execute("PRAGMA auto_vacuum").fetchone()[0] == 0:
                        log.warning(KEEPS_ITS_SIZE, self.path, self.path)
                status = os.stat(self.path)
            except (sqlite3.Error, OSError) as error:
                raise self._unavailable(f"cannot be used: {error}") from error
            self._identity = (status.st_dev, status.st_ino)

    def _check_identity(self) -> None:
        """The file is the one first opened: not deleted, not replaced."""
        try:
            status = os.stat(self.path)
        except FileNotFoundError:
            raise self._unavailable(
                "was deleted while the service ran, and its jobs with it; restart the service "
                "to start a new, empty store"
            ) from None
        except OSError as error:
            raise self._unavailable(f"cannot be used: {error}") from error
        if (status.st_dev, status.st_ino) != self._identity:
            raise self._unavailable(
                "was replaced by another file while the service ran; restart the service to "
                "use the new file"
            )

    @contextmanager
    def _connect(self, *, create: bool) -> Iterator[sqlite3.Connection]:
        mode = "rwc" if create else "rw"
        uri = f"{self.path.absolute().as_uri()}?mode={mode}"
        db = sqlite3.connect(uri, uri=True, timeout=30, isolation_level=None)
        db.row_factory = sqlite3.Row
        try:
            yield db
        finally:
            db.close()

    @contextmanager
    def _connection(self) -> Iterator[sqlite3.Connection]:
        """A connection to the store's file; any SQLite or OS error is JobStoreUnavailable."""
        if self._identity is None:
            self._open()
        self._check_identity()
        try:
            with self._connect(create=False) as db:
                yield db
        except (sqlite3.Error, OSError) as error:
            raise self._unavailable(f"cannot be used: {error}") from error
