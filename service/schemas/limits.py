"""The response of ``GET /v1/limits``: the request limits in force on this service.

Most limits are settings (``DTF_<NAME>``, :class:`service.config.Settings`), a few the schema's
own bounds; a setting cannot be above its schema's bound (the start stops, naming it), so
each value is the one a request meets. A client (a CAM post-processor, the page) reads them
before it sends: a path too long, a grid too large or an STL mesh that makes the body too
large is then said before anything is sent.
"""

from __future__ import annotations

from typing import Any

from pydantic import ConfigDict, Field

from service.config import Settings
from service.schemas.common import ResponseModel
from service.schemas.map import MAX_GRID_VALUES
from service.schemas.path_cam import MAX_CAM_TEXT
from service.schemas.robot_options import MAX_JOINTS


def _limit(setting: str | None, said: str) -> Any:
    """A field: what it bounds, then the setting that sets it (or that it is the schema's)."""
    where = f" (DTF_{setting.upper()})" if setting else " (the schema's; no setting)"
    return Field(description=said + where)


class LimitsResponse(ResponseModel):
    """The request limits of this service: what a request may hold, and what it may cost."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "max_body_bytes": 2_000_000,
                    "body_read_seconds": 10.0,
                    "max_path_waypoints": 20_000,
                    "max_optimize_waypoints": 20_000,
                    "max_detail_waypoints": 2_000,
                    "max_cam_characters": 2_000_000,
                    "max_map_cells": 50_000,
                    "max_map_poses": 5_000_000,
                    "max_search_poses": 6_100_000,
                    "max_grid_values": 360,
                    "max_png_panels": 24,
                    "max_cell_objects": 100,
                    "max_mesh_triangles": 50_000,
                    "max_urdf_joints": 64,
                    "max_joint_values": 64,
                    "max_solver_seconds": 20.0,
                    "max_job_cells": 2_000_000,
                    "max_job_poses": 500_000_000,
                    "job_page_cells": 10_000,
                    "max_queued_jobs": 100,
                    "job_ttl_seconds": 604_800.0,
                }
            ]
        }
    )

    max_body_bytes: int = _limit("max_body_bytes", "Largest request body (bytes): 413 over it.")
    body_read_seconds: float = _limit(
        "body_read_seconds", "Longest wait (s) for a body to arrive: 408 after it."
    )
    max_path_waypoints: int = _limit(
        "max_path_waypoints", "Most waypoints a path of /v1/evaluate, /v1/map and jobs may have."
    )
    max_optimize_waypoints: int = _limit(
        "max_optimize_waypoints", "Most waypoints a path of /v1/optimize may have."
    )
    max_detail_waypoints: int = _limit(
        "max_detail_waypoints",
        "Up to this many waypoints /v1/evaluate answers each waypoint's detail by default.",
    )
    max_cam_characters: int = _limit(None, "Most characters of a CL program or CSV text.")
    max_map_cells: int = _limit(
        "max_map_cells", "Most placements (x * y * yaw * spin values) of one /v1/map request."
    )
    max_map_poses: int = _limit(
        "max_map_poses",
        "Most work of one /v1/map request (or /v1/optimize's coarse map, or one /v1/evaluate), "
        "in closed-form poses: placements * waypoints, weighed by the IK family and the cell.",
    )
    max_search_poses: int = _limit(
        "max_search_poses",
        "Most work, weighed as max_map_poses, of the scipy method's search in one /v1/optimize.",
    )
    max_grid_values: int = _limit(None, "Most values of a map's yaw or spin list.")
    max_png_panels: int = _limit("max_png_panels", "Most panels (yaw x spin values) of a PNG.")
    max_cell_objects: int = _limit(
        "max_cell_objects", "Most objects (fixed and workpiece) of a request's cell."
    )
    max_mesh_triangles: int = _limit(
        "max_mesh_triangles", "Most triangles of one STL mesh of a cell."
    )
    max_urdf_joints: int = _limit(
        "max_urdf_joints", "Most joints (of any type, in the document) of a URDF robot."
    )
    max_joint_values: int = _limit(
        None, "Most values of a per-joint list (limits, a start configuration, link radii)."
    )
    max_solver_seconds: float = _limit(
        "max_solver_seconds", "Longest time (s) of one IPOPT solve of /v1/optimize."
    )
    max_job_cells: int = _limit("max_job_cells", "Most placements of one map job.")
    max_job_poses: int = _limit(
        "max_job_poses", "Most work of one job, weighed as max_map_poses (a map job's, a search's)."
    )
    job_page_cells: int = _limit(
        "job_page_cells", "Most cells of a map job's result in one answer (its pages' size)."
    )
    max_queued_jobs: int = _limit("max_queued_jobs", "Most jobs queued or running: 429 over it.")
    job_ttl_seconds: float = _limit(
        "job_ttl", "How long (s) a finished job and its result are kept: 404 after it."
    )


def limits_of(settings: Settings) -> LimitsResponse:
    """The limits a request meets under ``settings`` (each within its schema's bound)."""
    return LimitsResponse(
        max_body_bytes=settings.max_body_bytes,
        body_read_seconds=settings.body_read_seconds,
        max_path_waypoints=settings.max_path_waypoints,
        max_optimize_waypoints=settings.max_optimize_waypoints,
        max_detail_waypoints=settings.max_detail_waypoints,
        max_cam_characters=MAX_CAM_TEXT,
        max_map_cells=settings.max_map_cells,
        max_map_poses=settings.max_map_poses,
        max_search_poses=settings.max_search_poses,
        max_grid_values=MAX_GRID_VALUES,
        max_png_panels=settings.max_png_panels,
        max_cell_objects=settings.max_cell_objects,
        max_mesh_triangles=settings.max_mesh_triangles,
        max_urdf_joints=settings.max_urdf_joints,
        max_joint_values=MAX_JOINTS,
        max_solver_seconds=settings.max_solver_seconds,
        max_job_cells=settings.max_job_cells,
        max_job_poses=settings.max_job_poses,
        job_page_cells=settings.job_page_cells,
        max_queued_jobs=settings.max_queued_jobs,
        job_ttl_seconds=settings.job_ttl,
    )
