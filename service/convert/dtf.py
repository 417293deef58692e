"""``POST /v1/dtf``: the answer from the solver's DTF result."""

from __future__ import annotations

from service import schemas
from service.convert.robots import robot_read_of
from solver.core.dtf import DtfResult
from solver.core.robots import Robot


def dtf_response(
    result: DtfResult, robot: Robot, *, yoshikawa: float, chiu: float
) -> schemas.DtfResponse:
    """The response of ``POST /v1/dtf``."""
    return schemas.DtfResponse(
        v_max=result.v_max,
        omega_max=result.omega_max,
        qdot=result.qdot.tolist(),
        limiting_joint=result.limiting_joint,
        limiting_joint_name=robot.joint_names[result.limiting_joint],
        method=result.method,
        yoshikawa=yoshikawa,
        chiu=chiu,
        robot_read=robot_read_of(robot),
    )
