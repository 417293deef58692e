"""The response of ``GET /v1/limits``: the request limits this service runs with.

Each limit is a setting (``DTF_<NAME>``, :class:`service.config.Settings`); a request over one is
refused naming it. A client (a CAM post-processor, the page) can read them before it sends: a
path too long, a grid too large or an STL mesh that makes the body too large is then said
before anything is sent. The fields are the settings' own, with their descriptions.
"""

from __future__ import annotations

from typing import Any

from pydantic import Field, create_model

from service.config import Settings
from service.schemas.common import ResponseModel

LIMIT_SETTINGS = (
    "max_body_bytes",
    "body_read_seconds",
    "max_path_waypoints",
    "max_optimize_waypoints",
    "max_detail_waypoints",
    "max_map_cells",
    "max_map_poses",
    "max_search_poses",
    "max_png_panels",
    "max_cell_objects",
    "max_mesh_triangles",
    "max_urdf_joints",
    "max_solver_seconds",
    "max_job_cells",
    "max_job_poses",
    "job_page_cells",
    "max_queued_jobs",
    "threads",
)
"""The settings a client's request meets (not where jobs are kept or which cluster runs them)."""


def _field(name: str) -> Any:
    setting = Settings.model_fields[name]
    said = f"DTF_{name.upper()}: {setting.description}"
    return (setting.annotation, Field(description=said))


LimitsResponse = create_model(  # fields made from the settings'
    "LimitsResponse",
    __base__=ResponseModel,
    __doc__="The request limits of this service, each a ``DTF_`` setting.",
    **{name: _field(name) for name in LIMIT_SETTINGS},
)


def limits_of(settings: Settings) -> Any:
    """The limits ``settings`` sets, as the response."""
    return LimitsResponse(**{name: getattr(settings, name) for name in LIMIT_SETTINGS})
