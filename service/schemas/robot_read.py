"""How a request's URDF was read, where the service changed anything in it (robots.md 4).

``/v1/evaluate``, ``/v1/map`` and ``/v1/optimize`` (and their jobs) give it as ``robot_read``,
rather than refusing a file as its generator wrote it or reading it otherwise without a word:
a link that no joint names has no pose and is no part of the robot, and pinocchio refuses the
document for it (two root links), so the service takes it out (a ROS 2 generated UR5e's
``<link name="world"/>``, whose joint the generator left out); a ``continuous`` joint (Kinova's
arms) is read as a revolute joint, with no position limit where the file gives none; a joint
that moves but not the tool frame (a gripper's fingers) is locked at 0.
"""

from __future__ import annotations

from pydantic import ConfigDict, Field

from service.schemas.common import ResponseModel


class RobotRead(ResponseModel):
    """What the service changed in the request's URDF before reading it."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "left_out_links": ["world"],
                    "left_out_count": 1,
                    "continuous_joints": [],
                    "unlimited_joints": [],
                    "locked_joints": [],
                }
            ]
        }
    )

    left_out_links: list[str] = Field(
        description="Links no joint names, as parent or child, in the document's order (the "
        "first 20, names cut at 100 characters): joined to nothing, they have no pose and are "
        "no part of the robot, so they were left out of the document (which has one root link "
        "without them). Such a link with collision geometry, or named as base_frame or "
        "tool_frame, is not left out: the request is refused naming the root links."
    )
    left_out_count: int = Field(description="How many links were left out (all of them).")
    continuous_joints: list[str] = Field(
        description="The chain's continuous joints (names cut at 100 characters), read as "
        "revolute joints: one angle each, with the lower and upper limits the file gives "
        "anyway (as Kinova's do), else none (unlimited_joints)."
    )
    unlimited_joints: list[str] = Field(
        description="Those continuous joints whose <limit> gives no lower or upper: no "
        "position limit on that side (a continuous joint has none in URDF's own terms), only "
        "the speed limit."
    )
    locked_joints: list[str] = Field(
        description="The document's joints that move but not tool_frame (a gripper's fingers, "
        "an arm's second branch), in its order: locked at 0 (their geometry, in a cell, "
        "where 0 puts it)."
    )


ROBOT_READ = (
    "When the robot is a request's URDF the service changed before reading it (links no joint "
    "names left out, continuous joints read as revolute ones, joints off the chain locked): "
    "what; null otherwise (and for catalogue robots)."
)
"""The description of every answer's ``robot_read`` field."""
