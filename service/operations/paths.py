"""Importing a path: what the service read, shown back without computing anything."""

from __future__ import annotations

from service import convert
from service.config import Settings
from service.convert.path_read import read_fields
from service.schemas.path_input import PathInput
from service.schemas.paths_import import ImportedPose, PathImportRequest, PathImportResponse
from solver.cam.frames import quaternions_wxyz
from solver.path.prepare import path_requirements


def import_of(body: PathImportRequest, settings: Settings) -> PathImportResponse:
    """The answer of ``POST /v1/paths/import``, the path checked as every route checks it.

    Its size, and each pass's segments (:func:`solver.path.prepare.path_requirements`: a
    waypoint repeating the one before, a turn of about half a turn): a path this accepts,
    /v1/evaluate and /v1/map accept too (cam.md section 9).
    """
    convert.check_path_size(
        body.path, limit=settings.max_path_waypoints, setting="DTF_MAX_PATH_WAYPOINTS"
    )
    path = convert.path_of(body.path)
    path_requirements(path.poses, path.passes, field=path.source)
    return imported(path)


def imported(path: PathInput) -> PathImportResponse:
    """The import answer of a parsed path (its reading as every answer's ``path_read``)."""
    quaternions = quaternions_wxyz(path.poses[:, :3, :3])[:, [1, 2, 3, 0]].tolist()
    waypoints = [
        ImportedPose.model_construct(position=position, orientation=orientation)
        for position, orientation in zip(path.poses[:, :3, 3].tolist(), quaternions, strict=True)
    ]
    passes = path.passes or ((0, len(path.poses)),)
    return PathImportResponse(
        waypoints=waypoints,
        lines=None if path.lines is None else path.lines.tolist(),
        passes=[[start, stop] for start, stop in passes],
        correction=path.axis_correction,
        spin_mode=path.default_spin_mode,
        **read_fields(path),
    )
