"""Evaluating a path at one placement (``POST /v1/evaluate`` and evaluate jobs)."""

from __future__ import annotations

from service import convert
from service.config import Settings
from service.render import render_joint_use
from service.schemas import EvaluateRequest, EvaluateResponse, PathInput
from solver.core.exceptions import InvalidInputError
from solver.core.progress import Progress
from solver.core.robots import Robot as SolverRobot
from solver.path.cycle_time import cycle_time
from solver.path.evaluate import PathEvaluation, evaluate_path
from solver.path.feed import check_feed
from solver.path.joint_path import evaluate_joint_path
from solver.path.problem import PathProblem


def _evaluated(
    body: EvaluateRequest, settings: Settings
) -> tuple[SolverRobot, PathInput, PathEvaluation, float | None, PathProblem]:
    """The robot, the path, its evaluation, the feed to check and the problem.

    The path's size is checked first.
    """
    convert.check_path_size(
        body.path, limit=settings.max_path_waypoints, setting="DTF_MAX_PATH_WAYPOINTS"
    )
    robot = convert.robot_from_schema(body.robot)
    path = convert.path_of(body.path)
    poses, placement = convert.spun_poses(path, body.spins), convert.placement_of(body.placement)
    spin_mode = convert.spin_mode_of(body.spin_mode, path)
    cell = convert.cell_of(body.cell, settings)
    problem = convert.problem_of(robot, poses, path, ik=body.ik, spin_mode=spin_mode, cell=cell)
    if body.joint_path is not None:
        if spin_mode != "fixed":
            raise InvalidInputError("joint_path", "a joint path is evaluated in spin_mode fixed")
        joint_path = convert.joint_path_of(body.joint_path, robot)
        evaluation = evaluate_joint_path(problem, placement, joint_path)
    else:
        evaluation = evaluate_path(problem, placement)
    feed = body.feed if body.feed is not None else path.feed
    return robot, path, evaluation, feed, problem


def joint_use_png(body: EvaluateRequest, settings: Settings) -> bytes:
    """The PNG of each joint's use of its speed (and acceleration) limit at the feed.

    The feed defaults to mu_path, or mu_acc with acceleration limits.

    Raises:
        InvalidInputError: on ``placement``, the path does not run there.
    """
    robot, _, evaluation, feed, _ = _evaluated(body, settings)
    index = evaluation.feed_index  # mu_acc with acceleration limits
    if index is None or index <= 0.0:
        raise InvalidInputError(
            "placement",
            f"the path does not run here ({evaluation.reason or 'mu_path is 0'}): no joint "
            "speeds to draw; ask for JSON to see why",
        )
    check = check_feed(
        evaluation, index if feed is None else feed, robot.qdot_max, qddot_max=robot.qddot_max
    )
    return render_joint_use(check, evaluation, robot.joint_names, title=robot.name)


def evaluation_of(
    body: EvaluateRequest, settings: Settings, progress: Progress
) -> EvaluateResponse:
    """The JSON answer of ``POST /v1/evaluate`` (an evaluate job's result too)."""
    robot, path, evaluation, feed, problem = _evaluated(body, settings)
    detail = body.detail or (
        "waypoints" if body.path.n_waypoints() <= settings.max_detail_waypoints else "summary"
    )
    return convert.evaluate_response(
        evaluation,
        robot,
        axis_correction=path.axis_correction,
        with_waypoints=detail == "waypoints",
        feed=None if feed is None else check_feed(evaluation, feed, robot.qdot_max),
        cycle_time=cycle_time(problem, evaluation),
    )
