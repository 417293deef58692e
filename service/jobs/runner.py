"""Jobs run in a local process pool, outside the web process (api.md "Jobs").

A worker process takes a job id, reads the job from the store, runs the route's own code with
the job limits (``Settings.for_jobs``), reports progress to the store (at most every 0.2 s) and
stops at its next report once a cancel is stored. The web process only submits ids, so
``/healthz`` and small requests stay fast while jobs run.
"""

from __future__ import annotations

import multiprocessing
import time
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from service.config import Settings
from service.errors import request_location, solver_error_location
from service.jobs.store import JobStore
from service.metrics import log, log_to_stderr
from solver.exceptions import SolverError
from solver.progress import Cancelled, Progress

REPORT_SECONDS = 0.2
"""How often a running job writes its progress (and reads a cancel) at most (s)."""

Work = Callable[[dict[str, Any], Settings, Progress], dict[str, Any]]


def _map(request: dict[str, Any], settings: Settings, progress: Progress) -> dict[str, Any]:
    from service.api.routes.map import map_of
    from service.schemas import MapRequest

    return map_of(MapRequest.model_validate(request), settings, progress).model_dump(mode="json")


def _optimize(request: dict[str, Any], settings: Settings, progress: Progress) -> dict[str, Any]:
    from service.api.routes.optimize import optimum_of
    from service.schemas import OptimizeRequest

    body = OptimizeRequest.model_validate(request)
    return optimum_of(body, settings, progress).model_dump(mode="json")


def _evaluate(request: dict[str, Any], settings: Settings, progress: Progress) -> dict[str, Any]:
    from service.api.routes.evaluate import evaluation_of
    from service.schemas import EvaluateRequest

    body = EvaluateRequest.model_validate(request)
    return evaluation_of(body, settings, progress).model_dump(mode="json")


KINDS: dict[str, Work] = {"map": _map, "optimize": _optimize, "evaluate": _evaluate}
"""The work of each job kind: the route's own code, its answer as JSON."""


def run_job(store_path: str, job_id: str, settings_json: str) -> None:
    """Run one job to its end, in a worker process; every outcome is written to the store."""
    log_to_stderr()
    store = JobStore(Path(store_path))
    if not store.start(job_id):
        return  # cancelled while queued, or taken by another worker
    log.info("job %s running", job_id)
    job = store.get(job_id)
    if job is None:
        return
    settings = Settings.model_validate_json(settings_json).for_jobs()
    last = [time.monotonic()]

    def progress(fraction: float) -> None:
        now = time.monotonic()
        if now - last[0] >= REPORT_SECONDS:
            last[0] = now
            if store.progress(job_id, fraction):
                raise Cancelled

    try:
        result = KINDS[job.kind](job.request, settings, progress)
    except Cancelled:
        store.finish(job_id, "cancelled")
        log.info("job %s cancelled", job_id)
    except SolverError as error:
        loc = solver_error_location(error)
        detail = {"loc": loc, "msg": error.message, "type": "invalid_input"}
        store.finish(job_id, "failed", error=[detail])
        log.info("job %s failed: %s", job_id, error.message[:200])
    except ValidationError as error:
        details = [
            {"loc": request_location(("body", *e["loc"])), "msg": e["msg"], "type": e["type"]}
            for e in error.errors()
        ]
        store.finish(job_id, "failed", error=details)
        log.info("job %s failed: invalid request", job_id)
    except Exception as error:  # noqa: BLE001 - a job must end with a status, whatever happens
        detail = {"loc": [], "msg": f"internal error: {type(error).__name__}", "type": "internal"}
        store.finish(job_id, "failed", error=[detail])
        log.exception("job %s failed", job_id)
    else:
        store.finish(job_id, "done", result=result)
        log.info("job %s done", job_id)


class JobRunner:
    """The store and the process pool of one service."""

    def __init__(self, settings: Settings) -> None:
        """Open the store under the data directory and start the pool (spawned processes)."""
        self.settings = settings
        self.store = JobStore(Path(settings.data_dir) / "jobs.sqlite3")
        self._pool = ProcessPoolExecutor(
            max_workers=settings.workers, mp_context=multiprocessing.get_context("spawn")
        )

    def submit(self, job_id: str) -> Future[None]:
        """Run a stored job in the pool."""
        return self._pool.submit(
            run_job, str(self.store.path), job_id, self.settings.model_dump_json()
        )

    def recover(self) -> list[str]:
        """Forget expired jobs, then queue again and run every job a restart interrupted."""
        self.store.expire(ttl=self.settings.job_ttl)
        ids = self.store.recover(attempts=self.settings.job_attempts)
        for job_id in ids:
            self.submit(job_id)
        return ids

    def close(self) -> None:
        """Stop the pool without waiting (unfinished jobs run again after a restart)."""
        self._pool.shutdown(wait=False, cancel_futures=True)


_RUNNERS: dict[str, JobRunner] = {}


def get_runner(settings: Settings) -> JobRunner:
    """The service's runner for these settings, made on first use."""
    key = settings.model_dump_json()
    if key not in _RUNNERS:
        _RUNNERS[key] = JobRunner(settings)
    return _RUNNERS[key]


def close_runners() -> None:
    """Stop every runner's pool (the service is shutting down)."""
    for runner in _RUNNERS.values():
        runner.close()
    _RUNNERS.clear()
