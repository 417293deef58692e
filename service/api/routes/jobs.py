"""``/v1/jobs``: submit long work, watch its progress, read its result, cancel it (api.md).

Cancel and delete are two operations: ``POST /v1/jobs/{id}/cancel`` stops the work and keeps
the job (status ``cancelled``, readable until DTF_JOB_TTL, as the page shows it);
``DELETE /v1/jobs/{id}`` cancels it too and forgets it, so that a ``GET`` afterwards is 404.
While the job store cannot be used, every route here answers 503 saying why.
"""

from __future__ import annotations

import functools
import json
from typing import Annotated, Any
from uuid import UUID

import anyio
from fastapi import APIRouter, HTTPException, Path, Query, Response, status
from fastapi.responses import JSONResponse

from service.body import union_body_in_thread, union_body_openapi
from service.deps import SettingsDep
from service.errors import ERROR_RESPONSES, RETRY_AFTER, job_not_found
from service.jobs.checks import check_job
from service.jobs.job import QueueFull
from service.jobs.runner import get_runner
from service.jobs.views import job_info, units_of
from service.logs import log
from service.schemas import ErrorDetail, ErrorResponse
from service.schemas.jobs import (
    EvaluateJob,
    JobInfo,
    JobKind,
    JobList,
    JobRequest,
    JobStatus,
    MapJob,
    OptimizeJob,
)
from service.work import json_response

JOB_RESPONSES: dict[int | str, dict[str, Any]] = {
    **ERROR_RESPONSES,
    status.HTTP_503_SERVICE_UNAVAILABLE: {
        "model": ErrorResponse,
        "description": "The job store cannot be used (corrupt, replaced or deleted file: the "
        "detail says which), or the service is shutting down; retry after Retry-After. The "
        "compute routes are not affected.",
        "headers": RETRY_AFTER,
    },
}

router = APIRouter(prefix="/jobs", tags=["jobs"], responses=JOB_RESPONSES)

JobId = Annotated[UUID, Path(description="The job's id, as POST /v1/jobs answered it.")]

JOB_MODELS = (MapJob, OptimizeJob, EvaluateJob)
"""The kinds of job a body may be (JobRequest's members, in its order)."""

NOT_FOUND: dict[int | str, dict[str, Any]] = {
    404: {"model": ErrorResponse, "description": "No job has this id (or it expired)."}
}


@router.post(
    "",
    operation_id="submit_job",
    summary="Run a map, optimisation or evaluation as a job",
    status_code=status.HTTP_202_ACCEPTED,
    response_model=JobInfo,
    responses={
        202: {
            "description": "Queued: the job as GET /v1/jobs/{id} answers it.",
            "headers": {
                "Location": {
                    "description": "The job's URL, /v1/jobs/{id}.",
                    "schema": {"type": "string"},
                }
            },
        },
        429: {
            "model": ErrorResponse,
            "description": "Too many jobs queued or running (DTF_MAX_QUEUED_JOBS); retry after "
            "Retry-After.",
            "headers": RETRY_AFTER,
        },
    },
    openapi_extra=union_body_openapi(JOB_MODELS),
)
async def post_job(
    body: Annotated[JobRequest, union_body_in_thread(JobRequest, JOB_MODELS)],
    settings: SettingsDep,
) -> JSONResponse:
    """Queue the work; answer 202 with its id and Location.

    A large body (a 20,000-waypoint path) is validated off the event loop, in pieces.

    The request is checked as its route checks it before it is queued (the robot, the path as
    read, the options, the grid, the bounds), with the route's error types, a field inside the
    job (``request.path.csv``); job limits (DTF_MAX_JOB_CELLS, DTF_MAX_JOB_POSES) replace the
    routes' own. The queue's limit (DTF_MAX_QUEUED_JOBS) is counted in the insert's transaction.
    """
    await anyio.to_thread.run_sync(check_job, body, settings)
    runner = get_runner(settings)
    request = body.request.model_dump(mode="json", exclude_unset=True)
    try:
        job = await anyio.to_thread.run_sync(
            functools.partial(
                runner.store.create,
                body.kind,
                request,
                total=units_of(body),
                limit=settings.max_queued_jobs,
            )
        )
    except QueueFull:
        detail = ErrorDetail(
            loc=[],
            msg=f"{settings.max_queued_jobs} jobs are queued or running, every client's "
            "(DTF_MAX_QUEUED_JOBS): submit again once some have ended (Retry-After)",
            type="queue_full",
        )
        raise HTTPException(
            status.HTTP_429_TOO_MANY_REQUESTS,
            [detail.model_dump()],
            headers={"Retry-After": "10"},
        ) from None
    runner.wake()  # an idle worker takes the job now
    log.info("job %s queued (%s)", job.id, body.kind)
    info = job_info(job, runner.store)
    return JSONResponse(
        info.model_dump(mode="json"),
        status_code=status.HTTP_202_ACCEPTED,
        headers={"Location": f"/v1/jobs/{job.id}"},
    )


