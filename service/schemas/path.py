"""The tool path of a request: one object per path form, told apart by its key (cam.md).

``path`` is a ``oneOf``: full poses (``waypoints``), tool points with tool axes
(``tool_axis_waypoints``), or a CAM program as CL data or CSV (:mod:`service.schemas.path_cam`).
Each form converts itself to the poses the solver takes (``to_solver``, a
:class:`~service.schemas.path_input.PathInput`); a new path form is a new variant here.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import ConfigDict, Discriminator, Field, Tag

from service.config import MAX_PATH_WAYPOINTS
from service.schemas.common import Pose, RequestModel, ToolAxisWaypoint
from service.schemas.path_cam import ClDataPath, CsvPath
from service.schemas.path_input import PathInput
from solver.core.spatial import check_position, pose_matrices
from solver.core.task import task_requirements
from solver.core.tool_axis import poses_from_tool_axes

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
        return PathInput(
            poses=poses, axis_correction=correction, default_spin_mode="free", source=field
        )


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
