"""``POST /v1/paths/import``: a path parsed for inspection, before any computing (api.md)."""

from __future__ import annotations

from typing import Literal

from pydantic import ConfigDict, Field

from service.schemas.common import RequestModel, ResponseModel, SpinMode
from service.schemas.path import Path
from service.schemas.path_read import (
    END_NOTE,
    ENDED,
    SKIPPED,
    UNITS_NOTE,
    UNITS_SOURCE,
    PassOut,
    SkippedRecordOut,
)


class PathImportRequest(RequestModel):
    """A path in any form, to be read and shown back."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {"path": {"csv": "x,y,z,i,j,k\n0,0,0,0,0,1\n10,0,0,0,0,1\n", "units": "mm"}}
            ]
        }
    )

    path: Path = Field(description="The path: poses, tool axes, CL data or CSV.")


class ImportedPose(ResponseModel):
    """One waypoint as the solver takes it: a pose of the tool point in {O}."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [{"position": [0.0, 0.0127, 0.0254], "orientation": [0, 0.98, 0, 0.18]}]
        }
    )

    position: list[float] = Field(description="[x, y, z] in {O} (m).")
    orientation: list[float] = Field(
        description="Unit quaternion [qx, qy, qz, qw] (ROS order); tool z = -(tool axis)."
    )


class PathImportResponse(ResponseModel):
    """The path read: its waypoints, passes, feed and the corrections made."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "waypoints": [
                        {"position": [0.0, 0.0, 0.0], "orientation": [1.0, 0.0, 0.0, 0.0]},
                        {"position": [0.01, 0.0, 0.0], "orientation": [1.0, 0.0, 0.0, 0.0]},
                    ],
                    "lines": [6, 7],
                    "passes": [[0, 2]],
                    "feed": 0.025,
                    "units": "mm",
                    "correction": 0.0,
                    "spin_mode": "free",
                    "units_source": "stated",
                    "units_note": "UNITS/MM at line 1",
                    "pass_details": [
                        {"start": 0, "stop": 2, "operation": "FACE_MILL", "feed": 0.025}
                    ],
                    "skipped_records": [
                        {"word": "PAINT", "count": 3, "first_line": 4, "recognised": True}
                    ],
                    "repeated_points": 0,
                    "one_point_passes": 0,
                    "arcs": 0,
                    "ended": True,
                    "end_note": "FINI at line 9",
                }
            ]
        }
    )

    waypoints: list[ImportedPose] = Field(description="The N waypoints, poses in {O} (m).")
    lines: list[int] | None = Field(
        default=None,
        description="CL data or CSV: the line of the program (from 1) each waypoint was read "
        "from (an arc's inner points: the CIRCLE's line), so a failed_waypoint or bottleneck "
        "leads back to its record; null for poses and tool axes.",
    )
    passes: list[list[int]] = Field(
        description="Each pass as [start, stop) into the waypoints, in order (a rapid between "
        "two passes belongs to neither)."
    )
    feed: float | None = Field(
        description="The program's feed (m/s), its highest FEDRAT; null when none is programmed."
    )
    units: str = Field(description="The length unit the path was written in (mm, inches, m).")
    correction: float = Field(
        description="The largest correction made to a unit vector's or quaternion's length "
        "(normalised within 1e-3); 0 when none was needed."
    )
    spin_mode: SpinMode = Field(description="The default spin_mode of this path form.")
    units_source: Literal["stated", "inferred", "request"] = Field(description=UNITS_SOURCE)
    units_note: str = Field(description=UNITS_NOTE)
    pass_details: list[PassOut] = Field(
        description="Each pass, in the order of passes, with its operation and feed."
    )
    skipped_records: list[SkippedRecordOut] = Field(description=SKIPPED)
    repeated_points: int = Field(
        description="CL data: GOTOs to where the tool already was, dropped."
    )
    one_point_passes: int = Field(description="CL data: passes of a single point, dropped.")
    arcs: int = Field(description="CL data: CIRCLE moves interpolated into waypoints.")
    ended: bool | None = Field(description=ENDED)
    end_note: str = Field(description=END_NOTE)
