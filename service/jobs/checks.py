"""A job's request checked as its route checks it, before the job is queued.

``POST /v1/jobs`` refuses what ``POST /v1/map``, ``/v1/optimize`` or ``/v1/evaluate`` would
refuse, with the same error types: the request's size against the job limits, the robot, the
path as read (a CSV, CL data, tool axes), the options against the robot, the grid, the bounds
and the start. What is left to the worker is the work itself. An error's field is given inside
the job's body (``request.path.csv``), as the job's schema errors are.
"""

from __future__ import annotations

from service import convert
from service.config import Settings
from service.operations import checked_grid
from service.operations.optimize import check_work, max_spin_step_of
from service.schemas import EvaluateRequest, MapRequest, OptimizeRequest
from service.schemas.jobs import EvaluateJob, JobRequest, MapJob
from solver.core.exceptions import InvalidInputError, SolverError
from solver.core.robots import Robot
from solver.optimise.optimize import check_search
from solver.path.problem import PathProblem


def check_job(body: JobRequest, settings: Settings) -> None:
    """Check a job's request as its route would, with the job limits (``settings.for_jobs()``).

    Raises:
        SolverError: the route's own error (its type kept), its field prefixed ``request.``.
    """
    try:
        if isinstance(body, MapJob):
            _check_map(body.request, settings.for_jobs())
        elif isinstance(body, EvaluateJob):
            _check_evaluate(body.request, settings.for_jobs())
        else:
            _check_optimize(body.request, settings.for_jobs())
    except SolverError as error:
        error.field = f"request.{error.field}" if error.field else "request"
        raise


def _problem(
    robot: Robot, body: MapRequest | EvaluateRequest | OptimizeRequest, settings: Settings
) -> PathProblem:
    """The path read and checked, the options (the cell too) checked against the robot."""
    path = convert.path_of(body.path)
    poses = convert.spun_poses(path, body.spins) if isinstance(body, EvaluateRequest) else None
    spin_mode = convert.spin_mode_of(body.spin_mode, path)
    problem = convert.problem_of(
        robot,
        path.poses if poses is None else poses,
        path,
        ik=body.ik,
        spin_mode=spin_mode,
        cell=convert.cell_of(body.cell, settings, robot),
    )
    problem.prepared  # noqa: B018 - the path checked (repeated waypoints, passes)
    problem.branches  # noqa: B018 - the options checked against the robot
    problem.path_checks  # noqa: B018 - the cell checked against the robot
    return problem


def _check_map(body: MapRequest, settings: Settings) -> None:
    robot = checked_grid(body, settings).robot
    _problem(robot, body, settings)


def _check_evaluate(body: EvaluateRequest, settings: Settings) -> None:
    convert.check_path_size(
        body.path, limit=settings.max_path_waypoints, setting="DTF_MAX_PATH_WAYPOINTS"
    )
    robot = convert.robot_from_schema(body.robot)
    problem = _problem(robot, body, settings)
    if body.joint_path is not None:
        if problem.options.spin_mode != "fixed":
            raise InvalidInputError("joint_path", "a joint path is evaluated in spin_mode fixed")
        convert.joint_path_of(body.joint_path, robot)


def _check_optimize(body: OptimizeRequest, settings: Settings) -> None:
    """The route's own checks: the optimiser's arguments (``check_search``), then the work."""
    convert.check_path_size(
        body.path, limit=settings.max_optimize_waypoints, setting="DTF_MAX_OPTIMIZE_WAYPOINTS"
    )
    robot = convert.robot_from_schema(body.robot)
    problem = _problem(robot, body, settings)
    bounds = convert.bounds_of(body.bounds, z=body.z)
    start = None if body.start is None else convert.placement_of(body.start)
    check_search(
        problem,
        bounds=bounds,
        start=start,
        method=body.method,
        max_spin_step=max_spin_step_of(body),
    )
    check_work(problem, bounds, body, settings)
