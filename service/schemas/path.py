"""The tool path of a request: one object per path form, told apart by its key (cam.md).

``path`` is a ``oneOf``: full poses (``waypoints``) or tool points with tool axes
(``tool_axis_waypoints``). Each form converts itself to the poses the solver takes
(``to_solver``); a new path form (CL data, CSV) is a new variant here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated

import numpy as np
from pydantic import ConfigDict, Discriminator, Field, Tag

from service.schemas.common import Pose, RequestModel, SpinMode, ToolAxisWaypoint, pose_matrix_of
from solver.spatial import check_position
from solver.task import task_requirements
from solver.tool_axis import poses_from_tool_axes

MAX_PATH_WAYPOINTS = 20_000
"""The most waypoints any route takes (DTF_MAX_PATH_WAYPOINTS may lower it, never raise it)."""


@dataclass(frozen=True)
class PathInput:
    """A request's path as the solver takes it.

    Attributes:
        poses: shape (N, 4, 4), T_O_i (m).
        axis_correction: the largest correction made to a tool axis's length (0 for poses).
        default_spin_mode: ``free`` for a path given by tool axes, ``fixed`` for poses.
    """

    poses: np.ndarray
    axis_correction: float
    default_spin_mode: SpinMode


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
        poses = np.array(
            [
                pose_matrix_of(pose, field=f"path.waypoints.{i}")
                for i, pose in enumerate(self.waypoints)
            ]
        )
        return PathInput(poses=poses, axis_correction=0.0, default_spin_mode="fixed")


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


_FORMS = ("waypoints", "tool_axis_waypoints")


def _path_form(value: object) -> str | None:
    """Tag of a path: which one of its forms it gives (``None``: not exactly one)."""
    if isinstance(value, dict):
        given = [key for key in _FORMS if value.get(key) is not None]
        return f"path:{given[0]}" if len(given) == 1 else None
    if isinstance(value, PosePath):
        return "path:waypoints"
    if isinstance(value, ToolAxisPath):
        return "path:tool_axis_waypoints"
    return None


Path = Annotated[
    Annotated[PosePath, Tag("path:waypoints")]
    | Annotated[ToolAxisPath, Tag("path:tool_axis_waypoints")],
    Discriminator(
        _path_form,
        custom_error_type="path_form",
        custom_error_message="give exactly one of waypoints or tool_axis_waypoints",
    ),
]
"""The tool path in the workpiece frame {O}, in machining order: poses or tool axes."""
