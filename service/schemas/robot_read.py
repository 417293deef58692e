"""How a request's URDF was read, where the service took anything out of it (robots.md 4).

``/v1/evaluate``, ``/v1/map`` and ``/v1/optimize`` (and their jobs) give it as ``robot_read``:
a link that no joint names has no pose and is no part of the robot, and pinocchio refuses the
document for it (two root links); the service takes it out and says so here, rather than refusing
a file as its generator wrote it (a ROS 2 generated UR5e's ``<link name="world"/>``, whose joint
the generator left out) or reading it without a word.
"""

from __future__ import annotations

from pydantic import ConfigDict, Field

from service.schemas.common import ResponseModel


class RobotRead(ResponseModel):
    """What the service took out of the request's URDF before reading it."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"left_out_links": ["world"], "left_out_count": 1}]}
    )

    left_out_links: list[str] = Field(
        description="Links no joint names, as parent or child, in the document's order (the "
        "first 20, names cut at 100 characters): joined to nothing, they have no pose and are "
        "no part of the robot, so they were left out of the document (which has one root link "
        "without them). Such a link with collision geometry, or named as base_frame or "
        "tool_frame, is not left out: the request is refused naming the root links."
    )
    left_out_count: int = Field(description="How many links were left out (all of them).")


ROBOT_READ = (
    "When the robot is a URDF out of which the service took something before reading it (links "
    "no joint names): what, as robot_read.left_out_links; null otherwise."
)
"""The description of every answer's ``robot_read`` field."""
