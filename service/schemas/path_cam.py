"""The CAM forms of a request's path: a program as APT CL data, or a CSV file (cam.md).

Each is read by the solver's CAM readers (units, passes, feed, what was skipped) and converts
itself to the poses the solver takes (``to_solver``).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import ConfigDict, Field, PrivateAttr
from typing_extensions import TypeAliasType

from service.config import MAX_PATH_WAYPOINTS
from service.schemas.common import RequestModel
from service.schemas.path_input import PathInput
from solver.cam.cam_path import CamPath, Units
from solver.cam.cl_data import DEFAULT_ARC_TOLERANCE, read_cl_data
from solver.cam.csv_path import csv_waypoints, read_csv_path

ProgramUnits = TypeAliasType(
    "ProgramUnits",
    Annotated[
        Literal["mm", "inch", "inches"],
        Field(
            description="The length unit of a CL program that states none: mm or inch "
            "(inches, as answers name it, too).",
            examples=["mm"],
        ),
    ],
)
"""The units a request gives a CL program (a named component for generated clients)."""


MAX_CAM_TEXT = 2_000_000
"""Characters of CL data or CSV at most (a request body is at most 2 MB anyway)."""


CL_UNITS: dict[str, Units] = {"mm": "mm", "inch": "inches", "inches": "inches"}
"""A request's units of a CL program; ``inches`` is how answers name the unit, so an answer's
``units`` can be sent back (it was refused: audit 24)."""


class ClDataPath(RequestModel):
    """A CAM program as APT CL data (cam.md sections 5 and 9), as CAM systems write it.

    NX, SolidWorks CAM, CATIA or Mastercam: passes split at rapids, tool changes and
    operations; feed from FEDRAT.
    """

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "cl_data": "UNITS/MM\nMULTAX/ON\nFEDRAT/MMPM, 1500\n"
                    "GOTO/0, 0, 0, 0, 0, 1\nGOTO/10, 0, 0, 0, 0, 1\nGOTO/20, 0, 1, 0, 0, 1\n"
                }
            ]
        }
    )

    cl_data: str = Field(
        min_length=1,
        max_length=MAX_CAM_TEXT,
        description="APT CL data as CAM writes it (cam.md sections 5 and 9): GOTO (3 numbers "
        "keep the last tool axis), CIRCLE arcs, FEDRAT, RAPID, UNITS/UNIT, MSYS/CSYS, TOOL PATH "
        "and tool changes. Records without geometry or feed are skipped and counted (see "
        "/v1/paths/import); a record that would move the tool in a way not applied is a 422 "
        "naming its line. Tool axes within 1e-3 of unit length are normalised and the "
        "correction reported. The default spin_mode is free; the default feed of /v1/evaluate "
        "is the program's highest FEDRAT.",
    )
    units: ProgramUnits | None = Field(
        default=None,
        description="The length unit, for a program that states none (no UNITS or UNIT record "
        "and no FEDRAT/IPM, from which inches are inferred). A program that states none and "
        "is sent without units is a 422 on path.units; units that contradict the program's "
        "UNITS record are a 422 too.",
    )
    arc_tolerance: float = Field(
        default=DEFAULT_ARC_TOLERANCE,
        ge=1e-7,
        le=1e-3,
        description="m: CIRCLE arcs are interpolated by points whose chords stay this close to "
        "the arc (default 1e-5 m = 0.01 mm).",
    )
    _read: CamPath | None = PrivateAttr(default=None)

    def cam_path(self) -> CamPath:
        """The program as read, once (the waypoint count and the poses come from one reading).

        Raises:
            InvalidLineError: a record that cannot be read, naming its line.
            InvalidInputError: no units (on ``path.units``), or more waypoints than any route
                takes (on ``path``).
        """
        if self._read is None:
            self._read = read_cl_data(
                self.cl_data,
                units=None if self.units is None else CL_UNITS[self.units],
                arc_tolerance=self.arc_tolerance,
                max_waypoints=MAX_PATH_WAYPOINTS,
                field="path.cl_data",
                units_field="path.units",
            )
        return self._read

    def n_waypoints(self) -> int:
        """The number of waypoints as read: what /v1/paths/import shows (cam.md section 9)."""
        return self.cam_path().n_waypoints

    def to_solver(self) -> PathInput:
        """The program's poses, passes, feed, units and what was skipped.

        Raises:
            InvalidLineError: a record that cannot be read, naming its line.
        """
        return PathInput.from_cam(self.cam_path(), form="cl_data", units_note="")


class CsvPath(RequestModel):
    """A path as CSV, one waypoint a line: x,y,z,i,j,k (tool axis) or x,y,z,qx,qy,qz,qw."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [{"csv": "x,y,z,i,j,k\n0,0,0,0,0,1\n10,0,0,0,0,1\n", "units": "mm"}]
        }
    )

    csv: str = Field(
        min_length=1,
        max_length=MAX_CAM_TEXT,
        description="One waypoint a line: x,y,z,i,j,k (a tool axis, tip towards holder) or "
        "x,y,z,qx,qy,qz,qw (a pose); an optional header line naming those columns. Vectors "
        "within 1e-3 of unit length are normalised and the correction reported.",
    )
    units: Literal["mm", "inch", "inches", "m"] = Field(
        description="The unit of x, y, z: mm, inch (inches, as answers name it, too) or m."
    )

    def n_waypoints(self) -> int:
        """The number of waypoints as read: the non-blank lines after any header (cam.md 9)."""
        return csv_waypoints(self.csv)

    def to_solver(self) -> PathInput:
        """The path's poses (one pass, no feed).

        Raises:
            InvalidLineError: a line that cannot be read, naming it.
        """
        cam = read_csv_path(self.csv, units=self.units, field="path.csv")
        return PathInput.from_cam(cam, form="csv", units_note=f"the request's units ({self.units})")
