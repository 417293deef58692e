"""``GET /healthz``: is the service up."""

from __future__ import annotations

from fastapi import APIRouter

from service.schemas import HealthResponse

router = APIRouter(tags=["health"])


@router.get("/healthz", operation_id="health", summary="Liveness check")
async def healthz() -> HealthResponse:
    """Answer ``{"status": "ok"}`` while the service runs."""
    return HealthResponse(status="ok")
