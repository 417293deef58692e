"""Which service runs a job: a lock each service holds under the data directory while it lives.

Several services may share one ``DTF_DATA_DIR`` (an overlapping deploy, ``uvicorn --workers N``):
each takes queued jobs from the store, which hands each to one. A start queued again every job
the store held as running, the other services' too, which then ran twice (the operator audit's
M1). Now each service holds a lock of its own, ``services/<id>.lock`` under the data directory
(``flock``, exclusive), from its runner's making to its close; the store keeps the id of the
service that started a job (:meth:`service.jobs.store.JobStore.start`), and a recovery queues
again only the jobs of a service whose lock is free: one that stopped or died (the kernel frees a
dead process's lock; its job workers die with it, ``service.jobs.worker``). A lock file found free
is removed by the service that found it.

``flock`` is not reliable on a network filesystem (nor is SQLite's locking, README): the data
directory is a local disk's.
"""

from __future__ import annotations

import fcntl
import os
import re
import uuid
from pathlib import Path

from service.logs import log

SERVICES = "services"
"""The directory under the data directory that holds the services' locks."""

_ID = re.compile(r"[0-9a-f]{32}")


def lock_file(data_dir: Path, owner: str) -> Path:
    """The lock file of the service ``owner`` under ``data_dir``."""
    return Path(data_dir) / SERVICES / f"{owner}.lock"


class ServiceLock:
    """This service's lock: its id, held from :meth:`hold` to :meth:`release`."""

    def __init__(self, data_dir: Path) -> None:
        """A new id for a service on ``data_dir``; the lock is taken by :meth:`hold`."""
        self.id = uuid.uuid4().hex
        self.path = lock_file(data_dir, self.id)
        """The lock's file."""
        self._fd: int | None = None

    def hold(self) -> str:
        """Take the lock (once; later calls keep it); this service's id.

        Raises:
            OSError: the directory or the file cannot be made, or locked.
        """
        if self._fd is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                os.write(fd, f"{os.getpid()}\n".encode())
            except OSError:
                os.close(fd)
                raise
            self._fd = fd
        return self.id

    def release(self) -> None:
        """Free the lock and remove its file (the service stops; its running jobs are free)."""
        if self._fd is None:
            return
        try:
            self.path.unlink(missing_ok=True)
        finally:
            os.close(self._fd)  # closing frees the flock
            self._fd = None


def alive(data_dir: Path, owner: str | None) -> bool:
    """Whether the service ``owner`` still holds its lock under ``data_dir``.

    No owner (a job started by a release before owners), an id not of this module's making, or
    no lock file: not alive. A lock file whose lock is free (its service stopped or died) is
    removed here.
    """
    if owner is None or not _ID.fullmatch(owner):
        return False
    path = lock_file(data_dir, owner)
    try:
        fd = os.open(path, os.O_RDWR)
    except FileNotFoundError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return True  # held: its service lives
    else:
        path.unlink(missing_ok=True)
        return False
    finally:
        os.close(fd)


def forget_gone(data_dir: Path) -> int:
    """Remove the lock files of the services that are gone; how many.

    A service that was killed leaves its file (the kernel frees the lock, not the file): a look
    for its jobs removes it, but one that ran none left it for good. A start removes them all.
    """
    directory = Path(data_dir) / SERVICES
    gone = 0
    try:
        for path in sorted(directory.glob("*.lock")):
            if _ID.fullmatch(path.stem) and not alive(data_dir, path.stem):
                gone += 1
    except OSError as error:  # a directory it may not read: the files stay, nothing else
        log.warning("the lock files of stopped services under %s not removed: %s", directory, error)
    return gone
