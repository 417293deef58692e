"""The job runner of one service: worker processes fed from the store, watched by a thread.

Jobs wait in the store (``service.jobs.store``), which is the queue: a supervisor thread in the
web process hands the oldest queued job to an idle worker process (``service.jobs.worker``).
It also watches the running ones: a worker that has not stopped a cancelled job within
``KILL_AFTER`` seconds is killed and replaced, so a cancel stops the work within a second even
inside a long solver step, and a worker that dies fails its job instead of hanging it.

Several services may share a data directory: each holds a lock of its own and keeps its id with
the jobs it starts (:mod:`service.jobs.owner`); a start queues again only the running jobs of a
service that is gone, and every ``TAKE_OVER_SECONDS`` the supervisor looks for those too (a
service that died while another runs).

When the store cannot be used (``JobStoreUnavailable``: a corrupt, replaced or deleted file),
the supervisor logs it once and looks again less and less often (up to ``MAX_BACKOFF``), and
logs once more when the store is back; the web process and its compute routes go on.
"""

from __future__ import annotations

import logging
import math
import multiprocessing
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from multiprocessing.connection import Connection
from multiprocessing.process import BaseProcess
from pathlib import Path
from typing import TYPE_CHECKING

from service.config import Settings
from service.jobs.job import JobStoreUnavailable
from service.jobs.owner import ServiceLock, alive, forget_gone
from service.jobs.store import JobStore
from service.jobs.worker import UNSTORED, serve
from service.logs import duration, log

if TYPE_CHECKING:  # no fork server on Windows
    from multiprocessing.context import ForkServerContext, SpawnContext

POLL_SECONDS = 0.05
"""How often the supervisor looks at the workers and the queue while a job runs or waits (s)."""
IDLE_POLL_SECONDS = 0.5
"""How often it looks when no job runs or waits (s). A job queued or cancelled by this service
wakes it at once (:meth:`JobRunner.wake`); a look only finds one queued by another process on
the same data directory. At POLL_SECONDS an idle service spent about 2 % of a core opening the
store 20 times a second."""

KILL_AFTER = 0.5
"""How long a worker has to stop a cancelled job before it is killed and replaced (s)."""

MAX_BACKOFF = 5.0
"""The longest wait between two looks at a store that is failing (s)."""

TAKE_OVER_SECONDS = 10.0
"""How often the supervisor looks for running jobs of a service that is gone (s): another
service on the same data directory that stopped or died. Its jobs are queued again, as a
restart queues its own."""

EXPIRE_SECONDS = 60.0
"""How often the supervisor forgets the jobs older than DTF_JOB_TTL (s; more often for a
shorter TTL): a finished job stays readable for at most this long past its TTL."""


WORKER_MODULES = ["service.jobs.worker"]
"""What the fork server imports once, before it forks any worker (:func:`worker_context`)."""


def worker_context() -> SpawnContext | ForkServerContext:
    """How worker processes start: forked from a fork server that imported the worker's modules.

    The fork server is a process of its own, started with the first worker and single-threaded
    (safe to fork, unlike the web process with its threads); it imports ``WORKER_MODULES``
    (the solver, numba, scipy, the schemas) once, and each worker after is a fork of it that
    starts at once and shares those pages. Started by ``spawn`` each worker imported them
    itself: about 2 s of CPU before its first job, again for each worker replaced after a kill
    (bench/parallel.py: four jobs on four new workers 5.8 s spawned, 2.8 s forked with the fork
    server's start, 0.4 s once it runs). A program started as a script (the ``uvicorn``
    command) is still imported again by each worker, as ``__mp_main__``: multiprocessing's
    ``__main__`` preload does nothing for a fork server on Python 3.11 (it is given no path).
    ``spawn`` where the platform has no fork server.
    """
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(WORKER_MODULES)
    return context


@dataclass
class _Worker:
    """A worker process, the end of its pipe in the web process, and the job it runs."""

    process: BaseProcess
    connection: Connection
    job_id: str | None = None
    cancel_seen: float | None = None


