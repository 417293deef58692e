"""The robot in answers: a catalogue entry, and what was changed in a request's URDF.

``GET /v1/robots`` shows catalogue robots (:func:`robot_info`); answers say what was changed in
a request's URDF (:func:`robot_read_of`). Pictures and messages name a request's URDF robot by
its own name (:attr:`solver.core.robots.Robot.shown_name`).
"""

from __future__ import annotations

from service import schemas
from solver.core.exceptions import MAX_LISTED_NAMES, cut
from solver.core.robots import Robot


def robot_read_of(robot: Robot) -> schemas.RobotRead | None:
    """What was changed in a request's URDF before it was read; None where nothing was.

    None for a catalogue robot too (the catalogue says how each arm is read: the Panda's
    fingers locked, the Jaco2's continuous joints revolute).
    """
    reading = robot.reading
    left_out = reading.left_out_links
    changed = left_out or reading.continuous_joints or reading.locked_joints
    if robot.name != "urdf" or not changed:
        return None
    return schemas.RobotRead(
        left_out_links=[cut(name) for name in left_out[:MAX_LISTED_NAMES]],
        left_out_count=len(left_out),
        continuous_joints=[cut(name) for name in reading.continuous_joints],
        unlimited_joints=[cut(name) for name in reading.unlimited_joints],
        locked_joints=[cut(name) for name in reading.locked_joints],
    )


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