@router.get(
    "",
    operation_id="list_jobs",
    summary="The jobs, newest first, without results",
    responses=NOT_FOUND,
)
def get_jobs(
    settings: SettingsDep,
    job_status: Annotated[
        JobStatus | None,
        Query(
            alias="status", description="Only the jobs in this state (all of them if not given)."
        ),
    ] = None,
    kind: Annotated[
        JobKind | None,
        Query(description="Only the jobs of this kind (every client's: the page lists maps)."),
    ] = None,
    limit: Annotated[
        int, Query(ge=1, le=1000, description="Most jobs to list (the page's length).")
    ] = 100,
    after: Annotated[
        UUID | None,
        Query(
            description="A job's id: the listing goes on after that job's place in it (the "
            "last id of the previous page; a position, whatever that job's kind or status), "
            "also when that job was deleted or expired since (its place is kept for another "
            "DTF_JOB_TTL). An id the store never held, or forgot longer ago, is a 404 naming "
            "``after``."
        ),
    ] = None,
) -> JobList:
    """Every job the store holds (finished ones until DTF_JOB_TTL), newest first.

    Results are not read: ``result`` is null here; ``GET /v1/jobs/{id}`` gives it. A listing
    longer than ``limit`` is read in pages: ``after`` the last id of one page gives the next
    (jobs submitted in the same instant are in the order of their ids).
    """
    store = get_runner(settings).store
    if after is not None and not store.placed(str(after)):
        # a 404, as the same id in the path is: the job it names is not there
        raise job_not_found(
            after,
            loc=("query", "after"),
            why=" (never held, or forgotten over DTF_JOB_TTL ago: its place in the listing too)",
        )
    states = store.jobs(
        status=job_status, kind=kind, limit=limit, after=None if after is None else str(after)
    )
    return JobList(jobs=[job_info(state, store) for state in states])


@router.get(
    "/{job_id}",
    operation_id="get_job",
    summary="A job's status and result",
    response_model=JobInfo,
    responses=NOT_FOUND,
)
def get_job(job_id: JobId, settings: SettingsDep) -> Response:
    """Status, progress with ETA, times, and the route's answer once done (or the error).

    A map's answer holds its cells up to DTF_JOB_PAGE_CELLS (default 10,000) of them; a larger
    one comes without ``cells``, and ``result_cells`` says how many there are and where the
    first page is: ``GET /v1/jobs/{id}/result?offset=0&limit=10000``, then each page's
    ``next``.
    """
    store = get_runner(settings).store
    job = store.get(str(job_id), inline_cells=settings.job_page_cells)
    if job is None:
        raise job_not_found(job_id)
    return json_response(
        job_info(job, store, result=job.result, page_limit=settings.job_page_cells)
    )


@router.get(
    "/{job_id}/request",
    operation_id="get_job_request",
    summary="What a job computes: its kind and request, as submitted",
    response_class=Response,
    responses={
        200: {
            "description": "The job's body, as POST /v1/jobs took it.",
            "content": {
                "application/json": {
                    "schema": {
                        "oneOf": [
                            {"$ref": f"#/components/schemas/{model.__name__}"}
                            for model in JOB_MODELS
                        ]
                    }
                }
            },
        },
        **NOT_FOUND,
    },
)
def get_job_request(job_id: JobId, settings: SettingsDep) -> Response:
    """The body ``POST /v1/jobs`` took: its ``kind`` and ``request`` (the fields it was given).

    For a client that no longer holds it (a page reloaded while its map ran): a map's cells are
    evaluated with their own request. Not in ``GET /v1/jobs/{id}``, which a client polls: a
    request may hold a path of 20,000 waypoints.
    """
    store = get_runner(settings).store
    state = store.state(str(job_id))
    request = store.request(str(job_id))
    if state is None or request is None:
        raise job_not_found(job_id)
    body = json.dumps({"kind": state.kind, "request": request}, separators=(",", ":"))
    return Response(body, media_type="application/json")


@router.post(
    "/{job_id}/cancel",
    operation_id="cancel_job",
    summary="Cancel a queued or running job, keeping it",
    responses=NOT_FOUND,
)
def cancel_job(job_id: JobId, settings: SettingsDep) -> JobInfo:
    """A queued job is cancelled now; a running one stops within a second.

    The job stays (``cancelled`` once stopped, readable until DTF_JOB_TTL); a finished job is
    left as it is. The answer is the job after the cancel was asked.
    """
    runner = get_runner(settings)
    if runner.store.state(str(job_id)) is None:
        raise job_not_found(job_id)
    runner.store.cancel(str(job_id))
    runner.wake()  # the supervisor sees the cancel now
    log.info("job %s cancel asked", job_id)
    state = runner.store.state(str(job_id))
    if state is None:  # deleted meanwhile
        raise job_not_found(job_id)
    return job_info(state, runner.store)


@router.delete(
    "/{job_id}",
    operation_id="delete_job",
    summary="Delete a job, cancelling it first",
    status_code=status.HTTP_204_NO_CONTENT,
    responses=NOT_FOUND,
)
def delete_job(job_id: JobId, settings: SettingsDep) -> Response:
    """Cancel the job (its work stops within a second) and forget it and its result.

    Afterwards the id is unknown (404), as for a job that expired.
    """
    runner = get_runner(settings)
    runner.store.cancel(str(job_id))
    if not runner.store.delete(str(job_id)):
        raise job_not_found(job_id)
    runner.wake()  # the supervisor stops a running job's worker now
    log.info("job %s deleted", job_id)
    return Response(status_code=status.HTTP_204_NO_CONTENT)
