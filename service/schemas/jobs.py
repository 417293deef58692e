"""``/v1/jobs``: long work as persisted jobs with progress and cancel (api.md "Jobs")."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import ConfigDict, Discriminator, Field, Tag, WithJsonSchema
from pydantic.config import JsonDict
from typing_extensions import TypeAliasType

from service.schemas.common import RequestModel, ResponseModel
from service.schemas.errors import ErrorDetail
from service.schemas.evaluate_request import _REQUEST_EXAMPLE, EvaluateRequest
from service.schemas.map import _CELL, _MAP_REQUEST_EXAMPLE, MapCell, MapRequest
from service.schemas.optimize import _REQUEST as _OPTIMIZE_EXAMPLE
from service.schemas.optimize import OptimizeRequest

JobStatus = TypeAliasType(
    "JobStatus",
    Annotated[
        Literal["queued", "running", "done", "failed", "cancelled"],
        Field(
            description="Where a job is: queued, running, done, failed or cancelled.",
            examples=["done"],
        ),
    ],
)
"""One component for a job's status and the status filter of GET /v1/jobs."""
JobKind = TypeAliasType(
    "JobKind",
    Annotated[
        Literal["map", "optimize", "evaluate"],
        Field(
            description="What a job computes: a map, an optimisation or an evaluation.",
            examples=["map"],
        ),
    ],
)
"""One component for a job's kind and the kind filter of GET /v1/jobs."""
JobResult = Annotated[
    dict[str, Any] | None,
    WithJsonSchema(
        {
            "anyOf": [
                {"$ref": "#/components/schemas/MapResponse"},
                {"$ref": "#/components/schemas/MapResponseWithoutCells"},
                {"$ref": "#/components/schemas/OptimizeResponse"},
                {"$ref": "#/components/schemas/EvaluateResponse"},
                {"type": "null"},
            ]
        }
    ),
]
"""A finished job's answer, as its route gives it (kept as stored; typed for clients)."""


class MapJob(RequestModel):
    """A map as a job: the body of POST /v1/map, with the job limits."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"kind": "map", "request": _MAP_REQUEST_EXAMPLE}]}
    )

    kind: Literal["map"] = Field(description='"map".')
    request: MapRequest = Field(description="The body POST /v1/map takes.")


class OptimizeJob(RequestModel):
    """An optimisation as a job: the body of POST /v1/optimize."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"kind": "optimize", "request": _OPTIMIZE_EXAMPLE}]}
    )

    kind: Literal["optimize"] = Field(description='"optimize".')
    request: OptimizeRequest = Field(description="The body POST /v1/optimize takes.")


class EvaluateJob(RequestModel):
    """An evaluation as a job: the body of POST /v1/evaluate."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"kind": "evaluate", "request": _REQUEST_EXAMPLE}]}
    )

    kind: Literal["evaluate"] = Field(description='"evaluate".')
    request: EvaluateRequest = Field(description="The body POST /v1/evaluate takes.")


JOB_KINDS = ("map", "optimize", "evaluate")
"""The kinds of job, in JobRequest's order."""


def _job_kind(value: object) -> str | None:
    """Tag of a job: ``job:<kind>`` (the tag is left out of error locs)."""
    kind = value.get("kind") if isinstance(value, dict) else getattr(value, "kind", None)
    return f"job:{kind}" if kind in JOB_KINDS else None


JobRequest = Annotated[
    Annotated[MapJob, Tag("job:map")]
    | Annotated[OptimizeJob, Tag("job:optimize")]
    | Annotated[EvaluateJob, Tag("job:evaluate")],
    Discriminator(
        _job_kind,
        custom_error_type="job_kind",
        custom_error_message='give kind: "map", "optimize" or "evaluate"',
        custom_error_context={"tag_field": "kind"},  # the error's loc (service.body)
    ),
]
"""A job: its kind and the route's own request body."""


