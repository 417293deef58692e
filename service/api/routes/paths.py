"""``POST /v1/paths/import``: read a path (CL data, CSV, poses, tool axes) and show it back."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Request, Response

from service import convert
from service.body import body_in_thread, body_openapi
from service.config import Settings
from service.deps import SettingsDep
from service.errors import ERROR_RESPONSES
from service.schemas.path import PathInput
from service.schemas.paths_import import (
    ImportedPose,
    PassOut,
    PathImportRequest,
    PathImportResponse,
    SkippedRecordOut,
)
from service.work import json_response, run_stoppable
from solver.cam.frames import quaternions_wxyz

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


def import_of(body: PathImportRequest, settings: Settings) -> PathImportResponse:
    """The answer of ``POST /v1/paths/import``, the path's size checked as every route does."""
    convert.check_path_size(
        body.path, limit=settings.max_path_waypoints, setting="DTF_MAX_PATH_WAYPOINTS"
    )
    return imported(convert.path_of(body.path))


def imported(path: PathInput) -> PathImportResponse:
    """The import answer of a parsed path."""
    quaternions = quaternions_wxyz(path.poses[:, :3, :3])[:, [1, 2, 3, 0]].tolist()
    waypoints = [
        ImportedPose.model_construct(position=position, orientation=orientation)
        for position, orientation in zip(path.poses[:, :3, 3].tolist(), quaternions, strict=True)
    ]
    passes = path.passes or ((0, len(path.poses)),)
    operations = path.pass_operations or (None,) * len(passes)
    report = path.report
    return PathImportResponse(
        waypoints=waypoints,
        passes=[[start, stop] for start, stop in passes],
        feed=path.feed,
        units=path.units,
        correction=path.axis_correction,
        spin_mode=path.default_spin_mode,
        units_source=path.units_source,
        units_note=path.units_note,
        pass_details=[
            PassOut(start=start, stop=stop, operation=operation, feed=feed)
            for (start, stop), operation, feed in zip(
                passes, operations, path.pass_feeds or (path.feed,) * len(passes), strict=True
            )
        ],
        skipped_records=[]
        if report is None
        else [
            SkippedRecordOut(
                word=s.word, count=s.count, first_line=s.first_line, recognised=s.recognised
            )
            for s in report.skipped_records
        ],
        repeated_points=0 if report is None else report.repeated_points,
        one_point_passes=path.one_point_passes,
        arcs=0 if report is None else report.arcs,
    )
