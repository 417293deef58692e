"""Error answers: schema and solver input errors as ``422``, and their OpenAPI entries.

They use FastAPI's validation-error shape, ``{"detail": [{"loc": [...], "msg": ..., "type":
...}]}``, as do HTTP errors, faults, stops and the body's own limits (``413``, ``415``, ``408``:
:mod:`service.body_limits`), so a client reads every error the same way.
"""

from __future__ import annotations

import re
from http import HTTPStatus
from typing import Any

from fastapi import Request, status
from fastapi.exception_handlers import http_exception_handler
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, Response
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.routing import Route

from service.convert.errors import (
    request_errors,
    solver_error_location,
    solver_error_type,
)
from service.jobs.job import JobStoreUnavailable
from service.logs import request_log
from service.schemas import ErrorDetail, ErrorResponse
from service.work import STOPPING
from solver.core.exceptions import SolverError
from solver.core.progress import Cancelled

RETRY_AFTER = {
    "Retry-After": {
        "description": "Seconds to wait before retrying.",
        "schema": {"type": "integer"},
    }
}
"""The OpenAPI header entry of answers that say when to retry (429, 503)."""
JSON_ERROR: dict[str, Any] = {
    "content": {"application/json": {"schema": {"$ref": "#/components/schemas/ErrorResponse"}}}
}
"""An error answer's OpenAPI content, for routes whose own answers are not JSON (/metrics)."""
SERVER_ERROR_RESPONSE: dict[int | str, dict[str, Any]] = {
    status.HTTP_500_INTERNAL_SERVER_ERROR: {
        "model": ErrorResponse,
        "description": "A fault of the service (a bug: no input should cause it), as JSON.",
    }
}
"""The OpenAPI entry of the 500 answer, for every operation."""
ERROR_RESPONSES: dict[int | str, dict[str, Any]] = {
    status.HTTP_408_REQUEST_TIMEOUT: {
        "model": ErrorResponse,
        "description": "The body did not arrive in time (setting DTF_BODY_READ_SECONDS).",
    },
    status.HTTP_413_CONTENT_TOO_LARGE: {
        "model": ErrorResponse,
        "description": "The body is over the size limit (setting DTF_MAX_BODY_BYTES).",
    },
    status.HTTP_415_UNSUPPORTED_MEDIA_TYPE: {
        "model": ErrorResponse,
        "description": "The body is not declared as JSON (Content-Type application/json).",
    },
    status.HTTP_503_SERVICE_UNAVAILABLE: {
        "model": ErrorResponse,
        "description": "The work was stopped because the service is shutting down; retry. (A "
        "client that left is answered 499, which nobody hears, for the request metrics.)",
        "headers": RETRY_AFTER,
    },
    status.HTTP_422_UNPROCESSABLE_CONTENT: {
        "model": ErrorResponse,
        "description": "Bad input; each detail's loc names the field (and waypoint index).",
    },
}
"""OpenAPI entries of the error answers, for routers that take a body."""


def job_not_found(
    job_id: object, *, loc: tuple[str, str] = ("path", "job_id"), why: str = ""
) -> StarletteHTTPException:
    """The 404 of an unknown job id, naming the parameter (``job_id``, or ``after``)."""
    detail = ErrorDetail(loc=list(loc), msg=f"no job {str(job_id)!r}{why}", type="not_found")
    return StarletteHTTPException(status.HTTP_404_NOT_FOUND, [detail.model_dump()])  # type: ignore[arg-type]


def error_response(status_code: int, details: list[ErrorDetail]) -> JSONResponse:
    """An error answer with its ``detail`` list."""
    return JSONResponse(status_code=status_code, content=ErrorResponse(detail=details).model_dump())


async def request_validation_error_handler(
    request: Request, error: RequestValidationError
) -> JSONResponse:
    """Answer a schema error with ``422`` as FastAPI does, without echoing the input.

    FastAPI's own answer repeats each offending ``input``, which breaks on the NaN it is
    refusing (JSON has no NaN) and can run to megabytes for a whole path.
    """
    return error_response(
        status.HTTP_422_UNPROCESSABLE_CONTENT, request_errors(list(error.errors()))
    )


def http_error_type(status_code: int) -> str:
    """``404`` -> ``"not_found"``: the error type of an HTTP error without a field."""
    try:
        phrase = HTTPStatus(status_code).phrase
    except ValueError:
        return "http_error"
    return re.sub(r"\W+", "_", phrase).strip("_").lower()