class JobRunner:
    """The store and the worker processes of one service."""

    def __init__(self, settings: Settings, *, worker: Callable[..., None] = serve) -> None:
        """The store under the data directory (opened on first use), and the supervisor.

        Worker processes are started when jobs first wait.

        Args:
            settings: the service's settings (data directory, workers, limits).
            worker: a worker process's life, ``serve`` (another one only in tests).
        """
        self.settings = settings
        self._worker = worker
        self.store = JobStore(Path(settings.data_dir) / "jobs.sqlite3")
        self.service = ServiceLock(Path(settings.data_dir))
        """This service's lock and id (its jobs are its own while it lives)."""
        self._context = worker_context()
        self._workers: list[_Worker] = []  # started when jobs first wait (README: memory)
        self._unsettled: set[str] = set()  # jobs whose worker could not store their end
        self._recovery_due = False  # recover() was refused by the store: the supervisor's to do
        self._expired_at = -math.inf  # when expire() last ran (monotonic, s)
        self._expiring = threading.Lock()  # recover() at the start and the supervisor's look
        self._looked_at = time.monotonic()  # when the last look for a gone service's jobs was
        self.failure: str | None = None
        """Why the supervisor's last look failed (the store's reason), None when it did not."""
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._supervise, name="dtf-jobs", daemon=True)
        self._thread.start()

    def _owner(self) -> str:
        """This service's id, its lock held (taken at the first job).

        Raises:
            JobStoreUnavailable: the lock cannot be made or taken (jobs wait: a job started
                without it would be any other service's to run again).
        """
        try:
            return self.service.hold()
        except OSError as error:
            raise JobStoreUnavailable(
                f"the service's lock {str(self.service.path)!r} cannot be held: {error}"
            ) from error

    def _alive(self, owner: str | None) -> bool:
        """Whether the service ``owner`` runs: this one, or another holding its lock."""
        return owner == self.service.id or alive(Path(self.settings.data_dir), owner)

    def _start_worker(self) -> _Worker:
        ours, theirs = self._context.Pipe()
        process = self._context.Process(
            target=self._worker,
            args=(theirs, str(self.store.path), self.settings.model_dump_json(), self._owner()),
            name="dtf-job-worker",
            daemon=True,
        )
        process.start()
        theirs.close()
        return _Worker(process, ours)

    def wake(self) -> None:
        """The store changed (a job queued, a cancel asked): the supervisor looks now.

        Without it the supervisor looks every POLL_SECONDS.
        """
        self._wake.set()

    def recover(self) -> list[str]:
        """Forget expired jobs, then queue again the running jobs of services that are gone.

        Those a restart interrupted, this service's before it, and any other stopped service's;
        a live service's are left to it (:mod:`service.jobs.owner`). The lock files of stopped
        services are removed.

        Where the store refuses (its ``JobStoreUnavailable`` is raised), the supervisor does it
        at its first look that the store answers, before it hands out any job: the jobs the
        restart interrupted stayed ``running`` with no worker, for good, holding their queue
        places (the operator audit of 2026-12-07, H1's third part).

        Returns:
            The ids queued, oldest first; they run as workers become idle.
        """
        try:
            self.expire()  # unless the supervisor's first look just did
            ids = self.store.recover(attempts=self.settings.job_attempts, alive=self._alive)
            self._looked_at = time.monotonic()
            forget_gone(Path(self.settings.data_dir))  # the files of services killed idle
        except JobStoreUnavailable:
            self._recovery_due = True
            raise
        self._recovery_due = False
        self._wake.set()
        return ids

    def take_over(self) -> list[str]:
        """Queue again the running jobs of the services that are gone; the ids queued.

        A cheap read when every running job's service lives (the store's write lock is taken
        only when one is gone).
        """
        self._looked_at = time.monotonic()
        if all(self._alive(owner) for owner in self.store.running_owners()):
            return []
        ids = self.store.recover(attempts=self.settings.job_attempts, alive=self._alive)
        self._wake.set()
        return ids

    def expire(self) -> int:
        """Forget the jobs that finished over DTF_JOB_TTL ago, saying how many; how many.

        Done when EXPIRE_SECONDS (or DTF_JOB_TTL if shorter) have passed since it last was,
        else nothing (0); under a lock, so that the supervisor's first look and ``recover()``
        at the start, which race, do it once between them (both did it when the look came
        first or while the start's expiry ran: the project's CI of stop 71 found it).
        It was silent: DTF_JOB_TTL=7 (meant as days) emptied a 318 MB store at the next start
        without a line (the operator audit of 2026-12-07, M5).
        """
        ttl = self.settings.job_ttl
        with self._expiring:
            if time.monotonic() - self._expired_at < min(ttl, EXPIRE_SECONDS):
                return 0
            count = self.store.expire(ttl=ttl)
            self._expired_at = time.monotonic()
        if count:
            log.info(
                "forgot %d job(s) that finished over DTF_JOB_TTL = %g s (%s) ago, with their "
                "results",
                count,
                ttl,
                duration(ttl),
            )
        return count

    def _supervise(self) -> None:
        """Watch and dispatch every POLL_SECONDS; after a failure, log once and back off.

        When no job runs or waits, every IDLE_POLL_SECONDS (a wake looks at once). Every
        EXPIRE_SECONDS (or DTF_JOB_TTL if shorter) it also forgets the expired jobs, so that a
        long-running service does not keep them past their TTL; counted from the last expiry,
        so the one ``recover()`` did at the start is not done again at the first look.
        """
        delay, failing = POLL_SECONDS, False
        while not self._stop.is_set():
            self._wake.wait(delay)
            self._wake.clear()
            try:
                if self._recovery_due:
                    self.recover()
                self.expire()  # when due
                if time.monotonic() - self._looked_at >= TAKE_OVER_SECONDS:
                    self.take_over()
                self._watch()
                self.settle()
                waiting = self._dispatch()
            except JobStoreUnavailable as error:
                if not failing:
                    log.error("jobs wait: %s (a look every %g s at most)", error, MAX_BACKOFF)
                self.failure = error.reason
                failing, delay = True, min(2.0 * delay, MAX_BACKOFF)
            except Exception as error:  # noqa: BLE001 - the supervisor must outlive any one failure
                if not failing:
                    log.exception("job supervisor (looking again every %g s at most)", MAX_BACKOFF)
                self.failure = f"the job supervisor failed: {type(error).__name__}: {error}"[:500]
                failing, delay = True, min(2.0 * delay, MAX_BACKOFF)
            else:
                self.failure = None
                if failing:
                    log.warning("job supervisor: the store answers again; jobs run")
                busy = waiting or any(w.job_id is not None for w in self._workers)
                failing, delay = False, POLL_SECONDS if busy else IDLE_POLL_SECONDS

    def _watch(self) -> None:
        """Free the workers whose job ended; kill those that do not stop a cancelled job."""
        busy = [w for w in self._workers if w.job_id is not None]
        cancels = self.store.cancel_asked([w.job_id for w in busy if w.job_id is not None])
        now = time.monotonic()
        for i, worker in enumerate(self._workers):
            job_id = worker.job_id
            if job_id is None:
                _heard(worker.connection)  # its lines (a warm-up's, say)
                continue
            answer = _heard(worker.connection)
            if answer is not None:
                self._workers[i] = _Worker(worker.process, worker.connection)
                if isinstance(answer, tuple) and answer[1] is False:  # its end not stored
                    self._unsettled.add(job_id)
                continue
            if not worker.process.is_alive():  # killed (out of memory, say): run again, a few times
                cause = f"the worker process ended (exit code {worker.process.exitcode})"
                self._run_again(job_id, cause, "interrupted")
                self._replace(i)
            elif job_id in cancels:
                worker.cancel_seen = worker.cancel_seen or now
                if now - worker.cancel_seen >= KILL_AFTER:
                    worker.process.kill()
                    worker.process.join()
                    self.store.finish(job_id, "cancelled", if_running=True)
                    log.info("job %s cancelled (its worker was stopped)", job_id)
                    self._replace(i)

    def settle(self) -> None:
        """Queue again, or end, each job whose worker could not write its end nor its failure.

        The store failed as the job ended (a full disk): the job is still ``running`` with no
        worker. It is queued again, as a job whose worker died is, up to DTF_JOB_ATTEMPTS
        runs, then failed; cancelled where its cancel was asked. A job the store cannot take
        this either stays to be settled at the next look (the supervisor backs off meanwhile).
        """
        cause = "its end could not be written to the job store (a full disk, say)"
        for job_id in sorted(self._unsettled):
            self._run_again(job_id, cause, UNSTORED)
            self._unsettled.discard(job_id)

    def _run_again(self, job_id: str, cause: str, error_type: str) -> None:
        """Queue again a running job whose run ended abnormally, or end it (``store.retry``).

        Failed, once it has had DTF_JOB_ATTEMPTS runs, with the error ``error_type`` saying
        ``cause`` in each; cancelled where its cancel was asked (not a failure of the job).
        """
        attempts = self.settings.job_attempts
        message = f"{cause} in each of the job's {attempts} runs (DTF_JOB_ATTEMPTS)"
        error = [{"loc": [], "msg": message, "type": error_type}]
        ended = self.store.retry(job_id, attempts=attempts, error=error)
        if ended == "queued":
            log.warning("job %s queued again: %s", job_id, cause)
        elif ended == "cancelled":
            log.info("job %s cancelled: %s", job_id, cause)
        else:
            log.error("job %s failed: %s", job_id, message)

    def _replace(self, i: int) -> None:
        self._workers[i].connection.close()
        self._workers[i] = self._start_worker()

    def _dispatch(self) -> bool:
        """Hand the oldest queued jobs to the idle workers, starting workers as jobs wait.

        Returns:
            Whether a job was waiting.
        """
        taken = {w.job_id for w in self._workers if w.job_id is not None}
        queued = self.store.queued(exclude=taken, limit=self.settings.workers)
        waiting = bool(queued)
        idle = [w for w in self._workers if w.job_id is None]
        while len(idle) < len(queued) and len(self._workers) < self.settings.workers:
            self._workers.append(self._start_worker())
            idle.append(self._workers[-1])
        queued = queued[: len(idle)]
        for worker, job_id in zip(idle[: len(queued)], queued, strict=True):
            worker.job_id, worker.cancel_seen = job_id, None
            worker.connection.send(job_id)
        return waiting

    def close(self) -> None:
        """Stop the supervisor and the workers (unfinished jobs run again after a restart).

        Each job stopped so is logged: a shutdown said nothing until the next start queued it
        again, and each such run counts against DTF_JOB_ATTEMPTS (the operator audit, L2).
        """
        self._stop.set()
        self._wake.set()
        self._thread.join(timeout=5)
        for worker in self._workers:
            if worker.job_id is not None and worker.process.is_alive():
                log.warning(
                    "job %s stopped by the shutdown: it runs again at the next start (a run "
                    "of its DTF_JOB_ATTEMPTS = %d)",
                    worker.job_id,
                    self.settings.job_attempts,
                )
            worker.process.kill()
        for worker in self._workers:
            worker.process.join(timeout=5)
            worker.connection.close()
        self.service.release()  # after the workers: their jobs are free to run again now


def _heard(connection: Connection) -> object | None:
    """What a worker sent since the last look: its log lines said here, its answer returned.

    The lines are logged by their own logger in this process, at the levels it has here
    (where an operator's logging configuration places them); None where no answer came, or
    the pipe broke (a worker that died as it answered: the look sees it dead).
    """
    try:
        while connection.poll():
            message: object = connection.recv()
            if not isinstance(message, logging.LogRecord):
                return message
            logger = logging.getLogger(message.name)
            if logger.isEnabledFor(message.levelno):
                logger.handle(message)
    except (EOFError, OSError):
        pass
    return None


_RUNNERS: dict[str, JobRunner] = {}


def get_runner(settings: Settings) -> JobRunner:
    """The service's runner for these settings, made on first use."""
    key = settings.model_dump_json()
    if key not in _RUNNERS:
        _RUNNERS[key] = JobRunner(settings)
    return _RUNNERS[key]


def runner_if_made(settings: Settings) -> JobRunner | None:
    """The service's runner for these settings if one was made, without making one."""
    return _RUNNERS.get(settings.model_dump_json())


def close_runners() -> None:
    """Stop every runner (the service is shutting down)."""
    for runner in _RUNNERS.values():
        runner.close()
    _RUNNERS.clear()
