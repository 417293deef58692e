"""The tool path of a request: one object per path form, told apart by its key (cam.md).

``path`` is a ``oneOf``: full poses (``waypoints``) or tool points with tool axes
(``tool_axis_waypoints``). Each form converts itself to the poses the solver takes
(``to_solver``); a new path form (CL data, CSV) is a new variant here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Literal

import numpy as np
from pydantic import ConfigDict, Discriminator, Field, PrivateAttr, Tag
from typing_extensions import TypeAliasType

from service.schemas.common import Pose, RequestModel, SpinMode, ToolAxisWaypoint
from solver.cam.cam_path import CamPath, Units
from solver.cam.cl_data import DEFAULT_ARC_TOLERANCE, read_cl_data
from solver.cam.csv_path import read_csv_path
from solver.cam.read_report import ReadReport, UnitsSource
from solver.cam.reading import is_number
from solver.core.spatial import check_position, pose_matrices
from solver.core.task import task_requirements
from solver.core.tool_axis import poses_from_tool_axes

MAX_PATH_WAYPOINTS = 20_000
"""The most waypoints any route takes (DTF_MAX_PATH_WAYPOINTS may lower it, never raise it)."""


ProgramUnits = TypeAliasType(
    "ProgramUnits",
    Annotated[
        Literal["mm", "inch"],
        Field(description="The length unit of a CL program that states none: mm or inch."),
    ],
)
"""The units a request gives a CL program (a named component for generated clients)."""


@dataclass(frozen=True)
class PathInput:
    """A request's path as the solver takes it.

    Attributes:
        poses: shape (N, 4, 4), T_O_i (m).
        axis_correction: the largest correction made to a tool axis's length (0 for poses).
        default_spin_mode: ``free`` for a path given by tool axes, ``fixed`` for poses.
        passes: index ranges [start, stop) of the passes (cam.md section 5); None: one pass.
        feed: the program's feed (m/s), its highest FEDRAT; None when it programs none.
        units: the length unit the path was written in.
        units_source: how the units were known: ``stated``, ``inferred`` (CL data, from an
            inch feed) or ``request`` (the request's units, or metres by the API).
        units_note: the evidence for the units.
        pass_operations: each pass's operation name (CL data), ``None`` where none is named;
            empty for other forms.
        pass_feeds: each pass's highest feed (m/s) or ``None``; empty for poses and axes.
        one_point_passes: passes of one point dropped (CL data).
        report: what the CL reader skipped, dropped and inferred; ``None`` for other forms.
    """

    poses: np.ndarray
    axis_correction: float
    default_spin_mode: SpinMode
    passes: tuple[tuple[int, int], ...] | None = None
    feed: float | None = None
    units: str = "m"
    units_source: UnitsSource = "request"
    units_note: str = "the API's unit (m)"
    pass_operations: tuple[str | None, ...] = ()
    pass_feeds: tuple[float | None, ...] = ()
    one_point_passes: int = 0
    report: ReadReport | None = None


def _from_cam(cam: CamPath, *, field: str, units_note: str) -> PathInput:
    """The solver's path of a CAM program: its poses, passes, feed, units and read report."""
    report = cam.report
    return PathInput(
        poses=cam.waypoints_in_workpiece(field=field),
        axis_correction=cam.axis_correction,
        default_spin_mode=cam.default_spin_mode,
        passes=cam.passes,
        feed=cam.feed,
        units=cam.units,
        units_source="request" if report is None else report.units_source,
        units_note=units_note if report is None else report.units_note,
        pass_operations=cam.pass_operations,
        pass_feeds=cam.pass_feeds,
        one_point_passes=cam.one_point_passes,
        report=report,
    )


_RULES = (
    "consecutive ones distinct (apart by 1e-9 m or 1e-9 rad at least), and no segment turning "
    "the tool by a half turn (within 1e-6 rad; its turning direction is undefined)"
)


class PosePath(RequestModel):
    """A path of full poses of the tool point in the workpiece frame {O}, in machining order."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "waypoints": [
                        {"position": [0.0, 0.0, 0.0], "orientation": [1, 0, 0, 0]},
                        {"position": [0.01, 0.0, 0.0], "orientation": [1, 0, 0, 0]},
                    ]
                }
            ]
        }
    )

    waypoints: list[Pose] = Field(
        min_length=2,
        max_length=MAX_PATH_WAYPOINTS,
        description=f"2 to {MAX_PATH_WAYPOINTS} poses in {{O}} (m, unit quaternions); {_RULES}.",
    )

    def n_waypoints(self) -> int:
        """The number of waypoints N."""
        return len(self.waypoints)

    def to_solver(self) -> PathInput:
        """The poses T_O_i.

        Raises:
            InvalidInputError: a quaternion that is not unit, naming the waypoint.
        """
        quaternions = np.array([pose.orientation for pose in self.waypoints], dtype=float)
        positions = np.array([pose.position for pose in self.waypoints], dtype=float)
        poses = pose_matrices(positions, quaternions, field="path.waypoints")
        norms = np.linalg.norm(quaternions, axis=1)
        correction = float(np.max(np.abs(norms - 1.0)))
        return PathInput(poses=poses, axis_correction=correction, default_spin_mode="fixed")


class ToolAxisPath(RequestModel):
    """A path of tool points and tool axes, as five-axis CAM writes them (cam.md section 1).

    The rotation about each axis is the minimal-rotation frame; the default spin_mode is free.
    """

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "tool_axis_waypoints": [
                        {"position": [0.0, 0.0, 0.0], "axis": [0.0, 0.0, 1.0]},
                        {"position": [0.01, 0.0, 0.0], "axis": [0.0, 0.0, 1.0]},
                    ]
                }
            ]
        }
    )

    tool_axis_waypoints: list[ToolAxisWaypoint] = Field(
        min_length=2,
        max_length=MAX_PATH_WAYPOINTS,
        description=f"2 to {MAX_PATH_WAYPOINTS} tool points and axes in {{O}} (m); {_RULES}.",
    )

    def n_waypoints(self) -> int:
        """The number of waypoints N."""
        return len(self.tool_axis_waypoints)

    def to_solver(self) -> PathInput:
        """The poses T_O_i of the minimal-rotation frame along the axes.

        Raises:
            InvalidInputError, RepeatedWaypointError: naming the field and the waypoint.
        """
        points = self.tool_axis_waypoints
        field = "path.tool_axis_waypoints"
        positions = np.array(
            [
                check_position(p.position, field=f"{field}.{i}.position")
                for i, p in enumerate(points)
            ]
        )
        poses, correction = poses_from_tool_axes(positions, np.array([p.axis for p in points]))
        task_requirements(poses, field=field)  # names this field, not path.waypoints, on an error
        return PathInput(poses=poses, axis_correction=correction, default_spin_mode="free")


MAX_CAM_TEXT = 2_000_000
"""Characters of CL data or CSV at most (a request body is at most 2 MB anyway)."""


CL_UNITS: dict[str, Units] = {"mm": "mm", "inch": "inches"}


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
        return _from_cam(self.cam_path(), field="path.cl_data", units_note="")


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
    units: Literal["mm", "inch", "m"] = Field(description="The unit of x, y, z: mm, inch or m.")

    def n_waypoints(self) -> int:
        """The number of waypoints as read: the non-blank lines after any header (cam.md 9)."""
        rows = [row for row in self.csv.splitlines() if row.strip()]
        header = bool(rows) and not all(is_number(cell) for cell in rows[0].split(","))
        return len(rows) - int(header)

    def to_solver(self) -> PathInput:
        """The path's poses (one pass, no feed).

        Raises:
            InvalidLineError: a line that cannot be read, naming it.
        """
        cam = read_csv_path(self.csv, units=self.units, field="path.csv")
        return _from_cam(cam, field="path.csv", units_note=f"the request's units ({self.units})")


_FORMS = ("waypoints", "tool_axis_waypoints", "cl_data", "csv")


def _path_form(value: object) -> str | None:
    """Tag of a path: which one of its forms it gives (``None``: not exactly one)."""
    if isinstance(value, dict):
        given = [key for key in _FORMS if value.get(key) is not None]
        return f"path:{given[0]}" if len(given) == 1 else None
    if isinstance(value, PosePath):
        return "path:waypoints"
    for kind, form in ((ToolAxisPath, "tool_axis_waypoints"), (ClDataPath, "cl_data")):
        if isinstance(value, kind):
            return f"path:{form}"
    return "path:csv" if isinstance(value, CsvPath) else None


Path = Annotated[
    Annotated[PosePath, Tag("path:waypoints")]
    | Annotated[ToolAxisPath, Tag("path:tool_axis_waypoints")]
    | Annotated[ClDataPath, Tag("path:cl_data")]
    | Annotated[CsvPath, Tag("path:csv")],
    Discriminator(
        _path_form,
        custom_error_type="path_form",
        custom_error_message="give exactly one of waypoints, tool_axis_waypoints, cl_data or csv",
    ),
]
"""The tool path in {O}, in machining order: poses, tool axes, CL data or CSV."""
