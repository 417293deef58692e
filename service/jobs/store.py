"""Jobs and their results in SQLite, under the service's data directory (api.md "Jobs").

The store is the one place job state lives, shared by the web process and the worker
processes: a worker reports progress by writing it here, and finds a cancel request here.

The file is opened on first use, not when the store is made: importing the service creates
nothing. Whatever goes wrong with the file (corrupt, replaced or deleted while the service runs,
unreadable) is one exception, :class:`JobStoreUnavailable`, which the service answers with 503:
the job routes are down, the compute routes are not.
"""

from __future__ import annotations

import json
import os
import sqlite3
import threading
import time
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from service.jobs.job import (
    FINISHED,
    Job,
    JobStoreUnavailable,
    Kind,
    QueueFull,
    Status,
    job_of_row,
)

__all__ = ["FINISHED", "Job", "JobStore", "JobStoreUnavailable", "Kind", "QueueFull", "Status"]

_SCHEMA = """
CREATE TABLE IF NOT EXISTS jobs (
    id TEXT PRIMARY KEY,
    kind TEXT NOT NULL,
    status TEXT NOT NULL,
    request TEXT NOT NULL,
    result TEXT,
    error TEXT,
    done REAL NOT NULL DEFAULT 0,
    created REAL NOT NULL,
    started REAL,
    finished REAL,
    attempts INTEGER NOT NULL DEFAULT 0,
    cancel INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX IF NOT EXISTS jobs_created ON jobs (created);
"""


