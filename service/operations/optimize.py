"""The best placement inside a box (``POST /v1/optimize`` and optimize jobs)."""

from __future__ import annotations

from service import convert
from service.config import Settings
from service.schemas import OptimizeRequest, OptimizeResponse
from solver.core.parallel import TaskRunner, ThreadRunner
from solver.core.progress import Progress
from solver.optimise.optimize import optimize_placement


def optimum_of(
    body: OptimizeRequest,
    settings: Settings,
    progress: Progress,
    runner: TaskRunner | None = None,
) -> OptimizeResponse:
    """The answer of ``POST /v1/optimize``, its size checked first."""
    convert.check_path_size(
        body.path, limit=settings.max_optimize_waypoints, setting="DTF_MAX_OPTIMIZE_WAYPOINTS"
    )
    robot = convert.robot_from_schema(body.robot)
    path = convert.path_of(body.path)
    bounds = convert.bounds_of(body.bounds, z=body.z)
    start = None if body.start is None else convert.placement_of(body.start)
    spin_mode = convert.spin_mode_of(body.spin_mode, path)
    cell = convert.cell_of(body.cell, settings)
    problem = convert.problem_of(
        robot, path.poses, path, ik=body.ik, spin_mode=spin_mode, cell=cell
    )
    optimum = optimize_placement(
        problem,
        bounds=bounds,
        start=start,
        method=body.method,
        max_spin_step=None if body.spin_path is None else body.spin_path.max_spin_step,
        max_coarse_cells=settings.max_map_cells,
        max_coarse_poses=settings.max_map_poses,
        max_search_poses=settings.max_search_poses,
        max_solver_seconds=settings.max_solver_seconds,
        progress=progress,
        runner=ThreadRunner(settings.threads) if runner is None else runner,
    )
    return convert.optimize_response(optimum, robot, axis_correction=path.axis_correction)
