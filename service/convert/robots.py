"""``GET /v1/robots``: a catalogue robot as the API shows it."""

from __future__ import annotations

from service import schemas
from solver.core.robots import Robot


def robot_info(robot: Robot) -> schemas.RobotInfo:
    """One catalogue entry of ``GET /v1/robots``."""
    return schemas.RobotInfo(
        name=robot.name,
        dof=robot.dof,
        joint_names=list(robot.joint_names),
        q_lower=robot.q_lower.tolist(),
        q_upper=robot.q_upper.tolist(),
        qdot_max=robot.qdot_max.tolist(),
        base_frame=robot.base_frame,
        tool_frame=robot.tool_frame,
        family=None if robot.family is None else robot.family.name,
        branches=_branch_levels(robot),
    )


def _branch_levels(robot: Robot) -> list[schemas.BranchLevel]:
    """The levels of the robot's IK branches and the choices at each, in branch order."""
    if robot.family is None:
        return []
    choices: dict[str, list[str]] = {}
    for branch in robot.family.branches:
        for level, choice in branch.choices:
            if choice not in choices.setdefault(level, []):
                choices[level].append(choice)
    return [schemas.BranchLevel(level=level, choices=names) for level, names in choices.items()]
