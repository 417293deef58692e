"""The ASGI app, ``service.main:app``.

Settings are not read here: the body size limit reads them on the first request, so importing
the app (to serve it, or to write ``openapi/openapi.json``) needs no environment.
"""

from __future__ import annotations

import contextlib
import gc
import signal
import sys
import threading
import time
from collections.abc import AsyncIterator
from pathlib import Path
from types import FrameType
from typing import Any

import anyio
import numpy as np
from fastapi import Depends, FastAPI
from fastapi.exceptions import RequestValidationError
from fastapi_offline import FastAPIOffline
from pydantic.json_schema import models_json_schema
from starlette.exceptions import HTTPException as StarletteHTTPException

from service import caches
from service.api import API_ROUTERS
from service.api.routes import health
from service.body import BODY_MODELS
from service.body_limits import BodySizeLimitMiddleware
from service.config import Settings, get_settings, settings_or_exit
from service.cors import CorsMiddleware
from service.errors import (
    SERVER_ERROR_RESPONSE,
    cancelled_handler,
    http_error_handler,
    job_store_unavailable_handler,
    request_validation_error_handler,
    server_error_handler,
    solver_error_handler,
)
from service.jobs.job import JobStoreUnavailable
from service.jobs.runner import close_runners, get_runner
from service.logs import duration, log, log_to_stderr, startup_log
from service.metrics import instrument
from service.query import known_query_parameters
from service.refusals import RefusalLogMiddleware
from service.spec import defaults_in_words, with_paged_map
from service.web import mount_page
from service.work import STOPPING
from solver.core.exceptions import SolverError
from solver.core.progress import Cancelled
from solver.core.spatial import Placement
from solver.families import catalogue
from solver.kernels import feed_profile, spun_rows
from solver.kernels import fixed_spin as map_kernel
from solver.kernels import free_spin as free_spin_kernel
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathProblem

GIL_SWITCH_SECONDS = 0.001
DESCRIPTION = """\
Task-oriented workpiece placement for robot machining (Stradovnik & Hace: the Decomposed Twist
Feasibility index, Sensors 2022; the path index mu_path, ERK 2021).

- `GET /healthz`: the service is up.
- `GET /v1/robots`: the catalogue (UR, OPW industrial and URDF arms) with joint limits, kinematics
  family and IK branch names.
- `POST /v1/dtf`: the largest tool speed along a task direction at one configuration, with
  every joint within its speed limit.
- `POST /v1/evaluate`: mu_path, the highest constant feed rate for a whole path at one
  workpiece placement, where it is limited, per-waypoint detail; with `spin_mode: free` the
  tool spin about its axis is free (5-axis paths).
- `POST /v1/map`: mu_path over a grid of placements (yaws, spins), as JSON or a PNG.
- `POST /v1/optimize`: the placement (x, y, yaw, and optionally spin and height) inside a box
  where the path runs fastest, checked by the evaluator.
- `POST /v1/paths/import`: a path (poses, tool axes, APT CL data, CSV) as the service reads it.

Every placement in an answer also comes as a controller frame (UR, KUKA, ABB, FANUC).
SI units throughout (m, rad, s). Paths are poses, tool points with tool axes, APT CL data or
CSV (passes split at rapids; /v1/evaluate checks the programmed feed). Input errors
are `422` with a `detail` list whose `loc` names the field (and waypoint index), a query
parameter an operation does not take too; oversized bodies are `413`; bodies not declared as
JSON (or sent without a Content-Type, or compressed: a Content-Encoding) are `415`; a body
that stops short of its length is `408`. Every error answer (404, 429, 500 too) is a JSON object
with the same `detail` list. These pages load nothing from the internet.
"""


@contextlib.asynccontextmanager
async def lifespan(app: FastAPI) -> AsyncIterator[None]:
    """Hand the GIL round often; on SIGTERM or SIGINT, stop running work at its next report.

    Solver work runs in worker threads; between numpy calls it holds the GIL, and by default
    a waiting thread gets it only every 5 ms. The event loop needs it several times per request,
    so /healthz took 20 ms at the median while a map ran; at 1 ms it stays a few milliseconds.
    What startup made (about 266,000 objects: numba, pinocchio, matplotlib) is frozen out of the
    garbage collector: a full collection walked it in 0.15 to 0.3 s, holding the GIL, whenever a
    big answer was being built.
    """
    sys.setswitchinterval(GIL_SWITCH_SECONDS)
    STOPPING.clear()
    _stop_work_on(signal.SIGTERM)
    _stop_work_on(signal.SIGINT)
    log_to_stderr()
    for note in caches.cache_notes():  # a read-only install, an account without a home
        startup_log.info(note)
    started = time.monotonic()
    startup_log.info(
        "warming up: loading the compiled map kernels (the first start after an install "
        "compiles them, about 30 s; later starts take a few seconds)"
    )
    await anyio.to_thread.run_sync(_warm_up)
    startup_log.info("ready after %.1f s of warm-up", time.monotonic() - started)
    startup_log.info(jobs_line(get_settings()))
    gc.collect()
    gc.freeze()  # what startup made lives on: full collections no longer walk it
    try:
        get_runner(get_settings()).recover()  # jobs a restart interrupted run again
    except JobStoreUnavailable as error:  # the job routes answer 503; the rest serves
        log.error(
            "jobs are unavailable: %s (the jobs a restart interrupted are queued again once "
            "the store answers)",
            error,
        )
    yield
    close_runners()


