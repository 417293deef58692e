"""``POST /v1/evaluate``: mu_path of a path at one placement (spec sections 2-4)."""

from __future__ import annotations

from fastapi import APIRouter

from service import convert
from service.errors import ERROR_RESPONSES
from service.schemas import EvaluateRequest, EvaluateResponse
from solver.evaluate import evaluate_path

router = APIRouter(prefix="/evaluate", tags=["evaluate"], responses=ERROR_RESPONSES)


@router.post("", summary="Feasibility and mu_path of a path at a placement")
def post_evaluate(body: EvaluateRequest) -> EvaluateResponse:
    """An unreachable placement is not an error: it answers ``feasible: false`` with a reason."""
    robot = convert.robot_from_schema(body.robot)
    evaluation = evaluate_path(
        robot,
        convert.waypoints_of(body.path),
        convert.placement_of(body.placement),
        branch=convert.branch_of(body.ik.branch),
        max_joint_step=body.ik.max_joint_step,
    )
    return convert.evaluate_response(evaluation, robot)