async def http_error_handler(request: Request, error: StarletteHTTPException) -> Response:
    """FastAPI's answer with a ``detail`` list, as 422s have; an undecodable body is a ``422``.

    FastAPI answers ``400`` when the JSON parser itself fails (bytes that are not UTF-8, arrays
    nested deeper than the parser's recursion limit) rather than reporting a syntax error. A
    string ``detail`` (a 404 of an unknown route, a 405) becomes one error with no ``loc``.
    """
    cause = error.__cause__
    if error.status_code == 400 and isinstance(cause, UnicodeDecodeError | RecursionError):
        detail = ErrorDetail(
            loc=["body"], msg=f"cannot decode the JSON: {cause}", type="json_invalid"
        )
        return error_response(status.HTTP_422_UNPROCESSABLE_CONTENT, [detail])
    if error.status_code == 405:  # Allow lists every method of the path, not one route's
        allowed = sorted(
            method
            for route in request.app.routes
            if isinstance(route, Route) and route.path_regex.match(request.url.path)
            for method in route.methods or ()
            if method != "HEAD"
        )
        error = StarletteHTTPException(405, error.detail, headers={"Allow": ", ".join(allowed)})
    if isinstance(error.detail, str) and error.status_code not in (204, 304):
        detail = ErrorDetail(loc=[], msg=error.detail, type=http_error_type(error.status_code))
        response = error_response(error.status_code, [detail])
        response.headers.update(error.headers or {})
        return response
    return await http_exception_handler(request, error)


async def server_error_handler(request: Request, error: Exception) -> JSONResponse:
    """Answer a fault of the service with ``500`` as a JSON error, not text (none is expected)."""
    detail = ErrorDetail(
        loc=[], msg=f"internal error ({type(error).__name__}); please report it", type="internal"
    )
    return error_response(status.HTTP_500_INTERNAL_SERVER_ERROR, [detail])


CLIENT_CLOSED_REQUEST = 499
"""The status of a request its client left before the answer (nginx's "Client Closed
Request"): nobody hears it, but the request metrics count it as 4xx, the client's doing, not
as a server error (a 503, counted 5xx: every impatient client, closed browser tab or proxy
timeout raised the 5xx rate an operator alerts on, with no log line to explain it; the soak
audit of stop 61)."""


async def cancelled_handler(request: Request, error: Cancelled) -> JSONResponse:
    """Answer work stopped on the way: 503 while the service stops, 499 for a client that left.

    A client that left hears nothing; a proxy, a log or a test may: each says its own cause,
    and a line in the log says which request was left (uvicorn logs no access line for it).
    """
    if STOPPING.is_set():
        detail = ErrorDetail(
            loc=[], msg="the work was stopped: the service is shutting down", type="cancelled"
        )
        response = error_response(status.HTTP_503_SERVICE_UNAVAILABLE, [detail])
        response.headers["Retry-After"] = "5"
        return response
    if request is not None:  # (a test calls the handler alone)
        client_left(request.method, request.url.path, "its work was stopped")
    detail = ErrorDetail(loc=[], msg="the work was stopped: its client left", type="cancelled")
    return error_response(CLIENT_CLOSED_REQUEST, [detail])


def client_left(method: str, path: str, what: str) -> None:
    """Log that a request's client left before its answer (``what``: what then happened)."""
    request_log.info("%s %s %s: %s, its client left", method, path, CLIENT_CLOSED_REQUEST, what)


STORE_RETRY_SECONDS = 30
"""The Retry-After of a 503 answered while the job store cannot be used (s)."""


async def job_store_unavailable_handler(
    request: Request, error: JobStoreUnavailable
) -> JSONResponse:
    """Answer a job route (or /metrics) with 503 while the job store cannot be used.

    The compute routes never touch the store, so they stay up; the detail says what is wrong
    with the file, for the operator.
    """
    detail = ErrorDetail(loc=[], msg=error.reason, type="job_store_unavailable")
    response = error_response(status.HTTP_503_SERVICE_UNAVAILABLE, [detail])
    response.headers["Retry-After"] = str(STORE_RETRY_SECONDS)
    return response


async def solver_error_handler(request: Request, error: SolverError) -> JSONResponse:
    """Answer a solver input error with ``422`` naming the field (and waypoint)."""
    detail = ErrorDetail(
        loc=solver_error_location(error), msg=error.message, type=solver_error_type(error)
    )
    return error_response(status.HTTP_422_UNPROCESSABLE_CONTENT, [detail])
