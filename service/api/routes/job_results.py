"""``GET /v1/jobs/{id}/result``: a done map job's cells in pages (api.md "Jobs").

A map job may have 2 million placements; its answer as one body would be hundreds of MiB.
``GET /v1/jobs/{id}`` answers a result over DTF_JOB_PAGE_CELLS cells without its cells, and
this route gives them a page at a time, reading only that page from the store.
"""

from __future__ import annotations

import json
from typing import Annotated

from fastapi import APIRouter, HTTPException, Query, Response, status
from fastapi.exceptions import RequestValidationError

from service.api.routes.jobs import JOB_RESPONSES, NOT_FOUND, JobId
from service.deps import SettingsDep
from service.errors import job_not_found
from service.jobs.runner import get_runner
from service.jobs.views import page_url
from service.schemas.jobs import JobResultPage

router = APIRouter(prefix="/jobs", tags=["jobs"], responses=JOB_RESPONSES)


@router.get(
    "/{job_id}/result",
    operation_id="get_job_result",
    summary="A page of a map job's cells",
    response_model=JobResultPage,
    responses={
        **NOT_FOUND,
        409: {"description": "The job is not done, or its result has no cells (not a map)."},
    },
)
def get_job_result_page(
    job_id: JobId,
    settings: SettingsDep,
    offset: Annotated[int, Query(ge=0, description="The index of the first cell.")] = 0,
    limit: Annotated[
        int | None,
        Query(ge=1, description="Most cells to give (default and largest: DTF_JOB_PAGE_CELLS)."),
    ] = None,
) -> Response:
    """Cells ``offset`` to ``offset + limit`` of a done map job (``next``: the next page).

    They equal the same cells of ``POST /v1/map``'s answer; ``next`` is the following page's
    URL, null on the last one. Only these cells are read from the store, so any page of a
    2-million-placement map costs the same. A ``limit`` over DTF_JOB_PAGE_CELLS is a 422 naming it.
    """
    page_limit = settings.job_page_cells if limit is None else limit
    if page_limit > settings.job_page_cells:
        raise RequestValidationError(
            [
                {
                    "loc": ("query", "limit"),
                    "msg": f"at most {settings.job_page_cells} cells a page (DTF_JOB_PAGE_CELLS)",
                    "type": "less_than_equal",
                    "input": limit,
                }
            ]
        )
    store = get_runner(settings).store
    state = store.state(str(job_id))
    if state is None:
        raise job_not_found(job_id)
    if state.status != "done":
        raise HTTPException(
            status.HTTP_409_CONFLICT, f"job {state.id!r} is {state.status}: no result to page"
        )
    if state.kind != "map":
        raise HTTPException(
            status.HTTP_409_CONFLICT,
            f"job {state.id!r} is a {state.kind} job: its result has no cells to page; "
            f"GET /v1/jobs/{state.id} gives it whole",
        )
    cells, count = store.cells_json(state.id, offset=offset, limit=page_limit)
    end = offset + count
    total = state.cells if state.cells is not None else store.cell_count(state.id)
    after = page_url(state.id, offset=end, limit=page_limit) if end < total else None
    head = {"offset": offset, "limit": page_limit, "total": total, "next": after}
    # The cells are stored JSON, copied as they are: the page's text is put together here.
    text = json.dumps(head)[:-1] + f', "cells": {cells}}}'
    return Response(text, media_type="application/json")