def jobs_line(settings: Settings) -> str:
    """The start's line of where jobs are kept and run, and for how long.

    The start named neither the store (a relative DTF_DATA_DIR, ``var`` by default, is taken
    from the working directory: a unit without one put it in /var) nor the settings the jobs
    run with (the operator audit of 2026-12-07, M6).
    """
    store = (Path(settings.data_dir) / "jobs.sqlite3").resolve()
    where = (
        f"their tasks on the Dask cluster at {settings.dask_scheduler}"
        if settings.dask_scheduler
        else f"{settings.workers} worker process(es) (DTF_WORKERS)"
    )
    return (
        f"jobs: kept in {store}, finished ones for {duration(settings.job_ttl)} (DTF_JOB_TTL = "
        f"{settings.job_ttl:g} s); {where}; maps on {settings.threads} thread(s) (DTF_THREADS)"
    )


def _warm_up() -> None:
    """Do before serving what the first requests would otherwise pay for, holding the GIL.

    The catalogue reads its URDFs and the first path evaluation imports and sets up its
    modules: a few hundred milliseconds in which /healthz would wait. matplotlib is imported and
    draws a first figure (0.4 s; the first picture asked for held the GIL that long), so that
    its 42,000 objects are frozen with the rest: made by a first picture instead, a full
    collection in the next large request walked them (66 ms on an idle machine, 2026-12-07; a
    CI run's /healthz probe waited 188 ms during a Panda evaluation after the map picture's
    test). The compiled map kernels
    (fixed and free spin, and free spin's spun paths) are loaded from numba's disk cache, or
    compiled (about 10 s each, once per installation), and the cycle time's feed profiles (2 s).
    """
    map_kernel.warm_up()
    free_spin_kernel.warm_up()
    spun_rows.warm_up()
    feed_profile.warm_up()
    from service.render import render_message  # noqa: PLC0415 - the app's importers need no matplotlib

    render_message("")  # matplotlib's import and first figure: 0.4 s, 42,000 objects
    robot = catalogue()["ur5"]
    waypoints = np.repeat(np.eye(4)[None], 2, axis=0)
    waypoints[1, 0, 3] = 0.01
    evaluate_path(PathProblem.of(robot, waypoints), Placement(0.0, 0.45, 0.1, 0.0))


def _stop_work_on(signum: signal.Signals) -> None:
    """On ``signum``, stop running work, then run the server's own handler.

    uvicorn's graceful shutdown waits for the requests in flight; with this, their work stops at
    its next progress report and they answer 503 within a second instead.
    """
    previous = signal.getsignal(signum)
    if threading.current_thread() is not threading.main_thread() or not callable(previous):
        return  # an app run by a test client in its own thread, or no server handler

    def handler(number: int, frame: FrameType | None) -> None:
        STOPPING.set()
        previous(number, frame)

    signal.signal(signum, handler)


def create_app() -> FastAPI:
    """Build the app: routers, the error handlers, the body size limit and offline docs.

    The ``DTF_`` settings are read first: a bad one ends the process here, named, before any
    warm-up (:func:`service.config.settings_or_exit`).
    """
    settings_or_exit()
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
            Cancelled: cancelled_handler,
            JobStoreUnavailable: job_store_unavailable_handler,
            Exception: server_error_handler,
        },
        responses=SERVER_ERROR_RESPONSE,
        lifespan=lifespan,
        dependencies=[Depends(known_query_parameters)],
    )
    app.include_router(health.router)
    for router in API_ROUTERS:
        app.include_router(router, prefix="/v1")
    mount_page(app)
    app.add_middleware(BodySizeLimitMiddleware)
    app.add_middleware(RefusalLogMiddleware)  # outside it: its 413, 415 and 408 are logged too
    app.add_middleware(CorsMiddleware)  # outermost: a page elsewhere reads the refusals too
    instrument(app, job_store=lambda: get_runner(get_settings()).store)
    return app


app = create_app()


def _openapi() -> dict[str, Any]:
    """FastAPI's description, with the schemas of the bodies validated in worker threads.

    Request defaults are stated in words (:mod:`service.spec`).
    """
    if app.openapi_schema is None:
        spec = FastAPI.openapi(app)
        _, top = models_json_schema(
            [(model, "validation") for model in BODY_MODELS],
            ref_template="#/components/schemas/{model}",
        )
        components = spec.setdefault("components", {}).setdefault("schemas", {})
        for name, schema in top.get("$defs", {}).items():
            components.setdefault(name, schema)
        app.openapi_schema = with_paged_map(defaults_in_words(spec))
    return app.openapi_schema


app.openapi = _openapi  # type: ignore[method-assign]
