"""The capability map (``POST /v1/map``, ``/v1/map/png`` and map jobs), its size checked first."""

from __future__ import annotations

from typing import Any, NamedTuple

from service import convert
from service.config import Settings
from service.convert.map_json import map_json, rest_json
from service.operations.threads import thread_runner
from service.schemas import MapRequest, MapResponse, PathRead
from solver.core.parallel import TaskRunner
from solver.core.progress import Progress
from solver.core.robots import Robot
from solver.path.capability_map import CapabilityMap, capability_map, map_cost
from solver.path.problem import PathProblem, SpinMode


class ComputedMap(NamedTuple):
    """A map computed, with what its answer says besides the cells.

    Attributes:
        result: the map.
        robot: the robot it is of.
        spin_mode: the spin mode it was computed in.
        path_read: how the CAM program was read (None for poses and tool axes).
        axis_correction: the largest correction made in normalising the request's tool axes
            and quaternions (the path's, the tcp's, the cell's objects'), as an evaluation
            answers it.
    """

    result: CapabilityMap
    robot: Robot
    spin_mode: SpinMode
    path_read: PathRead | None
    axis_correction: float

    def answer(self) -> MapResponse:
        """The route's answer as its model (:func:`service.convert.map_response`)."""
        return convert.map_response(self.result, self.robot, **self._said())

    def answer_json(self) -> bytes:
        """The route's answer as the route writes it (:func:`service.convert.map_json.map_json`)."""
        return map_json(self.result, self.robot, **self._said())

    def rest_json(self) -> str:
        """The answer without its cells (:func:`service.convert.map_json.rest_json`)."""
        return rest_json(self.result, self.robot, **self._said())

    def _said(self) -> dict[str, Any]:
        """What the answer says besides the cells, as the writers take it."""
        return {
            "spin_mode": self.spin_mode,
            "path_read": self.path_read,
            "axis_correction": self.axis_correction,
        }


class CheckedGrid(NamedTuple):
    """A map request checked: its robot, grid, problem, reading and normalisation.

    ``axis_correction``: the largest correction made in normalising the request's unit vectors
    and quaternions.
    """

    robot: Robot
    grid: convert.MapGrid
    problem: PathProblem
    path_read: PathRead | None
    axis_correction: float


def checked_grid(body: MapRequest, settings: Settings) -> CheckedGrid:
    """The robot, the grid and the problem of a map request, its size checked against ``settings``.

    The grid's work is the problem's (:func:`solver.path.capability_map.map_cost`: the family's
    map figure, whether the map may drop branches, a cell's check).

    Raises:
        InvalidInputError: the path or the grid over a limit (the message names the setting).
    """
    convert.check_path_size(
        body.path, limit=settings.max_path_waypoints, setting="DTF_MAX_PATH_WAYPOINTS"
    )
    robot = convert.robot_from_schema(body.robot)
    path = convert.path_of(body.path)
    spin_mode = convert.spin_mode_of(body.spin_mode, path)
    cell = convert.cell_of(body.cell, settings, robot)
    problem = convert.problem_of(
        robot, path.poses, path, ik=body.ik, spin_mode=spin_mode, cell=cell
    )
    grid = convert.map_grid(
        body.grid,
        settings=settings,
        n_waypoints=body.path.n_waypoints(),
        robot=robot,
        cost=map_cost(problem),
        with_cell=body.cell is not None,
    )
    correction = convert.request_correction(path, body.robot, body.cell)
    return CheckedGrid(robot, grid, problem, convert.path_read_of(path), correction)


def computed_map(
    body: MapRequest,
    settings: Settings,
    *,
    png: bool,
    progress: Progress,
    runner: TaskRunner | None = None,
    checked: CheckedGrid | None = None,
) -> ComputedMap:
    """The map a request asks for, its size checked first; the robot; the spin mode; the reading.

    The placements run on ``runner``, by default on DTF_THREADS threads. ``checked``: the
    request's :func:`checked_grid` where the caller made it already (its problem's prepared
    path is then not made again).
    """
    robot, grid, problem, path_read, correction = (
        checked_grid(body, settings) if checked is None else checked
    )
    if png:
        convert.check_png_size(grid, settings=settings)
    result = capability_map(
        problem,
        xs=grid.xs,
        ys=grid.ys,
        z=body.grid.z,
        yaws=grid.yaws,
        spins=grid.spins,
        progress=progress,
        runner=thread_runner(settings.threads) if runner is None else runner,
    )
    return ComputedMap(result, robot, problem.options.spin_mode, path_read, correction)


def map_png(result: CapabilityMap, robot: Robot) -> bytes:
    """The colour map of a computed map, as PNG bytes."""
    from service.render import render_png  # matplotlib only where a picture is drawn

    index = "mu_path" if result.mu_acc is None else "mu_acc"
    return render_png(result, title=f"{robot.shown_name}: {index}")
