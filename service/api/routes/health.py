"""``GET /healthz``: is the service up."""

from __future__ import annotations

from fastapi import APIRouter

from service.deps import SettingsDep
from service.jobs.runner import runner_if_made
from service.schemas import HealthResponse

router = APIRouter(tags=["health"])


@router.get("/healthz", operation_id="health", summary="Liveness check")
async def healthz(settings: SettingsDep) -> HealthResponse:
    """Answer ``{"status": "ok", "jobs": ...}`` while the service runs.

    ``jobs`` is the job supervisor's last look (kept in memory, no store read): a service whose
    job store could not be used answered "ok" alone (the operator audit of 2026-12-07, M2).
    """
    runner = runner_if_made(settings)
    failure = None if runner is None else runner.failure
    return HealthResponse(status="ok", jobs="ok" if failure is None else f"unavailable: {failure}")
