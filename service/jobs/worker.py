"""A job worker: a process of its own that runs the jobs the service hands it, one at a time.

A worker takes a job id, reads the job from the store, runs the route's own code with the job
limits (``Settings.for_jobs``), writes progress to the store (at most every 0.2 s) and stops at
its next report once a cancel is stored. Workers run at a lower CPU priority than the web
process, so ``/healthz`` and small requests stay fast while jobs run.
"""

from __future__ import annotations

import functools
import json
import logging
import logging.handlers
import multiprocessing
import os
import select
import signal
import threading
import time
from collections.abc import Callable
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from service.config import Settings
from service.convert.errors import request_errors, solver_error_location, solver_error_type
from service.convert.map_json import cell_pages
from service.jobs.dask_runner import ClusterUnavailable
from service.jobs.job import DamagedJob, Job, JobStoreUnavailable
from service.jobs.results import PAGE_CELLS, CellPages, Result
from service.jobs.store import JobStore
from service.logs import duration, log
from service.operations import checked_grid, computed_map, evaluation_of
from service.operations.optimize import optimum_of
from service.schemas import EvaluateRequest, MapRequest, OptimizeRequest
from solver.core.exceptions import SolverError
from solver.core.parallel import TaskRunner, ThreadRunner
from solver.core.progress import Cancelled, Progress
from solver.kernels import fixed_spin as map_kernel
from solver.path.capability_map import map_cost

REPORT_SECONDS = 0.2
"""How often a running job writes its progress (and reads a cancel) at most (s)."""
STORED_CELL_COST = 36.0
"""A map job's cell written to the store (its JSON and its page's row), in the unit of the map's
work (:func:`solver.path.capability_map.map_cost`, closed-form poses): 2.25 us a cell against
8.2 us a placement of the UR5's 133-waypoint map on two threads (386,163 cells, 2026-12-05).
The placements' progress is reported as that share of the job, so that its ETA counts the
storing (before, a 2-million-cell job said 0.0 to 0.1 s left for 83 s)."""

SERVICE_POLL_SECONDS = 0.5
"""How often a worker looks whether its service still runs where it cannot wait for its end
(no ``os.pidfd_open``: not Linux) (s)."""

NICENESS = 10
"""How much lower than the web process's a worker's CPU priority is (``os.nice``)."""

Work = Callable[[dict[str, Any], Settings, Progress, TaskRunner], Result]


def _map(
    request: dict[str, Any], settings: Settings, progress: Progress, runner: TaskRunner
) -> CellPages:
    """The map route's answer, its cells as the route writes them, a store page at a time.

    From the map's columns (:func:`service.convert.map_json.cell_pages`), no model a cell.
    """
    body = MapRequest.model_validate(request)
    checked = checked_grid(body, settings)
    per_cell = map_cost(checked.problem)
    share = per_cell / (per_cell + STORED_CELL_COST)  # the placements' part of the job's work
    computed = computed_map(
        body,
        settings,
        png=False,
        progress=lambda done: progress(share * done),
        runner=runner,
        checked=checked,
    )
    rest = json.loads(computed.rest_json())
    del rest["cells"]
    result = computed.result
    return CellPages(rest, cell_pages(result, computed.robot, page=PAGE_CELLS), result.mu_path.size)


def _optimize(
    request: dict[str, Any], settings: Settings, progress: Progress, runner: TaskRunner
) -> dict[str, Any]:
    body = OptimizeRequest.model_validate(request)
    return optimum_of(body, settings, progress, runner=runner).model_dump(mode="json")


def _evaluate(
    request: dict[str, Any], settings: Settings, progress: Progress, runner: TaskRunner
) -> dict[str, Any]:
    body = EvaluateRequest.model_validate(request)
    return evaluation_of(body, settings, progress).model_dump(mode="json")


KINDS: dict[str, Work] = {"map": _map, "optimize": _optimize, "evaluate": _evaluate}
"""The work of each job kind: the route's own code, its answer as JSON."""


