"""The capability map (``POST /v1/map``, ``/v1/map/png`` and map jobs), its size checked first."""

from __future__ import annotations

from service import convert
from service.config import Settings
from service.render import render_png
from service.schemas import MapRequest, MapResponse
from solver.core.parallel import TaskRunner, ThreadRunner
from solver.core.progress import Progress
from solver.core.robots import Robot
from solver.path.capability_map import CapabilityMap, capability_map
from solver.path.problem import SpinMode


def checked_grid(body: MapRequest, settings: Settings) -> tuple[Robot, convert.MapGrid]:
    """The robot and the grid of a map request, its size checked against ``settings``.

    Raises:
        InvalidInputError: the path or the grid over a limit (the message names the setting).
    """
    convert.check_path_size(
        body.path, limit=settings.max_path_waypoints, setting="DTF_MAX_PATH_WAYPOINTS"
    )
    robot = convert.robot_from_schema(body.robot)
    # Free spin costs more on a redundant arm: its spin mode (the path's default unless given)
    # weighs the grid; the path is read for that on such an arm only.
    free_spin = (
        robot.dof > 6 and convert.spin_mode_of(body.spin_mode, convert.path_of(body.path)) == "free"
    )
    grid = convert.map_grid(
        body.grid,
        settings=settings,
        n_waypoints=body.path.n_waypoints(),
        robot=robot,
        with_cell=body.cell is not None,
        free_spin=free_spin,
    )
    return robot, grid


def computed_map(
    body: MapRequest,
    settings: Settings,
    *,
    png: bool,
    progress: Progress,
    runner: TaskRunner | None = None,
) -> tuple[CapabilityMap, Robot, SpinMode]:
    """The map a request asks for, its size checked first; the robot; the spin mode.

    The placements run on ``runner``, by default on DTF_THREADS threads.
    """
    robot, grid = checked_grid(body, settings)
    if png:
        convert.check_png_size(grid, settings=settings)
    path = convert.path_of(body.path)
    spin_mode = convert.spin_mode_of(body.spin_mode, path)
    cell = convert.cell_of(body.cell, settings)
    problem = convert.problem_of(
        robot, path.poses, path, ik=body.ik, spin_mode=spin_mode, cell=cell
    )
    result = capability_map(
        problem,
        xs=grid.xs,
        ys=grid.ys,
        z=body.grid.z,
        yaws=grid.yaws,
        spins=grid.spins,
        progress=progress,
        runner=ThreadRunner(settings.threads) if runner is None else runner,
    )
    return result, robot, spin_mode


def map_of(
    body: MapRequest, settings: Settings, progress: Progress, runner: TaskRunner | None = None
) -> MapResponse:
    """The JSON answer of ``POST /v1/map`` (a map job's result too, its tasks on ``runner``)."""
    result, robot, spin_mode = computed_map(
        body, settings, png=False, progress=progress, runner=runner
    )
    return convert.map_response(result, robot, spin_mode=spin_mode)


def map_png(result: CapabilityMap, robot: Robot) -> bytes:
    """The colour map of a computed map, as PNG bytes."""
    index = "mu_path" if result.mu_acc is None else "mu_acc"
    return render_png(result, title=f"{robot.name}: {index}")
