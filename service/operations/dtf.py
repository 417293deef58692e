"""The DTF index at one configuration (``POST /v1/dtf``, spec section 3)."""

from __future__ import annotations

import math

from service import convert
from service.schemas import DtfRequest, DtfResponse
from solver.core.dtf import chiu, dtf, twist_per_unit_speed, yoshikawa
from solver.core.kinematics import check_configuration, jacobian_in_base


def dtf_of(body: DtfRequest) -> DtfResponse:
    """V_max, Omega_max and the joint speeds there, Yoshikawa and Chiu, and the correction made.

    ``correction``: the largest amount by which a given direction (u_T, u_R) was off unit length.

    Raises:
        InvalidInputError: the configuration (count, values, limits) or the robot.
    """
    robot = convert.robot_from_schema(body.robot)
    q = check_configuration(robot, body.q)
    jacobian = jacobian_in_base(robot, q)
    h = convert.h_of(body.h)
    result = dtf(
        jacobian, u_T=body.u_T, u_R=body.u_R, h=h, qdot_max=robot.qdot_max, method=body.method
    )
    twist = twist_per_unit_speed(body.u_T, body.u_R, h)
    given = [u for u in (body.u_T, body.u_R) if u is not None]
    correction = float(max((abs(math.hypot(*u) - 1.0) for u in given), default=0.0))
    answer = convert.dtf_response(
        result, robot, yoshikawa=yoshikawa(jacobian), chiu=chiu(jacobian, twist)
    )
    return answer.model_copy(update={"correction": correction})
