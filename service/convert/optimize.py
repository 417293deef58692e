"""``POST /v1/optimize``: the solver's box from the request; the answer from the optimum."""

from __future__ import annotations

from service import schemas
from service.convert.common import api_placement
from service.convert.evaluate import evaluate_response
from service.convert.path_read import pass_at, path_read_of
from service.convert.robots import robot_read_of
from service.schemas.path_input import PathInput
from solver.core.robots import Robot
from solver.optimise.failures import SearchFailure
from solver.optimise.optimum import PlacementOptimum
from solver.optimise.search_space import PlacementBounds
from solver.path.cycle_time import CycleTime
from solver.path.feed import check_feed


def bounds_of(bounds: schemas.Bounds, *, z: float | None) -> PlacementBounds:
    """The solver's placement box (m, m, rad) at height z (m), or with the height's range."""
    return PlacementBounds(
        x=(bounds.x[0], bounds.x[1]),
        y=(bounds.y[0], bounds.y[1]),
        yaw=(bounds.yaw[0], bounds.yaw[1]),
        z=(bounds.z[0], bounds.z[1]) if bounds.z is not None else float(z or 0.0),
        spin=(bounds.spin[0], bounds.spin[1]),
    )


def failure_to_api(
    failure: SearchFailure | None, path: PathInput | None
) -> schemas.SearchFailure | None:
    """The answer's ``failure``: the most common failure, its pass and operation, a sentence.

    With what the search tried on its way, by reason, each with its pass and operation.
    """
    if failure is None:
        return None
    k, operation = _pass_of(path, failure.failed_waypoint)
    tried = None
    if failure.tried is not None:
        tried = schemas.TriedPlacements(
            placements=failure.tried.placements,
            feasible=failure.tried.feasible,
            reasons=[
                schemas.ReasonCount(
                    reason=schemas.FailureReason(t.reason),
                    count=t.count,
                    failed_waypoint=t.failed_waypoint,
                    failed_pass=(where := _pass_of(path, t.failed_waypoint))[0],
                    failed_operation=where[1],
                )
                for t in failure.tried.reasons
            ],
        )
    return schemas.SearchFailure(
        reason=schemas.FailureReason(failure.reason),
        failed_waypoint=failure.failed_waypoint,
        failed_pass=k,
        failed_operation=operation,
        count=failure.count,
        judged=failure.judged,
        tried=tried,
        message=_failure_message(failure, _where(failure.failed_waypoint, k, operation))
        + ("" if tried is None else _tried_message(tried)),
    )


def _pass_of(path: PathInput | None, waypoint: int | None) -> tuple[int | None, str | None]:
    """The pass and operation of a waypoint of the request's path (None, None for none)."""
    return (None, None) if path is None else pass_at(path, waypoint)


def _where(waypoint: int | None, k: int | None, operation: str | None) -> str:
    """``first at waypoint W (pass K, OPERATION)``, or empty without a waypoint."""
    if waypoint is None:
        return ""
    where = f"first at waypoint {waypoint}"
    if k is not None:
        where += f" (pass {k}" + ("" if operation is None else f", {operation}") + ")"
    return where


def _failure_message(failure: SearchFailure, where: str) -> str:
    """Why nothing was found, in a sentence: the search's placements, or its start alone.

    ``where``: the first failing waypoint (with its pass and operation), or empty.
    """
    if failure.judged == 1:  # the search found no placement of its own to judge
        return (
            "the search proposed no placement but the start, and the start does not run it: "
            f"{failure.reason}" + (where and f", {where}")
        )
    return (
        f"none of the {failure.judged} placements judged on the whole path (the start "
        f"included) runs it; {failure.count} of them {failure.reason}"
        + (where and f", most often {where}")
    )


def _tried_message(tried: schemas.TriedPlacements) -> str:
    """The sentence's end: the placements the search tried, by reason (most common first)."""
    reasons = ", ".join(
        f"{r.count} {r.reason.value}"
        + (
            ""
            if r.failed_waypoint is None
            else f", most often {_where(r.failed_waypoint, r.failed_pass, r.failed_operation)}"
        )
        for r in tried.reasons
    )
    if not tried.feasible:
        return (
            f"; none of the {tried.placements} placements it tried on the whole path runs it: "
            + reasons
        )
    return (
        f"; of the {tried.placements} placements it tried on the whole path, {tried.feasible} "
        f"run it (no candidate from them did)" + (reasons and f", the others: {reasons}")
    )


def optimize_response(
    optimum: PlacementOptimum,
    robot: Robot,
    *,
    axis_correction: float = 0.0,
    path: PathInput | None = None,
    cycle_time: CycleTime | None = None,
) -> schemas.OptimizeResponse:
    """The answer of ``POST /v1/optimize`` (``found: false`` when nothing was feasible).

    The optimum's evaluation checks the program's feed (its FEDRAT) and has the cycle time
    (``cycle_time``, with acceleration limits) as ``/v1/evaluate`` does.

    ``path``: the request's path, for how a CAM program was read (``path_read``) and the pass
    and operation of a failure; ``axis_correction``: the request's
    (:func:`~service.convert.common.request_correction`).
    """
    report = optimum.solver
    start = optimum.start_evaluation
    return schemas.OptimizeResponse(
        found=optimum.found,
        placement=None if optimum.placement is None else api_placement(optimum.placement),
        mu_path=optimum.mu_path,
        mu_acc=optimum.mu_acc,
        evaluation=None
        if optimum.evaluation is None
        else evaluate_response(
            optimum.evaluation,
            robot,
            axis_correction=axis_correction,
            feed=None
            if path is None or path.feed is None
            else check_feed(optimum.evaluation, path.feed, robot.qdot_max),
            cycle_time=cycle_time,
            placement=optimum.placement,
            lines=None if path is None else path.lines,
        ),
        start=schemas.StartInfo(
            placement=api_placement(optimum.start),
            mu_path=optimum.start_mu_path,
            mu_acc=optimum.start_mu_acc,
            reason=None
            if start is None or start.reason is None
            else schemas.FailureReason(start.reason),
            failed_waypoint=None if start is None else start.failed_waypoint,
        ),
        improvement_percent=optimum.improvement_percent,
        spins=None if optimum.spins is None else optimum.spins.tolist(),
        joint_path=None if optimum.joint_path is None else optimum.joint_path.tolist(),
        solver=schemas.SolverInfo(
            name=report.name,
            status=report.status,
            iterations=report.iterations,
            seconds=report.seconds,
        ),
        path_read=None if path is None else path_read_of(path),
        robot_read=robot_read_of(robot),
        failure=failure_to_api(optimum.failure, path),
    )
