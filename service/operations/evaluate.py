"""Evaluating a path at one placement (``POST /v1/evaluate`` and evaluate jobs)."""

from __future__ import annotations

from service import convert
from service.config import Settings
from service.schemas import EvaluateRequest, EvaluateResponse, PathInput
from solver.core.exceptions import InvalidInputError, SolverError
from solver.core.progress import Progress
from solver.core.robots import Robot as SolverRobot
from solver.core.task import task_requirements
from solver.path.cycle_time import cycle_time
from solver.path.evaluate import PathEvaluation, evaluate_path
from solver.path.feed import check_feed
from solver.path.joint_path import evaluate_joint_path
from solver.path.problem import PathProblem


def _evaluated(
    body: EvaluateRequest, settings: Settings, progress: Progress | None
) -> tuple[SolverRobot, PathInput, PathEvaluation, float | None, PathProblem]:
    """The robot, the path, its evaluation, the feed to check and the problem.

    The path's size is checked first; ``progress`` is handed to the evaluation (a numeric
    family reports as it goes, so a client that leaves stops it).
    """
    convert.check_path_size(
        body.path, limit=settings.max_path_waypoints, setting="DTF_MAX_PATH_WAYPOINTS"
    )
    robot = convert.robot_from_schema(body.robot)
    path = convert.path_of(body.path)
    poses, placement = convert.spun_poses(path, body.spins), convert.placement_of(body.placement)
    spin_mode = convert.spin_mode_of(body.spin_mode, path)
    cell = convert.cell_of(body.cell, settings, robot)
    problem = convert.problem_of(robot, poses, path, ik=body.ik, spin_mode=spin_mode, cell=cell)
    _check_work(problem, settings)
    if body.spins is not None:
        _prepared_with_spins(problem, path)
    if body.joint_path is not None:
        if spin_mode != "fixed":
            raise InvalidInputError("joint_path", "a joint path is evaluated in spin_mode fixed")
        joint_path = convert.joint_path_of(body.joint_path, robot)
        evaluation = evaluate_joint_path(problem, placement, joint_path, progress=progress)
    else:
        evaluation = evaluate_path(problem, placement, progress=progress)
    feed = body.feed if body.feed is not None else path.feed
    return robot, path, evaluation, feed, problem


def _prepared_with_spins(problem: PathProblem, path: PathInput) -> None:
    """The spun path prepared; an error of its waypoints the path sent has not is the spins'.

    Spins can turn a waypoint onto the pose before it (a pure spin turned back), or make a
    segment a half turn: the refusal named ``path.waypoints[i]`` of a path that is valid as
    sent (audit 23). It names ``spins[i]`` there, saying so.

    Raises:
        SolverError: the path's own, as preparing it raises them; InvalidInputError on
            ``spins`` where the waypoints i - 1 and i are a valid segment without them.
    """
    try:
        problem.prepared  # noqa: B018 - prepared here to tell whose error it is
    except SolverError as error:
        index = error.waypoint
        if not error.field.startswith("path") or index is None or index < 1:
            raise
        try:
            free_spin = problem.options.spin_mode == "free"
            segment = path.poses[index - 1 : index + 1]
            task_requirements(segment, field=error.field, free_spin=free_spin)
        except SolverError:
            raise error from None
        raise InvalidInputError(
            "spins",
            f"with spins {index - 1} and {index} the segment from waypoint {index - 1} is "
            f"refused, not without them: {error.message}",
            waypoint=index,
        ) from error


def _check_work(problem: PathProblem, settings: Settings) -> None:
    """Refuse an evaluation whose work, weighed as a map's, is over the map limit (before it).

    One placement of the path costs the problem's ``path_cost`` in closed-form poses (one a
    waypoint for a closed-form family, far more for numeric IK, plus the collision check's
    with a cell), the unit of the map limit.

    Raises:
        InvalidInputError: on ``path``, saying the work and the limit.
    """
    n_waypoints = len(problem.waypoints)
    work = problem.path_cost(n_waypoints)
    cell = ", with a cell" if problem.options.cell is not None else ""
    limits = settings.map_limits()
    if work > limits.poses:
        raise InvalidInputError(
            "path",
            f"{n_waypoints} waypoints, as work {work:.4g} closed-form poses "
            f"({problem.family.name} IK{cell}); the limit is {limits.poses} "
            f"({limits.poses_setting})",
        )


def joint_use_png(
    body: EvaluateRequest, settings: Settings, progress: Progress | None = None
) -> bytes:
    """The PNG of each joint's use of its speed (and acceleration) limit at the feed.

    The feed defaults to mu_path, or mu_acc with acceleration limits.

    Where the path does not run (an unreachable placement is not an input error, api.md) the
    picture says so: why, and at which waypoint.
    """
    from service.render import render_joint_use, render_message  # matplotlib only where drawn

    robot, _, evaluation, feed, _ = _evaluated(body, settings, progress)
    index = evaluation.feed_index  # mu_acc with acceleration limits
    if index is None or index <= 0.0:
        where = (
            ""
            if evaluation.failed_waypoint is None
            else f" at waypoint {evaluation.failed_waypoint}"
        )
        why = f"{evaluation.reason}{where}" if evaluation.reason else "mu_path is 0"
        return render_message(
            f"{robot.shown_name}: the path does not run at this placement ({why}); no "
            "joint speeds to draw (POST /v1/evaluate says more)"
        )
    check = check_feed(
        evaluation, index if feed is None else feed, robot.qdot_max, qddot_max=robot.qddot_max
    )
    return render_joint_use(check, evaluation, robot.joint_names, title=robot.shown_name)


def evaluation_of(
    body: EvaluateRequest, settings: Settings, progress: Progress
) -> EvaluateResponse:
    """The JSON answer of ``POST /v1/evaluate`` (an evaluate job's result too)."""
    robot, path, evaluation, feed, problem = _evaluated(body, settings, progress)
    detail = body.detail or (
        "waypoints" if body.path.n_waypoints() <= settings.max_detail_waypoints else "summary"
    )
    return convert.evaluate_response(
        evaluation,
        robot,
        axis_correction=convert.request_correction(path, body.robot, body.cell),
        with_waypoints=detail == "waypoints",
        feed=None if feed is None else check_feed(evaluation, feed, robot.qdot_max),
        cycle_time=cycle_time(problem, evaluation),
        path_read=convert.path_read_of(path),
        robot_read=convert.robot_read_of(robot),
        failed_in=convert.pass_at(path, evaluation.failed_waypoint),
        placement=convert.placement_of(body.placement),
        lines=path.lines,
    )
