"""The best placement inside a box (``POST /v1/optimize`` and optimize jobs)."""

from __future__ import annotations

from service import convert
from service.config import Settings
from service.operations.threads import thread_runner
from service.schemas import OptimizeRequest, OptimizeResponse
from solver.core.exceptions import InvalidInputError
from solver.core.parallel import TaskRunner
from solver.core.progress import Progress
from solver.optimise.methods import method_named
from solver.optimise.optimize import optimize_placement
from solver.optimise.search_space import PlacementBounds
from solver.optimise.work import (
    COARSE_MAP,
    OptimisationWork,
    map_is_worth_it,
    scipy_works,
    work_of,
)
from solver.path.cycle_time import cycle_time
from solver.path.problem import PathProblem


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
    cell = convert.cell_of(body.cell, settings, robot)
    problem = convert.problem_of(
        robot, path.poses, path, ik=body.ik, spin_mode=spin_mode, cell=cell
    )
    check_work(problem, bounds, body, settings)
    optimum = optimize_placement(
        problem,
        bounds=bounds,
        start=start,
        method=body.method,
        max_spin_step=max_spin_step_of(body),
        max_coarse_cells=settings.max_map_cells,
        max_coarse_poses=settings.max_map_poses,
        max_search_poses=settings.max_search_poses,
        max_solver_seconds=settings.max_solver_seconds,
        progress=progress,
        runner=thread_runner(settings.threads) if runner is None else runner,
    )
    return convert.optimize_response(
        optimum,
        robot,
        axis_correction=convert.request_correction(path, body.robot, body.cell),
        path=path,
        cycle_time=None if optimum.evaluation is None else cycle_time(problem, optimum.evaluation),
    )


def max_spin_step_of(body: OptimizeRequest) -> float | None:
    """The spin path's largest step (rad), or None without a spin path."""
    return None if body.spin_path is None else body.spin_path.max_spin_step


def check_work(
    problem: PathProblem, bounds: PlacementBounds, body: OptimizeRequest, settings: Settings
) -> None:
    """Refuse a search whose whole work is over its limit, before any of it.

    Every phase's placements at most (:func:`solver.optimise.work.work_of`: the start, the
    coarse map or differential evolution, the refinement, the Nelder-Mead climbs, the local
    solves' whole-path checks, the candidates), each weighed by the problem's ``path_cost``:
    against DTF_MAX_MAP_POSES for casadi, DTF_MAX_SEARCH_POSES for scipy (DTF_MAX_JOB_POSES
    for either in a job); a coarse map of more cells than DTF_MAX_MAP_CELLS (DTF_MAX_JOB_CELLS)
    first. The scipy search that also starts from the coarse map
    (:func:`solver.optimise.work.seeds_from_map`, a rule of the method, not of the limits) is
    weighed as it was without the map against DTF_MAX_SEARCH_POSES, and the work the map adds
    against DTF_MAX_MAP_POSES, as the casadi method's map is.

    Raises:
        InvalidInputError: on ``bounds``, saying the phases, the work and the limit.
    """
    bounds.check()
    limits = settings.map_limits()
    max_spin_step = max_spin_step_of(body)
    alone: OptimisationWork | None = None  # the scipy search without the coarse map
    if method_named(body.method).map_seeds:
        # the scipy method also starts from the coarse map (as it will: the limits do not decide)
        alone, with_map = scipy_works(problem, bounds, max_spin_step=max_spin_step)
        seeded = map_is_worth_it(problem, alone, with_map)
        work = with_map if seeded else alone
    else:
        seeded = False
        work = work_of(problem, bounds, method=body.method, max_spin_step=max_spin_step)
    weighed = work.weighed(problem)
    jobs = limits.hint.replace("maps", "searches")  # a route's: POST /v1/jobs; a job's: none
    if body.method == "scipy":
        limit, setting = limits.search_poses, limits.search_setting
        hint = "; fix a variable, shorten the path, or try method casadi" + jobs
    else:
        limit, setting, hint = limits.poses, limits.poses_setting, "; narrow the bounds" + jobs
    if body.method == "casadi" or seeded:
        cells = work.placements(COARSE_MAP, search="")  # a narrower search's map is smaller
        if cells > limits.cells:
            raise InvalidInputError(
                "bounds",
                f"the search box needs a coarse map of {cells} cells (20 mm, 15 deg); the "
                f"limit is {limits.cells} ({limits.cells_setting}){hint}",
            )
    if seeded and alone is not None:  # the map's work against the maps' limit, the rest
        without = alone.weighed(problem)  # against the search's
        if weighed - without > limits.poses:
            raise InvalidInputError(
                "bounds",
                f"the scipy search starts from the coarse map too, which adds "
                f"{weighed - without:.4g} closed-form poses of work; the limit is {limits.poses} "
                f"({limits.poses_setting}){hint}",
            )
        weighed = without
    if weighed > limit:
        cell = ", with a cell" if problem.options.cell is not None else ""
        raise InvalidInputError(
            "bounds",
            f"the {body.method} search evaluates placements of {problem.prepared.n_waypoints} "
            f"waypoints: {work.describe()}, as work {weighed:.4g} closed-form poses "
            f"({problem.family.name} IK{cell}); the limit is {limit} ({setting}){hint}",
        )
