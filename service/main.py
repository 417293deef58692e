"""The ASGI app, ``service.main:app``.

Settings are not read here: the body size limit reads them on the first request, so importing
the app (to serve it, or to write ``openapi/openapi.json``) needs no environment.
"""

from __future__ import annotations

from fastapi import FastAPI
from fastapi.exceptions import RequestValidationError
from starlette.exceptions import HTTPException as StarletteHTTPException

from service.api import api_router
from service.api.routes import health
from service.errors import (
    BodySizeLimitMiddleware,
    http_error_handler,
    request_validation_error_handler,
    solver_error_handler,
)
from solver.exceptions import SolverError

DESCRIPTION = """\
Task-oriented workpiece placement for robot machining.

`POST /v1/dtf` gives the Decomposed Twist Feasibility index (the largest tool speed along a
task direction with every joint within its speed limit) at one configuration;
`POST /v1/evaluate` gives mu_path, the highest constant feed rate for a whole path at one
workpiece placement. SI units throughout (m, rad, s). Input errors are `422` with a `detail`
list whose `loc` names the field (and waypoint index); oversized bodies are `413`.
"""


def create_app() -> FastAPI:
    """Build the app: routers, the error handlers and the body size limit."""
    app = FastAPI(
        title="DTF placement",
        version="0.1.0",
        description=DESCRIPTION,
        exception_handlers={
            RequestValidationError: request_validation_error_handler,
            StarletteHTTPException: http_error_handler,
            SolverError: solver_error_handler,
        },
    )
    app.include_router(health.router)
    app.include_router(api_router)
    app.add_middleware(BodySizeLimitMiddleware)
    return app


app = create_app()