@functools.cache
def task_runner(dask_scheduler: str | None, workers: int) -> TaskRunner:
    """Where a job's placement tasks run: the Dask cluster when one is set, else local threads.

    Args:
        dask_scheduler: the scheduler's address (DTF_DASK_SCHEDULER), or None.
        workers: the local job processes (DTF_WORKERS); each gets cores / workers threads.
    """
    if dask_scheduler is not None:
        from service.jobs.dask_runner import DaskRunner

        return DaskRunner(dask_scheduler)
    return ThreadRunner(max(1, (os.cpu_count() or 1) // workers))


def _what(job: Job) -> str:
    """A job as its log lines name it: its kind, a map's placements, its run."""
    size = f", {job.total:,} placements" if job.kind == "map" and job.total is not None else ""
    return f"{job.kind}{size}, run {job.attempts}"


def run_job(store: JobStore, job_id: str, settings: Settings, owner: str | None = None) -> None:
    """Run one job to its end; every outcome is written to the store.

    The log says what runs (kind, a map's size, which run) and, at its end, how long it took:
    the lines said neither (operator audit of 2026-12-07, M4). ``owner``: the id of the
    service whose worker runs it (:mod:`service.jobs.owner`), kept with the job.
    """
    if not store.start(job_id, owner):
        return  # cancelled while queued, or taken by another worker
    began = time.monotonic()
    try:
        job = store.get(job_id)
    except DamagedJob as error:  # not run, and not left running either
        store.finish(job_id, "failed", error=[{"loc": [], "msg": error.reason, "type": "damaged"}])
        log.error("job %s failed: %s", job_id, error.reason)
        return
    if job is None:
        return
    log.info("job %s running: %s", job_id, _what(job))
    last = [began]

    def progress(fraction: float) -> None:
        now = time.monotonic()
        if now - last[0] >= REPORT_SECONDS:
            last[0] = now
            if store.progress(job_id, fraction):
                raise Cancelled

    def took() -> str:
        return duration(time.monotonic() - began)

    try:
        runner = task_runner(settings.dask_scheduler, settings.workers)
        result = KINDS[job.kind](job.request, settings.for_jobs(), progress, runner)
    except Cancelled:
        store.finish(job_id, "cancelled")
        log.info("job %s cancelled after %s", job_id, took())
    except SolverError as error:
        loc = solver_error_location(error)
        detail = {"loc": loc, "msg": error.message, "type": solver_error_type(error)}
        store.finish(job_id, "failed", error=[detail])
        log.info("job %s failed after %s: %s", job_id, took(), error.message[:200])
    except ClusterUnavailable as error:  # the cluster's fault, not the request's or ours
        detail = {"loc": [], "msg": str(error), "type": "unavailable"}
        store.finish(job_id, "failed", error=[detail])
        log.warning("job %s failed after %s: %s", job_id, took(), error)
    except ValidationError as error:
        # as the route's 422 gives them (errors.request_errors), under the route's body
        located = [{**e, "loc": ("body", *e["loc"])} for e in error.errors()]
        details = [detail.model_dump() for detail in request_errors(located)]
        store.finish(job_id, "failed", error=details)
        log.info("job %s failed: invalid request (%d error(s))", job_id, len(details))
    except Exception as error:  # noqa: BLE001 - a job must end with a status, whatever happens
        message = f"internal error: {type(error).__name__}: {str(error)[:500]}"
        store.finish(job_id, "failed", error=[{"loc": [], "msg": message, "type": "internal"}])
        log.exception("job %s failed after %s", job_id, took())
    else:
        store.finish(job_id, "done", result=result)
        log.info("job %s done in %s", job_id, took())


def _die_with_the_service() -> None:
    """Have this worker kill itself when the service that started it ends, even by SIGKILL.

    No orphan worker then goes on with a job that the restarted service runs again. A thread
    waits for the service's end (a pidfd on Linux, else a look every SERVICE_POLL_SECONDS).
    Not Linux's parent death signal (``PR_SET_PDEATHSIG``): a worker's parent is the fork
    server (:func:`service.jobs.runner.worker_context`), which lives on as long as any worker
    does; with the signal a service killed by SIGKILL left both running, and the job on.
    Nothing is watched where no service started this process (``serve`` called in a test).
    """
    service = multiprocessing.parent_process()  # the process that asked for this one
    if service is None or service.pid is None:
        return
    watch = threading.Thread(
        target=_end_with, args=(service.pid,), name="dtf-service-watch", daemon=True
    )
    watch.start()


def _end_with(pid: int) -> None:
    """Wait until the process ``pid`` ends, then kill this one (as a SIGKILL from outside)."""
    try:
        handle: int | None = os.pidfd_open(pid)
    except ProcessLookupError:  # already gone
        handle = None
    except (AttributeError, OSError):  # no pidfd here: look now and then
        while _runs(pid):
            time.sleep(SERVICE_POLL_SECONDS)
        handle = None
    if handle is not None:
        select.select([handle], [], [])  # readable once it has ended
    os.kill(os.getpid(), signal.SIGKILL)


def _runs(pid: int) -> bool:
    """Whether the process ``pid`` exists (another user's too: a signal refused says it does)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    return True


class _Pipe:
    """The worker's end of its pipe as a :class:`logging.handlers.QueueHandler`'s queue.

    Each record goes to the web process (:meth:`service.jobs.runner.JobRunner`'s look), which
    logs it there, where the operator's logging configuration places it; the job's answer goes
    the same way, after its lines. One lock for both: a pipe's sends must not interleave.
    """

    def __init__(self, connection: Connection) -> None:
        self.connection = connection
        self.lock = threading.Lock()

    def put_nowait(self, message: Any) -> None:
        """Send ``message`` (a log record, or the job's answer) to the web process."""
        with self.lock:
            self.connection.send(message)


def _log_to_the_service(pipe: _Pipe) -> None:
    """The worker's ``dtf`` lines go to the web process, which says them as its own are said.

    They went to the worker's own stderr in the service's form: an operator's logging
    configuration (``uvicorn --log-config``) placed the web process's lines and never the
    workers' (the operator audit of 2026-12-07). The web process filters them by its levels.
    """
    logger = logging.getLogger("dtf")
    for handler in list(logger.handlers):
        logger.removeHandler(handler)
    logger.addHandler(logging.handlers.QueueHandler(pipe))  # type: ignore[arg-type]  # a queue that only puts
    logger.setLevel(logging.DEBUG)
    logger.propagate = False


def serve(
    connection: Connection, store_path: str, settings_json: str, owner: str | None = None
) -> None:
    """A worker process's life: run each job id received, answer it back when it has ended.

    The job's log lines and its answer go back through ``connection`` (:class:`_Pipe`).
    ``owner``: the id of the service that started the worker (:mod:`service.jobs.owner`).
    """
    _die_with_the_service()
    os.nice(NICENESS)
    pipe = _Pipe(connection)
    _log_to_the_service(pipe)
    store = JobStore(Path(store_path), create=False)  # never a new, empty file
    settings = Settings.model_validate_json(settings_json)
    map_kernel.warm_up()  # before the first job, not in it
    while True:
        try:
            job_id = connection.recv()
        except (EOFError, OSError):
            return  # the service has gone
        try:
            run_job(store, job_id, settings, owner)
            stored = True
        except JobStoreUnavailable as error:  # the supervisor reports the store (once)
            stored = fail_unstored(store, job_id, error)
        pipe.put_nowait((job_id, stored))


UNSTORED = "unstored"
"""The error type of a job whose end the store could not take (a full disk, say)."""


def fail_unstored(store: JobStore, job_id: str, error: JobStoreUnavailable) -> bool:
    """End as failed a job whose end could not be written; whether that could be.

    Writing its result failed (a full disk: rolled back, the job still running); a failure is a
    small write, which the store often takes then. Left running, a job was polled ``running``
    forever, kept its place in the queue and did not end on a cancel (the operator audit of
    2026-12-07, H1; logged "not run" as a warning). Where even that write fails the worker
    says so to the supervisor, which queues the job again or ends it once the store answers
    (:meth:`service.jobs.runner.JobRunner.settle`). A job that did not start (the store
    failing before it) is left as it was: ``if_running``.
    """
    message = f"its end could not be written to the job store: {error.reason}"
    try:
        detail = {"loc": [], "msg": message, "type": UNSTORED}
        ended = store.finish(job_id, "failed", error=[detail], if_running=True)
    except JobStoreUnavailable as again:
        log.error("job %s: %s; nor its failure (%s): to the supervisor", job_id, message, again)
        return False
    if ended:
        log.error("job %s failed: %s", job_id, message)
    else:  # the store failed before the job ran (it waits, queued), or it was deleted
        log.warning("job %s not run: %s", job_id, error.reason)
    return True
