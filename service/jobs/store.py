"""Jobs and their results in SQLite, under the service's data directory (api.md "Jobs").

The store is the one place job state lives, shared by the web process and the worker
processes: a worker reports progress by writing it here, and finds a cancel request here.

Its file (:mod:`service.jobs.store_file`) is opened on first use; whatever goes wrong with it
is :class:`~service.jobs.job.JobStoreUnavailable` (503). What it reads is
:class:`~service.jobs.store_reads.JobReads`; this module holds what changes a job: submission,
the runner's and the workers' updates, cancel, delete, recovery after a restart and expiry.
"""

from __future__ import annotations

import json
import sqlite3
import time
import uuid
from collections.abc import Callable
from typing import Any, Literal

from service.jobs.job import Job, Kind, QueueFull, Status, job_of_row
from service.jobs.results import Result, write_result
from service.jobs.store_reads import JobReads
from service.logs import log


class JobStore(JobReads):
    """Jobs in an SQLite file: its reads (:class:`JobReads`) and the changes made to jobs.

    The routes submit, cancel and delete; the runner starts, recovers and expires; the workers
    report progress and finish.
    """

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
        return job_of_row(row, store=self.path)

    def start(self, job_id: str, owner: str | None = None) -> bool:
        """Mark a queued job running (one more attempt, from no progress); False if not queued.

        ``owner``: the id of the service that runs it (:mod:`service.jobs.owner`), whose
        recovery alone may queue it again while that service lives.
        """
        with self._connection() as db:
            changed = db.execute(
                "UPDATE jobs SET status = 'running', started = ?, done = 0, first_at = NULL, "
                "first_done = NULL, attempts = attempts + 1, owner = ? "
                "WHERE id = ? AND status = 'queued' AND cancel = 0",
                (time.time(), owner, job_id),
            ).rowcount
        return bool(changed)

    def retry(
        self, job_id: str, *, attempts: int, error: list[dict[str, Any]]
    ) -> Literal["queued", "cancelled", "failed"]:
        """Queue again a running job whose run ended abnormally (its worker died), or end it.

        Queued again, from no progress, while it has had fewer than ``attempts`` runs and no
        cancel was asked; cancelled where a cancel was asked (what its user asked for, whatever
        killed the worker); else failed with ``error``. Returns which.
        """
        with self._connection() as db:
            queued = db.execute(
                "UPDATE jobs SET status = 'queued', done = 0, started = NULL WHERE id = ? AND "
                "status = 'running' AND attempts < ? AND cancel = 0",
                (job_id, attempts),
            ).rowcount
            row = db.execute("SELECT cancel FROM jobs WHERE id = ?", (job_id,)).fetchone()
        if queued:
            return "queued"
        if row is not None and row[0]:
            self.finish(job_id, "cancelled", if_running=True)
            return "cancelled"
        self.finish(job_id, "failed", error=error, if_running=True)
        return "failed"

    def progress(self, job_id: str, fraction: float) -> bool:
        """Record the fraction done; whether to stop (a cancel was asked, or the job deleted).

        The run's first report over 0 is kept too (``JobState.first_report``): the ETA's rate.
        """
        with self._connection() as db:
            if fraction > 0.0:
                db.execute(
                    "UPDATE jobs SET done = ?, first_at = COALESCE(first_at, ?), "
                    "first_done = COALESCE(first_done, ?) WHERE id = ?",
                    (fraction, time.time(), fraction, job_id),
                )
            else:
                db.execute("UPDATE jobs SET done = ? WHERE id = ?", (fraction, job_id))
            row = db.execute("SELECT cancel FROM jobs WHERE id = ?", (job_id,)).fetchone()
        return bool(row is None or row[0])

    def finish(
        self,
        job_id: str,
        status: Status,
        *,
        result: Result | None = None,
        error: list[dict[str, Any]] | None = None,
        if_running: bool = False,
    ) -> bool:
        """Record how a job ended (with ``if_running``, only if still running); whether it was.

        A job deleted meanwhile (or, with ``if_running``, not running) is left alone: nothing is
        written, its result's cells neither, in the transaction that looks for it. A job whose
        cancel was asked before its work's end is written ended there, ``cancelled``, without its
        result: the client asked for it, and a map's answer stored from its columns may end
        before the next progress report would have seen the cancel (api.md: cancel stops the
        job, which is kept as cancelled).
        """
        condition = " AND status = 'running'" if if_running else ""
        with self._connection() as db:
            db.execute("BEGIN IMMEDIATE")  # the write lock, before the look
            try:
                row = db.execute(
                    "SELECT cancel FROM jobs WHERE id = ?" + condition, (job_id,)
                ).fetchone()
                if row is not None:
                    if status == "done" and row[0]:
                        status, result = "cancelled", None
                    self._finish(db, job_id, status, result=result, error=error)
                db.execute("COMMIT")
            except BaseException:
                if db.in_transaction:
                    db.execute("ROLLBACK")
                raise
        return row is not None

    @staticmethod
    def _finish(
        db: sqlite3.Connection,
        job_id: str,
        status: Status,
        *,
        result: Result | None,
        error: list[dict[str, Any]] | None,
    ) -> None:
        """Write a job's end, its result's cells in pages (inside the caller's transaction)."""
        text, cells = (None, None) if result is None else write_result(db, job_id, result)
        db.execute(
            "UPDATE jobs SET status = ?, result = ?, cells = ?, error = ?, finished = ?, "
            "done = CASE WHEN ? = 'done' THEN 1 ELSE done END WHERE id = ?",
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
            places = db.execute("SELECT id, created FROM jobs WHERE id = ?", (job_id,)).fetchall()
            # The row first: a finish() after it writes nothing; one before it wrote cells that
            # the second statement removes.
            deleted = db.execute("DELETE FROM jobs WHERE id = ?", (job_id,)).rowcount
            db.execute("DELETE FROM job_cells WHERE job_id = ?", (job_id,))
            _give_back(db)
            _keep_places(db, places)
        return bool(deleted)

    def recover(
        self, *, attempts: int, alive: Callable[[str | None], bool] = lambda _: False
    ) -> list[str]:
        """Jobs left running by a service that is gone are queued again (or failed, cancelled).

        ``alive``: whether the service of a job's ``owner`` id still runs
        (:func:`service.jobs.owner.alive`); its jobs are left to it, so that a second service
        on the same data directory does not run them again (the operator audit's M1). By
        default every owner is gone: the jobs left running were interrupted by a restart.

        A job whose cancel was asked before the restart (its worker stopped with the service
        before it could end the job) is cancelled: queued again it would never run (``queued``
        hands out no cancelled job) and never end, holding a place in the queue.

        A job queued again has no progress and no start time until it runs again.

        Result pages of no job (an older release's) are removed.

        Returns:
            The ids of the queued jobs, oldest first, to run.
        """
        now = time.time()
        with self._connection() as db:
            db.execute("BEGIN IMMEDIATE")
            running = db.execute(
                "SELECT id, attempts, started, cancel, owner FROM jobs WHERE status = 'running'"
            ).fetchall()
            owners = {row["owner"] for row in running}
            gone = {owner for owner in owners if not alive(owner)}
            left = [tuple(row)[:4] for row in running if row["owner"] in gone]
            kept = len(running) - len(left)
            # The trigger job_ran_to_its_end counts a failed job's finished - started: here the
            # restart's time, so the service's downtime too (35.6 s for a run of about 3 s, the
            # upgrade audit of stop 62). How long the interrupted run took is not known: it is
            # counted, with no seconds.
            downtime = sum(
                now - started
                for _, runs, started, cancel in left
                if (runs >= attempts or cancel) and started is not None
            )
            ids = [job_id for job_id, *_ in left]
            for job_id, runs, _, cancel in left:
                if cancel:
                    db.execute(
                        "UPDATE jobs SET status = 'cancelled', finished = ? WHERE id = ?",
                        (now, job_id),
                    )
                elif runs >= attempts:
                    db.execute(
                        "UPDATE jobs SET status = 'failed', finished = ?, error = ? WHERE id = ?",
                        (now, json.dumps([_interrupted(attempts)]), job_id),
                    )
            db.execute("UPDATE job_totals SET seconds = seconds - ?", (downtime,))
            # The interrupted run's progress and start time are not the next run's. In the
            # same transaction: two services recovering at once must not both take a job (the
            # second would queue again the run the first had started meanwhile).
            db.executemany(
                "UPDATE jobs SET status = 'queued', done = 0, started = NULL "
                "WHERE id = ? AND status = 'running'",
                [(job_id,) for job_id in ids],
            )
            db.execute("COMMIT")
            # Pages of no job: left by an older release, whose finish() wrote a deleted job's.
            db.execute("DELETE FROM job_cells WHERE job_id NOT IN (SELECT id FROM jobs)")
            rows = db.execute(
                "SELECT id FROM jobs WHERE status = 'queued' ORDER BY created"
            ).fetchall()
        for job_id, runs, _, cancel in left:  # a restart's work said (only a second line was)
            if cancel:
                log.info("job %s, cancelled before its service stopped: cancelled", job_id)
            elif runs >= attempts:
                log.info("job %s interrupted (its service stopped) after %d runs: failed",
                         job_id, runs)  # fmt: skip
            else:
                log.info("job %s interrupted (its service stopped): queued again (run %d of at "
                         "most %d)", job_id, runs + 1, attempts)  # fmt: skip
        if kept:
            log.info("%d running job(s) left to the live service(s) that run them", kept)
        return [row[0] for row in rows]

    def running_owners(self) -> set[str | None]:
        """The ids of the services running jobs (None: a job started before owners were kept)."""
        with self._connection() as db:
            rows = db.execute("SELECT DISTINCT owner FROM jobs WHERE status = 'running'").fetchall()
        return {row[0] for row in rows}

    def figures(self) -> tuple[dict[str, int], tuple[int, float], dict[str, int]]:
        """What /metrics shows, in one read of the store.

        Jobs held by status; how many jobs ran to an end since the store began and their
        seconds (the store's ``job_totals``, kept by a trigger: read from the jobs held, it fell
        when jobs were deleted or expired, which Prometheus reads as a counter reset, and a
        scrape read every finished job's times, 48 to 160 ms as 748 jobs piled up: the soak
        audit of stop 61); the jobs that ended since the store began by status (done, failed,
        cancelled; the jobs held by status fall as jobs are deleted or expire, so an alert on
        failed jobs could not tell a failure from an expiry: operator audit of 2026-12-07, L3).
        The last two only grow. One connection and one read transaction, so the figures agree
        with each other (a job that ends between two reads was counted running by one and ended
        by the other) and the file is opened once a scrape.
        """
        with self._connection() as db:
            db.execute("BEGIN")
            try:
                counts = dict(db.execute("SELECT status, COUNT(*) FROM jobs GROUP BY status"))
                totals = db.execute("SELECT finished, seconds FROM job_totals").fetchone()
                ended = db.execute("SELECT status, count FROM job_ended").fetchall()
            finally:
                db.execute("COMMIT")
        return (
            {str(k): int(v) for k, v in counts.items()},
            (int(totals[0]), float(totals[1])),
            {str(status): int(count) for status, count in ended},
        )

    def expire(self, *, ttl: float) -> int:
        """Forget finished jobs older than ``ttl`` seconds, and their results' pages; how many.

        The jobs are found by their end time (an index) and the pages by their job, so its
        cost is that of the jobs expired, not of the store (the supervisor runs it every
        minute). Their places in the listing are kept for another ``ttl`` (:func:`_keep_places`),
        and the places forgotten longer ago dropped.
        """
        expired = (
            "SELECT id FROM jobs WHERE finished < ? AND status IN ('done', 'failed', 'cancelled')"
        )
        cutoff = time.time() - ttl
        with self._connection() as db:
            db.execute("DELETE FROM job_places WHERE forgotten < ?", (cutoff,))
            places = db.execute(
                f"SELECT id, created FROM jobs WHERE id IN ({expired})", (cutoff,)
            ).fetchall()
            db.execute(f"DELETE FROM job_cells WHERE job_id IN ({expired})", (cutoff,))
            count = db.execute(f"DELETE FROM jobs WHERE id IN ({expired})", (cutoff,)).rowcount
            if count:
                _give_back(db)
            _keep_places(db, places)
        return int(count)


def _keep_places(db: sqlite3.Connection, places: list[sqlite3.Row]) -> None:
    """Keep the ids and submission times of jobs just forgotten (rows of id, created).

    ``GET /v1/jobs?after=<id>`` goes on after a job's place in the listing; a client reading it
    in pages got a 404 when another client deleted the last job of its page (audit 26, F4).
    Written after the jobs are deleted, and only if the store takes it: on a full disk the
    delete, which frees room, must not fail for want of room for their places (the listing
    after such an id is then a 404, as before).
    """
    if not places:
        return
    now = time.time()
    try:
        db.executemany(
            "INSERT OR REPLACE INTO job_places (id, created, forgotten) VALUES (?, ?, ?)",
            [(row[0], row[1], now) for row in places],
        )
    except sqlite3.Error as error:
        log.warning("the places of %d forgotten job(s) not kept: %s", len(places), error)


def _give_back(db: sqlite3.Connection) -> None:
    """Return the pages deleted rows freed to the disk (a store made with ``auto_vacuum``).

    The file never shrank: 748 jobs deleted left it at 564 MB, the free pages only reused (the
    soak audit of stop 61; a map job keeps about 240 bytes a cell, 480 MB at 2 million).
    ``executescript`` steps the pragma to its end (``execute`` ran one step: nothing freed).
    """
    db.executescript("PRAGMA incremental_vacuum;")


def _interrupted(attempts: int) -> dict[str, Any]:
    return {
        "loc": [],
        "msg": f"the job was interrupted {attempts} times (service restarts) and is not retried",
        "type": "interrupted",
    }
