"""``POST /v1/paths/import``: read a path (CL data, CSV, poses, tool axes) and show it back."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Request, Response

from service.body import body_in_thread, body_openapi
from service.deps import SettingsDep
from service.errors import ERROR_RESPONSES
from service.operations import import_of
from service.schemas.paths_import import PathImportRequest, PathImportResponse
from service.work import json_response, run_stoppable

router = APIRouter(prefix="/paths", tags=["paths"], responses=ERROR_RESPONSES)


@router.post(
    "/import",
    operation_id="import_path",
    summary="The path as the service reads it: waypoints, passes, feed, corrections",
    response_model=PathImportResponse,
    openapi_extra=body_openapi(PathImportRequest),
)
async def post_import(
    request: Request,
    body: Annotated[PathImportRequest, body_in_thread(PathImportRequest)],
    settings: SettingsDep,
) -> Response:
    """Read a path without computing anything, so a user can look at it first.

    The waypoints shown are the ones every route counts against DTF_MAX_PATH_WAYPOINTS: a path
    this accepts, /v1/evaluate and /v1/map accept too (cam.md section 9).
    """
    return await run_stoppable(request, lambda _: json_response(import_of(body, settings)))
