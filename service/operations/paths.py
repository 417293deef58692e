"""Importing a path: what the service read, shown back without computing anything."""

from __future__ import annotations

from service.schemas.path import PathInput
from service.schemas.paths_import import ImportedPose, PathImportResponse
from solver.cam.frames import quaternion_wxyz


def imported(path: PathInput) -> PathImportResponse:
    """The import answer of a parsed path."""
    waypoints = []
    for pose in path.poses:
        w, x, y, z = quaternion_wxyz(pose[:3, :3])
        waypoints.append(ImportedPose(position=pose[:3, 3].tolist(), orientation=[x, y, z, w]))
    passes = path.passes or ((0, len(path.poses)),)
    return PathImportResponse(
        waypoints=waypoints,
        passes=[[start, stop] for start, stop in passes],
        feed=path.feed,
        units=path.units,
        correction=path.axis_correction,
        spin_mode=path.default_spin_mode,
    )
