"""``GET /v1/limits``: the request limits this service runs with (its ``DTF_`` settings)."""

from __future__ import annotations

from fastapi import APIRouter

from service.deps import SettingsDep
from service.schemas.limits import LimitsResponse, limits_of

router = APIRouter(prefix="/limits", tags=["limits"])


@router.get(
    "",
    operation_id="get_limits",
    summary="The request limits of this service",
    response_model=LimitsResponse,
)
def get_limits(settings: SettingsDep) -> LimitsResponse:
    """Each limit a request meets, with its ``DTF_`` setting (or the schema's own bound).

    What would be refused, and why, can be said before a request is sent: the body's bytes, a
    path's waypoints, a map's placements and work, a mesh's triangles, a job's cells.
    """
    return limits_of(settings)
