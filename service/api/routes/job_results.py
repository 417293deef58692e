"""A done map job's cells in pages (``GET /v1/jobs/{id}/result``, api.md "Jobs"), and its picture.

A map job may have 2 million placements; its answer as one body would be hundreds of MiB.
``GET /v1/jobs/{id}`` answers a result over DTF_JOB_PAGE_CELLS cells without its cells, and
``/result`` gives them a page at a time, reading only that page from the store.
``GET /v1/jobs/{id}/png`` draws the stored cells as ``POST /v1/map/png`` draws a map: a map too
large for a request has its picture too, without computing it again.
"""

from __future__ import annotations

import json
from contextlib import closing
from typing import Annotated
from uuid import UUID

from fastapi import APIRouter, HTTPException, Query, Request, Response, status
from fastapi.exceptions import RequestValidationError
from pydantic import ValidationError

from service import convert
from service.api.routes.jobs import JOB_RESPONSES, NOT_FOUND, JobId
from service.config import Settings
from service.convert.stored_map import StoredCellsMismatch, reported, stored_grid, stored_map
from service.deps import SettingsDep
from service.errors import job_not_found
from service.jobs.job import DamagedJob, JobState
from service.jobs.runner import get_runner
from service.jobs.store import JobStore
from service.jobs.views import page_url
from service.operations import map_png
from service.schemas import ErrorResponse, MapRequest
from service.schemas.jobs import JobResultPage
from service.work import run_stoppable
from solver.core.progress import Progress

router = APIRouter(prefix="/jobs", tags=["jobs"], responses=JOB_RESPONSES)


@router.get(
    "/{job_id}/result",
    operation_id="get_job_result",
    summary="A page of a map job's cells",
    response_model=JobResultPage,
    responses={
        **NOT_FOUND,
        409: {
            "model": ErrorResponse,
            "description": "The job is not done, or its result has no cells (not a map).",
        },
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
    state = _done_map(store, str(job_id), "no result to page")
    cells, count = store.cells_json(state.id, offset=offset, limit=page_limit)
    end = offset + count
    total = state.cells if state.cells is not None else store.cell_count(state.id)
    if count == 0 and offset < total and store.state(state.id) is None:
        # deleted by another client between the state's read and the cells': a page of no
        # cells within the total, whose next is itself, would be the answer (audit 26, F10)
        raise job_not_found(job_id, why=" (deleted while its page was read)")
    after = page_url(state.id, offset=end, limit=page_limit) if end < total else None
    head = {
        "offset": offset,
        "limit": page_limit,
        "total": total,
        "next": after,
        "next_offset": end if end < total else None,
    }
    # The cells are stored JSON, copied as they are: the page's text is put together here.
    text = json.dumps(head)[:-1] + f', "cells": {cells}}}'
    return Response(text, media_type="application/json")


@router.get(
    "/{job_id}/png",
    operation_id="get_job_png",
    summary="A done map job's colour map, as a PNG",
    response_class=Response,
    responses={
        200: {
            "content": {"image/png": {"schema": {"type": "string", "format": "binary"}}},
            "description": "The map as POST /v1/map/png draws it for the job's request (the "
            "same picture), drawn from the stored cells.",
        },
        **NOT_FOUND,
        409: {
            "model": ErrorResponse,
            "description": "The job is not done, is not a map, its map has more panels "
            "(yaws x spins) than a picture draws (DTF_MAX_PNG_PANELS), or its request was "
            "stored by a release whose map requests this one does not read.",
        },
    },
)
async def get_job_png(request: Request, job_id: JobId, settings: SettingsDep) -> Response:
    """The colour map of a done map job, drawn from its stored cells (no map computed again).

    ``POST /v1/map/png`` computes a map within a request's limits; a map run as a job (up to
    DTF_MAX_JOB_CELLS placements) is drawn here. The stored cells are read a page at a
    time (about 2 s a million cells), in a worker thread, and the reading stops when the
    client leaves.
    """
    return await run_stoppable(request, lambda progress: job_picture(job_id, settings, progress))


def job_picture(job_id: UUID, settings: Settings, progress: Progress) -> Response:
    """:func:`get_job_png`'s work; ``progress`` told each page read (it raises to stop)."""
    store = get_runner(settings).store
    state = _done_map(store, str(job_id), "no map to draw")
    asked = store.request(state.id)
    if asked is None:  # deleted (or expired) since its state was read
        raise job_not_found(job_id)
    try:
        body = MapRequest.model_validate(asked)
    except ValidationError as error:  # stored by a release whose map requests differ
        first = error.errors()[0]
        said = f"{'.'.join(map(str, first['loc']))}: {first['msg']}"
        raise HTTPException(
            status.HTTP_409_CONFLICT,
            f"job {state.id!r}: its request is not a map request this release reads ({said}); "
            f"its cells are at GET /v1/jobs/{state.id}/result",
        ) from None
    over = convert.png_panels_over(stored_grid(body), settings=settings)
    if over is not None:
        raise HTTPException(
            status.HTTP_409_CONFLICT,
            f"job {state.id!r}: its map has {over}; its cells are at GET "
            f"/v1/jobs/{state.id}/result",
        )
    robot = convert.robot_from_schema(body.robot)
    try:
        # closed here, in this worker thread, on every way out (its SQLite connection is this
        # thread's): left to the garbage collector, a generator stopped by a client's leaving
        # kept its read transaction open, and the store's checkpoints waiting, until a cycle
        # collection ran on another thread, where its connection could not be closed
        with closing(store.cell_pages(state.id)) as cells:
            cmap = stored_map(body, robot, reported(cells, progress, total=state.cells or 1))
    except StoredCellsMismatch as error:
        if store.state(state.id) is None:  # deleted (or expired) before its cells were read
            raise job_not_found(job_id) from None
        raise DamagedJob(store.path, state.id, str(error)) from None
    return Response(map_png(cmap, robot), media_type="image/png")


def _done_map(store: JobStore, job_id: str, nothing: str) -> JobState:
    """The state of a done map job; else 404 (unknown) or 409 (saying ``nothing``, and why)."""
    state = store.state(job_id)
    if state is None:
        raise job_not_found(job_id)
    if state.status != "done":
        raise HTTPException(
            status.HTTP_409_CONFLICT, f"job {state.id!r} is {state.status}: {nothing}"
        )
    if state.kind != "map":
        raise HTTPException(
            status.HTTP_409_CONFLICT,
            f"job {state.id!r} is {'an' if state.kind[0] in 'aeiou' else 'a'} {state.kind} "
            f"job: {nothing}; "
            f"GET /v1/jobs/{state.id} gives its result",
        )
    return state
