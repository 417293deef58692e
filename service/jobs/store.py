"""Jobs and their results in SQLite, under the service's data directory (api.md "Jobs").

The store is the one place job state lives, shared by the web process and the worker
processes: a worker reports progress by writing it here, and finds a cancel request here.

Its file (:mod:`service.jobs.store_file`) is opened on first use; whatever goes wrong with it
is :class:`JobStoreUnavailable` (503). A map's cells are kept in pages of their own
(:mod:`service.jobs.results`), so that a job listing reads no result and a page of cells
reads only that page.
"""

from __future__ import annotations

import json
import time
import uuid
from typing import Any

from service.jobs.job import (
    FINISHED,
    STATE_COLUMNS,
    Job,
    JobState,
    JobStoreUnavailable,
    Kind,
    QueueFull,
    Status,
    job_of_row,
    state_of_row,
)
from service.jobs.results import cells_text, read_cells, with_cells, write_result
from service.jobs.store_file import StoreFile

__all__ = [
    "FINISHED",
    "Job",
    "JobState",
    "JobStore",
    "JobStoreUnavailable",
    "Kind",
    "QueueFull",
    "Status",
]


class JobStore(StoreFile):
    """Jobs in an SQLite file (:class:`StoreFile`): what the routes, runner and workers ask."""

    def create(
        self,
        kind: Kind,
        request: dict[str, Any],
        *,
        total: int | None = None,
        limit: int | None = None,
    ) -> Job:
        """A new queued job with a random id.

        Args:
            kind: what the job computes.
            request: the route's body, as JSON.
            total: its units of work (a map's placements, else 100), kept for its progress.
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
                    "INSERT INTO jobs (id, kind, status, request, created, total) "
                    "VALUES (?, ?, ?, ?, ?, ?)",
                    (job_id, kind, "queued", json.dumps(request), time.time(), total),
                )
                row = db.execute("SELECT * FROM jobs WHERE id = ?", (job_id,)).fetchone()
                db.execute("COMMIT")
            except BaseException:
                if db.in_transaction:
                    db.execute("ROLLBACK")
                raise
        return job_of_row(row, None)

    def get(self, job_id: str, *, inline_cells: int | None = None) -> Job | None:
        """The job with its request and result, or None for an unknown id.

        Args:
            job_id: the job's id.
            inline_cells: a result's cells are put in it when there are at most this many
                (``Job.cells`` says how many there are); None: always.
        """
        with self._connection() as db:
            row = db.execute("SELECT * FROM jobs WHERE id = ?", (job_id,)).fetchone()
            if row is None:
                return None
            result = None if row["result"] is None else json.loads(row["result"])
            count = row["cells"]
            if result is not None and count is not None:
                if inline_cells is None or count <= inline_cells:
                    result = with_cells(result, read_cells(db, job_id, offset=0, limit=count))
        return job_of_row(row, result)

    def state(self, job_id: str) -> JobState | None:
        """The job without its request and result, or None for an unknown id."""
        with self._connection() as db:
            row = db.execute(f"SELECT {STATE_COLUMNS} FROM jobs WHERE id = ?", (job_id,)).fetchone()
        return None if row is None else state_of_row(row)

    def jobs(self, *, status: str | None, limit: int) -> list[JobState]:
        """The newest jobs first, optionally of one status, without requests and results."""
        query, args = f"SELECT {STATE_COLUMNS} FROM jobs", []
        if status is not None:
            query, args = query + " WHERE status = ?", [status]
        with self._connection() as db:
            rows = db.execute(query + " ORDER BY created DESC LIMIT ?", [*args, limit]).fetchall()
        return [state_of_row(row) for row in rows]

    def request(self, job_id: str) -> dict[str, Any] | None:
        """The job's request (the route's body), or None for an unknown id."""
        with self._connection() as db:
            row = db.execute("SELECT request FROM jobs WHERE id = ?", (job_id,)).fetchone()
        return None if row is None else dict(json.loads(row[0]))

    def cells(self, job_id: str, *, offset: int, limit: int) -> list[dict[str, Any]]:
        """Cells ``offset`` to ``offset + limit`` of a done job's result (fewer at its end).

        A result stored whole by an older release (``Job.cells`` None) is read whole.
        """
        with self._connection() as db:
            row = db.execute("SELECT result, cells FROM jobs WHERE id = ?", (job_id,)).fetchone()
            if row is None or row["result"] is None:
                return []
            if row["cells"] is not None:
                return read_cells(db, job_id, offset=offset, limit=limit)
        cells = json.loads(row["result"]).get("cells", [])
        return list(cells[offset : offset + limit])

    def cells_json(self, job_id: str, *, offset: int, limit: int) -> tuple[str, int]:
        """:meth:`cells` as a JSON array's text, and how many cells it holds.

        Whole stored pages are copied unparsed (:func:`service.jobs.results.cells_text`).
        """
        state = self.state(job_id)
        if state is None or state.cells is None:
            cells = self.cells(job_id, offset=offset, limit=limit)
            return json.dumps(cells), len(cells)
        with self._connection() as db:
            return cells_text(db, job_id, offset=offset, limit=limit, total=state.cells)

    def cell_count(self, job_id: str) -> int:
        """How many cells a done job's result has (0 without cells or result)."""
        state = self.state(job_id)
        if state is not None and state.cells is not None:
            return state.cells
        return len(self.cells(job_id, offset=0, limit=2**62))  # stored whole by an older release

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
            db.execute("BEGIN IMMEDIATE")
            try:
                text, cells = (None, None) if result is None else write_result(db, job_id, result)
                db.execute(
                    "UPDATE jobs SET status = ?, result = ?, cells = ?, error = ?, finished = ?, "
                    "done = CASE WHEN ? = 'done' THEN 1 ELSE done END WHERE id = ?" + condition,
                    (
                        status,
                        text,
                        cells,
                        None if error is None else json.dumps(error),
                        time.time(),
                        status,
                        job_id,
                    ),
                )
                db.execute("COMMIT")
            except BaseException:
                if db.in_transaction:
                    db.execute("ROLLBACK")
                raise

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
            db.execute("DELETE FROM job_cells WHERE job_id = ?", (job_id,))
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
            expired = db.execute(
                "DELETE FROM jobs WHERE status IN ('done', 'failed', 'cancelled') AND finished < ?",
                (time.time() - ttl,),
            ).rowcount
            db.execute("DELETE FROM job_cells WHERE job_id NOT IN (SELECT id FROM jobs)")
        return int(expired)


def _interrupted(attempts: int) -> dict[str, Any]:
    return {
        "loc": [],
        "msg": f"the job was interrupted {attempts} times (service restarts) and is not retried",
        "type": "interrupted",
    }