class JobStore:
    """Jobs in an SQLite file; each call opens its own connection (safe across processes).

    The file is made by the web process's store (``create=True``) on its first use; the worker
    processes' stores never make one, so a file deleted under a running service is found out
    (503) rather than silently replaced by an empty one. Which file it is (device and inode) is
    kept at the first use, so a file replaced under the running service is found out too.
    """

    def __init__(self, path: Path, *, create: bool = True) -> None:
        """A store at ``path``, opened on first use (``create``: make the file if missing)."""
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
                    db.executescript(_SCHEMA)
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
            db.execute("PRAGMA journal_mode=WAL")
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

    def create(self, kind: Kind, request: dict[str, Any], *, limit: int | None = None) -> Job:
        """A new queued job with a random id.

        Args:
            kind: what the job computes.
            request: the route's body, as JSON.
            limit: at most this many jobs queued or running, counted in the insert's own
                transaction (so that concurrent submissions cannot pass it together).

        Raises:
            QueueFull: ``limit`` jobs are queued or running already.
        """
        job_id = str(uuid.uuid4())
        with self._connection() as db:
            db.execute("BEGIN IMMEDIATE")  # the write lock, before the count
            try:
                if limit is not None:
                    row = db.execute(
                        "SELECT COUNT(*) FROM jobs WHERE status IN ('queued', 'running')"
                    ).fetchone()
                    if int(row[0]) >= limit:
                        raise QueueFull(limit)
                db.execute(
                    "INSERT INTO jobs (id, kind, status, request, created) VALUES (?, ?, ?, ?, ?)",
                    (job_id, kind, "queued", json.dumps(request), time.time()),
                )
                row = db.execute("SELECT * FROM jobs WHERE id = ?", (job_id,)).fetchone()
                db.execute("COMMIT")
            except BaseException:
                if db.in_transaction:
                    db.execute("ROLLBACK")
                raise
        return job_of_row(row)

    def get(self, job_id: str) -> Job | None:
        """The job, or None for an unknown id."""
        with self._connection() as db:
            row = db.execute("SELECT * FROM jobs WHERE id = ?", (job_id,)).fetchone()
        return None if row is None else job_of_row(row)

    def jobs(self, *, status: str | None, limit: int) -> list[Job]:
        """The newest jobs first, optionally of one status."""
        query, args = "SELECT * FROM jobs", []
        if status is not None:
            query, args = query + " WHERE status = ?", [status]
        with self._connection() as db:
            rows = db.execute(query + " ORDER BY created DESC LIMIT ?", [*args, limit]).fetchall()
        return [job_of_row(row) for row in rows]

    def start(self, job_id: str) -> bool:
        """Mark a queued job running (one more attempt); False if it is not queued."""
        with self._connection() as db:
            changed = db.execute(
                "UPDATE jobs SET status = 'running', started = ?, attempts = attempts + 1 "
                "WHERE id = ? AND status = 'queued' AND cancel = 0",
                (time.time(), job_id),
            ).rowcount
        return bool(changed)

    def progress(self, job_id: str, fraction: float) -> bool:
        """Record the fraction done; whether to stop (a cancel was asked, or the job deleted)."""
        with self._connection() as db:
            db.execute("UPDATE jobs SET done = ? WHERE id = ?", (fraction, job_id))
            row = db.execute("SELECT cancel FROM jobs WHERE id = ?", (job_id,)).fetchone()
        return bool(row is None or row[0])

    def finish(
        self,
        job_id: str,
        status: Status,
        *,
        result: dict[str, Any] | None = None,
        error: list[dict[str, Any]] | None = None,
        if_running: bool = False,
    ) -> None:
        """Record how a job ended (with ``if_running``, only if it is still running)."""
        condition = " AND status = 'running'" if if_running else ""
        with self._connection() as db:
            db.execute(
                "UPDATE jobs SET status = ?, result = ?, error = ?, finished = ?, "
                "done = CASE WHEN ? = 'done' THEN 1 ELSE done END WHERE id = ?" + condition,
                (
                    status,
                    None if result is None else json.dumps(result),
                    None if error is None else json.dumps(error),
                    time.time(),
                    status,
                    job_id,
                ),
            )

    def queued(self, *, exclude: set[str], limit: int) -> list[str]:
        """The ids of the oldest queued jobs not in ``exclude``, at most ``limit``."""
        with self._connection() as db:
            rows = db.execute(
                "SELECT id FROM jobs WHERE status = 'queued' AND cancel = 0 ORDER BY created "
                "LIMIT ?",
                (limit + len(exclude),),
            ).fetchall()
        return [row[0] for row in rows if row[0] not in exclude][:limit]

    def cancel_asked(self, ids: list[str]) -> set[str]:
        """Those of ``ids`` whose cancel has been asked for, or that were deleted."""
        if not ids:
            return set()
        marks = ", ".join("?" * len(ids))
        with self._connection() as db:
            rows = db.execute(
                f"SELECT id FROM jobs WHERE cancel = 0 AND id IN ({marks})", ids
            ).fetchall()
        return set(ids) - {row[0] for row in rows}

    def cancel(self, job_id: str) -> None:
        """Ask a job to stop: a queued one is cancelled now, a running one soon after.

        A finished job is left as it is.
        """
        with self._connection() as db:
            db.execute(
                "UPDATE jobs SET cancel = 1 WHERE id = ? AND status IN ('queued', 'running')",
                (job_id,),
            )
            db.execute(
                "UPDATE jobs SET status = 'cancelled', finished = ? WHERE id = ? AND "
                "status = 'queued'",
                (time.time(), job_id),
            )

    def delete(self, job_id: str) -> bool:
        """Forget a job; whether it existed.

        A running job's worker finds it gone at its next progress report and stops, as after a
        cancel (the supervisor stops a worker that does not).
        """
        with self._connection() as db:
            return bool(db.execute("DELETE FROM jobs WHERE id = ?", (job_id,)).rowcount)

    def recover(self, *, attempts: int) -> list[str]:
        """After a restart: jobs left running are queued again (or failed after ``attempts``).

        Returns:
            The ids of the queued jobs, oldest first, to run.
        """
        now = time.time()
        with self._connection() as db:
            db.execute(
                "UPDATE jobs SET status = 'failed', finished = ?, error = ? WHERE "
                "status = 'running' AND attempts >= ?",
                (now, json.dumps([_interrupted(attempts)]), attempts),
            )
            db.execute("UPDATE jobs SET status = 'queued' WHERE status = 'running'")
            rows = db.execute(
                "SELECT id FROM jobs WHERE status = 'queued' ORDER BY created"
            ).fetchall()
        return [row[0] for row in rows]

    def statistics(self) -> tuple[dict[str, int], list[float]]:
        """Jobs by status, and the durations (s) of the finished ones that ran."""
        with self._connection() as db:
            counts = dict(db.execute("SELECT status, COUNT(*) FROM jobs GROUP BY status"))
            rows = db.execute(
                "SELECT finished - started FROM jobs WHERE finished IS NOT NULL AND started IS "
                "NOT NULL"
            ).fetchall()
        return {str(k): int(v) for k, v in counts.items()}, [float(r[0]) for r in rows]

    def expire(self, *, ttl: float) -> int:
        """Forget finished jobs older than ``ttl`` seconds; how many."""
        with self._connection() as db:
            return int(
                db.execute(
                    "DELETE FROM jobs WHERE status IN ('done', 'failed', 'cancelled') AND "
                    "finished < ?",
                    (time.time() - ttl,),
                ).rowcount
            )


def _interrupted(attempts: int) -> dict[str, Any]:
    return {
        "loc": [],
        "msg": f"the job was interrupted {attempts} times (service restarts) and is not retried",
        "type": "interrupted",
    }