class JobProgress(ResponseModel):
    """How far a job is."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [{"done": 1200, "total": 5000, "fraction": 0.24, "eta_seconds": 9.5}]
        }
    )

    done: int = Field(description="Units of work done (placements for a map, else percent).")
    total: int = Field(description="Units of work in all.")
    fraction: float = Field(description="done / total, 0 to 1.")
    eta_seconds: float | None = Field(
        description="Estimated seconds to the end, at the rate of progress since the run's "
        "first report (its set-up before it is not counted); null unless running, and until "
        "a second report gives a rate."
    )


_JOB_EXAMPLE: JsonDict = {
    "id": "0b6f3c1e-7f1e-4d0a-9d55-3c5d8b1f2a10",
    "kind": "map",
    "status": "running",
    "progress": {"done": 1200, "total": 5000, "fraction": 0.24, "eta_seconds": 9},
    "created": 1764000000.0,
    "started": 1764000000.5,
    "finished": None,
    "result": None,
    "error": None,
}


class ResultCells(ResponseModel):
    """Where a map job's cells are: in its result, or in pages of GET /v1/jobs/{id}/result."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "total": 500000,
                    "in_result": False,
                    "page_limit": 10000,
                    "first_page": "/v1/jobs/0b6f3c1e-7f1e-4d0a-9d55-3c5d8b1f2a10/result"
                    "?offset=0&limit=10000",
                }
            ]
        }
    )

    total: int = Field(description="Cells in the map's answer.")
    in_result: bool = Field(
        description="Whether ``result.cells`` holds them all (at most DTF_JOB_PAGE_CELLS); when "
        "false the result has no ``cells``: read them in pages from ``first_page`` on."
    )
    page_limit: int = Field(description="Most cells one page may hold (DTF_JOB_PAGE_CELLS).")
    first_page: str = Field(description="The URL of the first page of cells.")


class JobInfo(ResponseModel):
    """A job: its status, progress, times and, once finished, its result or error."""

    model_config = ConfigDict(json_schema_extra={"examples": [_JOB_EXAMPLE]})

    id: str = Field(
        description="The job's id (a random UUID).", json_schema_extra={"format": "uuid"}
    )
    kind: JobKind = Field(description="What the job computes.")
    status: JobStatus = Field(description="queued, running, done, failed or cancelled.")
    progress: JobProgress = Field(description="How far it is.")
    created: float = Field(description="When it was submitted (Unix time, s).")
    started: float | None = Field(description="When it last started (Unix time, s).")
    finished: float | None = Field(description="When it ended (Unix time, s).")
    result: JobResult = Field(
        default=None,
        description="When done: the route's own answer (MapResponse, OptimizeResponse or "
        "EvaluateResponse, as kind says); a map whose cells are read in pages "
        "(result_cells.in_result false) is a MapResponseWithoutCells.",
    )
    error: list[ErrorDetail] | None = Field(
        default=None,
        description="When failed: what was wrong, as a 422's detail. Its type says whose "
        "it is: the request's (as the route's 422 would say: a validation type, invalid_input, "
        "repeated_waypoint, unknown_robot and the like, loc naming the field); unavailable (the"
        " Dask cluster cannot run the job: its scheduler unreachable or lost, no worker, a "
        "worker process dead under a task, or a worker whose code is not the service's; submit "
        "it again once the cluster runs); interrupted (service restarts, or its worker process "
        "ending, in each of its DTF_JOB_ATTEMPTS runs); damaged (its stored request cannot be "
        "read); internal (a bug of the service's: the message names the exception).",
    )
    result_cells: ResultCells | None = Field(
        default=None,
        description="When a map job is done: how many cells its answer has and where they are "
        "(a result over DTF_JOB_PAGE_CELLS cells comes without them; page through "
        "GET /v1/jobs/{id}/result?offset=&limit=).",
    )


class JobList(ResponseModel):
    """Jobs, newest first, without their results."""

    model_config = ConfigDict(json_schema_extra={"examples": [{"jobs": [_JOB_EXAMPLE]}]})

    jobs: list[JobInfo] = Field(description="The jobs.")


class JobResultPage(ResponseModel):
    """Cells ``offset`` to ``offset + limit`` of a done map job's answer, as ``POST /v1/map``."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "offset": 0,
                    "limit": 1,
                    "total": 500000,
                    "cells": [_CELL],
                    "next": "/v1/jobs/0b6f3c1e-7f1e-4d0a-9d55-3c5d8b1f2a10/result?offset=1&limit=1",
                    "next_offset": 1,
                }
            ]
        }
    )

    offset: int = Field(description="The index of the page's first cell in the map's cells.")
    limit: int = Field(description="Most cells asked for.")
    total: int = Field(description="Cells in the map's answer.")
    cells: list[MapCell] = Field(
        description="The cells, in the order of the map's ``cells`` (yaw-major, then y, then x); "
        "fewer than ``limit`` at the end."
    )
    next: str | None = Field(description="The URL of the next page; null on the last one.")
    next_offset: int | None = Field(
        default=None,
        description="The next page's offset (its limit this page's), as ``next`` asks it: for a "
        "client that calls the operation with its parameters; null on the last page.",
    )
