"""How a CAM program was read: units and their evidence, passes, records skipped (cam.md 9).

``POST /v1/paths/import`` shows it beside the waypoints; ``/v1/evaluate``, ``/v1/optimize``
and ``/v1/map`` (and their jobs) give it as ``path_read`` when the path came as CL data or CSV,
so an answer computed from a program says how the program was read (nothing inferred unsaid).
"""

from __future__ import annotations

from typing import Literal

from pydantic import ConfigDict, Field

from service.schemas.common import ResponseModel


class SkippedRecordOut(ResponseModel):
    """Records of one word skipped: they carry no geometry and no feed (cam.md section 9)."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [{"word": "PAINT", "count": 31, "first_line": 5, "recognised": True}]
        }
    )

    word: str = Field(description="The major word (PAINT, TLDATA; $$ for comments).")
    count: int = Field(description="How many records of this word the file has.")
    first_line: int = Field(description="The line of the first one, from 1.")
    recognised: bool = Field(
        description="false for a word the reader does not know: check that it moves nothing."
    )


class PassOut(ResponseModel):
    """One pass: its range of waypoints and the operation it belongs to."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "start": 0,
                    "stop": 108,
                    "operation": "CAVITY_MILL",
                    "feed": 0.004233,
                    "length": 0.2381,
                    "time": 61.7,
                }
            ]
        }
    )

    start: int = Field(description="Its first waypoint's index.")
    stop: int = Field(description="One past its last waypoint's index.")
    operation: str | None = Field(
        description="The operation's name in the file (NX TOOL PATH, PARTNO, PPRINT); null "
        "where the file names none."
    )
    feed: float | None = Field(description="Its highest programmed feed (m/s), or null.")
    length: float | None = Field(
        default=None, description="The tool point's way along the pass (m), its moves summed."
    )
    time: float | None = Field(
        default=None,
        description="How long the pass runs as programmed (s): each of its moves' length at its "
        "programmed feed, from its first waypoint (the move into it from a rapid's target is "
        "no pass's; a move that only turns the tool counts 0; no ramps); null where a move has "
        "no feed (poses and tool axes, or a CSV without feeds).",
    )


UNITS_SOURCE = (
    "How the units were known: stated by the file (UNITS, UNIT), inferred (no UNITS record, "
    "but FEDRAT/IPM: inches), or from the request (its units; metres for poses and tool-axis "
    "waypoints)."
)
UNITS_NOTE = "The evidence for the units, e.g. 'UNITS/MM at line 3'."
ENDED = (
    "CL data: whether the program ends as CAM systems end one: FINI or END-OF-PATH after its "
    "last move and, where an NX listing states its length on its last line, that many lines. "
    "false: the program may be cut short (a transfer, a full disk) and the path is only what "
    "was read: end_note says where it stops. null for a CSV, which has no end record."
)
END_NOTE = (
    "How the program ends: 'FINI at line 233', or where it stops and what is missing ('no "
    "FINI or END-OF-PATH after the last move (GOTO at line 812): ...')."
)
SKIPPED = (
    "CL data: the records skipped (no geometry, no feed), one entry a word, in the order "
    "first met; empty for other forms."
)


class PathRead(ResponseModel):
    """How a CAM program (CL data or CSV) was read: what ``POST /v1/paths/import`` reports.

    Everything the import answer says of the program but its waypoints: the units and how they
    were known (stated, inferred and from which record and line, or the request's), the
    program's feed, its passes with their operations, and what was skipped or dropped.
    """

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "form": "cl_data",
                    "units": "inches",
                    "units_source": "inferred",
                    "units_note": "no UNITS record; a feed in inches per minute, FEDRAT/IPM at "
                    "line 21",
                    "feed": 0.008467,
                    "pass_details": [
                        {"start": 0, "stop": 83, "operation": "FLOOR_SLOT", "feed": 0.008467},
                        {"start": 83, "stop": 89, "operation": "VARIABLE_CONTOUR", "feed": 0.00635},
                    ],
                    "skipped_records": [
                        {"word": "PAINT", "count": 11, "first_line": 11, "recognised": True}
                    ],
                    "repeated_points": 1,
                    "one_point_passes": 0,
                    "arcs": 2,
                    "ended": True,
                    "end_note": "END-OF-PATH at line 95; 89 lines, as the listing's last line "
                    "states",
                }
            ]
        }
    )

    form: Literal["cl_data", "csv"] = Field(description="The path form read: cl_data or csv.")
    units: str = Field(description="The length unit the program was written in (mm, inches, m).")
    units_source: Literal["stated", "inferred", "request"] = Field(description=UNITS_SOURCE)
    units_note: str = Field(description=UNITS_NOTE)
    feed: float | None = Field(
        description="The program's feed (m/s), its highest FEDRAT; null when none is programmed."
    )
    pass_details: list[PassOut] = Field(
        description="Each pass in order, [start, stop) into the waypoints, with its operation "
        "and feed."
    )
    skipped_records: list[SkippedRecordOut] = Field(description=SKIPPED)
    repeated_points: int = Field(
        description="CL data: GOTOs to where the tool already was, dropped."
    )
    one_point_passes: int = Field(description="CL data: passes of a single point, dropped.")
    arcs: int = Field(description="CL data: CIRCLE moves interpolated into waypoints.")
    ended: bool | None = Field(description=ENDED)
    end_note: str = Field(description=END_NOTE)


PATH_READ = (
    "When the path came as CL data or CSV: how the program was read, as POST /v1/paths/import "
    "reports it (units and how they were known: stated, inferred from which record and line, "
    "or the request's; the program's feed; passes and operations; records skipped and "
    "counted); null for poses and tool-axis waypoints."
)
"""The description of every answer's ``path_read`` field."""
FAILED_PASS = (
    "When the path came as CL data or CSV and a waypoint fails: the pass holding it (index into "
    "path_read.pass_details, from 0); null otherwise."
)
FAILED_LINE = (
    "When the path came as CL data or CSV and a waypoint fails: the line of the program (from "
    "1) it was read from (an arc's inner points: the CIRCLE's line); null otherwise."
)
FAILED_OPERATION = (
    "When the path came as CL data or CSV and a waypoint fails: the operation of its pass, as "
    "the file names it (NX TOOL PATH, PARTNO, PPRINT); null otherwise or where none is named."
)
