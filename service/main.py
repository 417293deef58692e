"""The ASGI app, ``service.main:app``.

Settings are not read here: the body size limit reads them on the first request, so importing
the app (to serve it, or to write ``openapi/openapi.json``) needs no environment.
"""

from __future__ import annotations

from fastapi import FastAPI
from fastapi.exceptions import RequestValidationError
from fastapi_offline import FastAPIOffline
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
Task-oriented workpiece placement for robot machining (Stradovnik & Hace: the Decomposed Twist
Feasibility index, Sensors 2022; the path index mu_path, ERK 2021).

- `GET /healthz`: the service is up.
- `GET /v1/robots`: the catalogue (UR and OPW industrial arms) with joint limits, kinematics
  family and IK branch names.
- `POST /v1/dtf`: the largest tool speed along a task direction at one configuration, with
  every joint within its speed limit.
- `POST /v1/evaluate`: mu_path, the highest constant feed rate for a whole path at one
  workpiece placement, where it is limited, per-waypoint detail; with `spin_mode: free` the
  tool spin about its axis is free (5-axis paths).
- `POST /v1/map`: mu_path over a grid of placements (yaws, spins), as JSON or a PNG.
- `POST /v1/optimize`: the placement (x, y, yaw, and optionally spin and height) inside a box
  where the path runs fastest, checked by the evaluator.

SI units throughout (m, rad, s). Paths are poses or tool points with tool axes. Input errors
are `422` with a `detail` list whose `loc` names the field (and waypoint index); oversized
bodies are `413`; bodies not declared as JSON are `415`. These pages load nothing from the
internet.
"""


def create_app() -> FastAPI:
    """Build the app: routers, the error handlers, the body size limit and offline docs."""
    # Swagger UI and ReDoc served from the fastapi-offline package, not a CDN: /docs works
    # on a machine with no internet.
    app = FastAPIOffline(
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
