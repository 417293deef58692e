"""Importing a path: what the service read, shown back without computing anything."""

from __future__ import annotations

from service import convert
from service.config import Settings
from service.schemas.path_input import PathInput
from service.schemas.paths_import import (
    ImportedPose,
    PassOut,
    PathImportRequest,
    PathImportResponse,
    SkippedRecordOut,
)
from solver.cam.frames import quaternions_wxyz


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
