"""The versioned API: every resource router under ``/v1``."""

from __future__ import annotations

from fastapi import APIRouter

from service.api.routes import (
    dtf,
    evaluate,
    job_results,
    jobs,
    limits,
    map,
    optimize,
    paths,
    robots,
)

api_router = APIRouter(prefix="/v1")
api_router.include_router(robots.router)
api_router.include_router(limits.router)
api_router.include_router(dtf.router)
api_router.include_router(evaluate.router)
api_router.include_router(map.router)
api_router.include_router(optimize.router)
api_router.include_router(paths.router)
api_router.include_router(jobs.router)
api_router.include_router(job_results.router)
