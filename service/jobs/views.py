"""The API's view of a stored job: its progress in units of work, where a map's cells are."""

from __future__ import annotations

import time
from typing import Any

from service.jobs.job import JobState
from service.jobs.store import JobStore
from service.schemas import ErrorDetail, MapRequest
from service.schemas.jobs import JobInfo, JobProgress, JobRequest, MapJob, ResultCells


def _units(state: JobState, store: JobStore) -> int:
    """Units of work of a job: a map's placements, else 100 (percent).

    Stored with the job; read from its request for a job an older release stored.
    """
    if state.total is not None:
        return state.total
    request = store.request(state.id) if state.kind == "map" else None
    return (
        100 if request is None else max(1, MapRequest.model_validate(request).grid.n_placements())
    )


def units_of(body: JobRequest) -> int:
    """Units of work of a job request: a map's placements, else 100 (percent)."""
    if isinstance(body, MapJob):
        return max(1, body.request.grid.n_placements())
    return 100


def page_url(job_id: str, *, offset: int, limit: int) -> str:
    """The URL of a page of a map job's cells (``GET /v1/jobs/{id}/result``)."""
    return f"/v1/jobs/{job_id}/result?offset={offset}&limit={limit}"


def eta_seconds(state: JobState, now: float) -> float | None:
    """The time a running job needs yet (s) at ``now``, at its rate of progress; else None.

    The rate is taken from the run's first progress report on: before it the run sets up
    (reads its request, builds its problem, an optimiser's first generation), and taken from
    the start, that time counted as progress made the first estimates several times too high
    (900 s said with 65 s left, the audit of stop 58). None until a second report gives a rate;
    a row of an older release, which kept no first report, from the start.
    """
    if state.status != "running" or state.started is None or state.fraction <= 0.0:
        return None
    if state.first_report is None:
        return (now - state.started) * (1.0 - state.fraction) / state.fraction
    at, done = state.first_report
    if state.fraction > done and now > at:
        return (now - at) * (1.0 - state.fraction) / (state.fraction - done)
    return None


def job_info(
    state: JobState,
    store: JobStore,
    *,
    result: dict[str, Any] | None = None,
    page_limit: int = 0,
) -> JobInfo:
    """The API's view of a stored job (its result as given; where a map's cells are)."""
    total = _units(state, store)
    eta = eta_seconds(state, time.time())
    cells = None
    if state.cells is not None and page_limit > 0:
        cells = ResultCells(
            total=state.cells,
            in_result=result is not None and "cells" in result,
            page_limit=page_limit,
            first_page=page_url(state.id, offset=0, limit=page_limit),
        )
    return JobInfo(
        id=state.id,
        kind=state.kind,
        status=state.status,
        progress=JobProgress(
            done=round(state.fraction * total),
            total=total,
            fraction=state.fraction,
            eta_seconds=eta,
        ),
        created=state.created,
        started=state.started,
        finished=state.finished,
        result=result,
        error=None if state.error is None else [ErrorDetail(**e) for e in state.error],
        result_cells=cells,
    )
