"""The arm of a request: one object per robot source, told apart by its key (api.md, robots.md).

``robot`` is a ``oneOf``: a catalogue ``model``, a ``urdf`` with its frames, or an ``opw``
geometry. Each variant states its own rules as JSON Schema (the model names as an enum, speed
limits within [1e-6, 1e4], list lengths), so a generated client knows what is accepted, and each
converts itself to the solver's robot (``to_solver``). A new robot source is a new variant here.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import ConfigDict, Discriminator, Field, Tag, field_validator
from pydantic.config import JsonValue
from pydantic_core import PydanticCustomError

from service.schemas.common import shown
from service.schemas.opw_robot import OpwRobot
from service.schemas.robot_options import RobotOptions, SpeedLimit, speed_limits_field
from solver.core.robots import Robot as SolverRobot
from solver.families import catalogue, robot_from_urdf


def catalogue_dofs() -> set[int]:
    """The numbers of joints of the catalogue's arms."""
    return {robot.dof for robot in catalogue().values()}


_DOFS = sorted(catalogue_dofs())


class CatalogueRobot(RobotOptions):
    """A robot of the catalogue (GET /v1/robots), optionally with other speed limits."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {"model": "ur5e"},
                {"model": "ur5", "joint_velocity_limits": [3.0, 3.0, 3.0, 3.0, 3.0, 3.0]},
            ]
        }
    )

    model: str = Field(
        description="A robot name from GET /v1/robots.",
        json_schema_extra={"enum": list[JsonValue](sorted(catalogue()))},
    )
    joint_velocity_limits: list[SpeedLimit] | None = speed_limits_field(
        _DOFS, required=False, extra=" Default: the model's."
    )

    @field_validator("model")
    @classmethod
    def _known(cls, value: str) -> str:
        names = catalogue()
        if value not in names:
            raise PydanticCustomError(
                "unknown_robot",
                "unknown robot {name}; the catalogue has {names}",
                {"name": shown(value), "names": ", ".join(sorted(names))},
            )
        return value

    def to_solver(self) -> SolverRobot:
        """The catalogue robot with this request's speed limits and tool point."""
        robot = catalogue()[self.model].with_options(qdot_max=self.joint_velocity_limits)
        return self._with_tcp(robot)


class UrdfRobot(RobotOptions):
    """A serial arm described by a URDF document and the two frames that bound its chain."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "urdf": "<robot name='arm'>...</robot>",
                    "base_frame": "base",
                    "tool_frame": "tool0",
                }
            ]
        }
    )

    urdf: str = Field(
        min_length=1,
        description="URDF document of a serial arm (lengths in m, angles in rad); joints that do "
        "not move tool_frame are locked at 0; links no joint names are left out and continuous "
        "joints read as revolute ones (no position limit where the file gives none); answers "
        "say all three in robot_read.",
    )
    base_frame: str = Field(
        min_length=1,
        description="The frame fixed to the root that poses and twists are expressed in; a link "
        "or frame of the URDF.",
    )
    tool_frame: str = Field(
        min_length=1, description="The tool flange frame; a link or frame of the URDF."
    )
    joint_velocity_limits: list[SpeedLimit] | None = speed_limits_field(
        None,
        required=False,
        extra=" Default: the URDF's velocity limits. With <mimic> joints, one per coordinate (a "
        "mimic joint has none): a leader's limit above its mimic joint's own over |multiplier| "
        "is refused (422).",
    )

    def to_solver(self) -> SolverRobot:
        """The arm of the URDF, with its speed limits and tool point."""
        robot = robot_from_urdf(
            self.urdf,
            base_frame=self.base_frame,
            tool_frame=self.tool_frame,
            qdot_max=self.joint_velocity_limits,
        )
        return self._with_tcp(robot)


_SOURCES = ("model", "urdf", "opw")


def _robot_source(value: object) -> str | None:
    """Tag of a robot: which one of model, urdf or opw it gives (``None``: not exactly one)."""
    if isinstance(value, dict):
        given = [key for key in _SOURCES if value.get(key) is not None]
        return f"robot:{given[0]}" if len(given) == 1 else None
    for kind, source in ((CatalogueRobot, "model"), (UrdfRobot, "urdf"), (OpwRobot, "opw")):
        if isinstance(value, kind):
            return f"robot:{source}"
    return None


Robot = Annotated[
    Annotated[CatalogueRobot, Tag("robot:model")]
    | Annotated[UrdfRobot, Tag("robot:urdf")]
    | Annotated[OpwRobot, Tag("robot:opw")],
    Discriminator(
        _robot_source,
        custom_error_type="robot_source",
        custom_error_message="give exactly one of model (a name from GET /v1/robots), urdf or opw",
    ),
]
"""The arm: a catalogue model, a URDF with its frames, or an OPW geometry with its limits."""
