"""``GET /v1/robots``: the robot catalogue."""

from __future__ import annotations

from fastapi import APIRouter

from service import convert
from service.deps import CatalogueDep
from service.schemas import RobotsResponse

router = APIRouter(prefix="/robots", tags=["robots"])


@router.get("", operation_id="list_robots", summary="The robot catalogue")
def list_robots(robots: CatalogueDep) -> RobotsResponse:
    """Every robot that ``robot.model`` can name, with its joints and limits."""
    return RobotsResponse(robots=[convert.robot_info(robot) for robot in robots.values()])
