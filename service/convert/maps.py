"""``POST /v1/map``: the grid from the request, its size checked; the answer from the map."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from service import schemas
from service.config import Settings
from service.convert.common import api_placement, branch_to_api, cell_model_to_api
from service.convert.robots import robot_read_of
from solver.core.codes import FEASIBLE, REASONS
from solver.core.exceptions import InvalidInputError
from solver.core.robots import Robot
from solver.core.spatial import MAX_COORDINATE
from solver.path.capability_map import CapabilityMap, axis_length, grid_axis
from solver.path.problem import SpinMode, require_family


@dataclass(frozen=True)
class MapGrid:
    """The grid values of a map request (m, m, rad)."""

    xs: np.ndarray
    ys: np.ndarray
    yaws: np.ndarray
    spins: np.ndarray


def map_grid(
    grid: schemas.Grid,
    *,
    settings: Settings,
    n_waypoints: int,
    robot: Robot,
    cost: float,
    with_cell: bool = False,
) -> MapGrid:
    """The grid's values, after checking its size against the settings.

    Each placement weighs ``cost`` closed-form poses (the problem's map figure,
    :func:`solver.path.capability_map.map_cost`: 1 a pose for a closed-form family, far more
    for numeric IK, a cell's check, the free spin), so that DTF_MAX_MAP_POSES bounds the time
    of every map.

    Raises:
        InvalidInputError: an axis is malformed, or the grid is over a size limit; the message
            says the size asked for and the limit.
    """
    nx = axis_length(grid.x.min, grid.x.max, grid.x.step, field="grid.x")
    ny = axis_length(grid.y.min, grid.y.max, grid.y.step, field="grid.y")
    for field, values in (
        ("grid.x", (grid.x.min, grid.x.max)),
        ("grid.y", (grid.y.min, grid.y.max)),
        ("grid.z", (grid.z,)),
    ):
        if max(abs(v) for v in values) > MAX_COORDINATE:
            raise InvalidInputError(
                field, f"{max(abs(v) for v in values):.6g} m is beyond +-{MAX_COORDINATE:g} m"
            )
    yaws, spins = grid.yaws(), grid.spins()
    cells = nx * ny * len(yaws) * len(spins)
    size = f"{nx} x * {ny} y * {len(yaws)} yaw * {len(spins)} spin = {cells} placements"
    limits = settings.map_limits()
    if cells > limits.cells:
        raise InvalidInputError(
            "grid", f"{size}; the limit is {limits.cells} ({limits.cells_setting}){limits.hint}"
        )
    poses = cells * n_waypoints
    family = require_family(robot)
    work = cells * cost
    if work > limits.poses:
        weighed = "" if work == poses else f", as work {work:.4g} closed-form poses"
        weighed += "" if work == poses else f" ({family.name} IK{' in a cell' * with_cell})"
        raise InvalidInputError(
            "grid",
            f"{size} * {n_waypoints} waypoints = {poses} poses{weighed}; the limit is "
            f"{limits.poses} ({limits.poses_setting}){limits.hint}",
        )
    return MapGrid(
        xs=grid_axis(grid.x.min, grid.x.max, grid.x.step, field="grid.x"),
        ys=grid_axis(grid.y.min, grid.y.max, grid.y.step, field="grid.y"),
        yaws=np.array(yaws, dtype=float),
        spins=np.array(spins, dtype=float),
    )


def png_panels_over(grid: MapGrid, *, settings: Settings) -> str | None:
    """What is over the limit in a PNG of more panels (yaw x spin values) than allowed.

    The size asked for and the limit, said for either picture route to end as it may (the
    map's answers a 422, a job's a 409); None within the limit.
    """
    panels = len(grid.yaws) * len(grid.spins)
    if panels <= settings.max_png_panels:
        return None
    return (
        f"{len(grid.yaws)} yaws * {len(grid.spins)} spins = {panels} PNG panels; the limit is "
        f"{settings.max_png_panels} (DTF_MAX_PNG_PANELS)"
    )


def check_png_size(grid: MapGrid, *, settings: Settings) -> None:
    """Refuse a PNG of more panels (yaw x spin values) than the setting allows.

    Raises:
        InvalidInputError: on ``grid``, saying the size asked for and the limit.
    """
    over = png_panels_over(grid, settings=settings)
    if over is not None:
        raise InvalidInputError("grid", f"{over}; ask for JSON for more")


def extreme(cmap: CapabilityMap, *, best: bool) -> schemas.MapExtreme | None:
    """The best (or worst) feasible cell as the answer gives it; None where none is."""
    index = cmap.extreme(best=best)
    if index is None:
        return None
    return schemas.MapExtreme(
        placement=api_placement(cmap.placement(index)),
        mu_path=float(cmap.mu_path[index]),
        mu_acc=None if cmap.mu_acc is None else float(cmap.mu_acc[index]),
    )


LIMITED_BY: tuple[Literal["speed", "acceleration"], ...] = ("speed", "acceleration")
"""What binds mu_acc, by the map's ``limited_by`` code (0 the speeds, 1 the accelerations)."""


def acceleration_columns(cmap: CapabilityMap) -> tuple[list[Any], list[Any]]:
    """Per cell (in C order) its mu_acc and what binds it: None without acceleration limits.

    Infeasible cells' values are never read.
    """
    if cmap.mu_acc is None or cmap.limited_by is None:
        return [None] * cmap.mu_path.size, [None] * cmap.mu_path.size
    bound = [LIMITED_BY[min(k, 1)] for k in cmap.limited_by.ravel().tolist()]
    return cmap.mu_acc.ravel().tolist(), bound


def map_response(
    cmap: CapabilityMap,
    robot: Robot,
    *,
    spin_mode: SpinMode,
    path_read: schemas.PathRead | None = None,
    axis_correction: float = 0.0,
) -> schemas.MapResponse:
    """The JSON answer of ``POST /v1/map``: cells yaw-major, then y, then x.

    ``path_read``: how the CAM program was read, None for poses and tool axes;
    ``axis_correction``: the largest correction made in normalising the request's unit vectors
    and quaternions.

    The columns are read as Python lists once (indexing numpy arrays cell by cell took longer
    than validating the cells; ``model_construct``, unvalidated, was slower still).
    """
    branches = [branch_to_api(b) for b in require_family(robot).branches]
    feasible = (cmap.reason == FEASIBLE).ravel().tolist()
    mu, reason = cmap.mu_path.ravel().tolist(), cmap.reason.ravel().tolist()
    failed, branch = cmap.failed_waypoint.ravel().tolist(), cmap.branch.ravel().tolist()
    at, joint = cmap.bottleneck_waypoint.ravel().tolist(), cmap.bottleneck_joint.ravel().tolist()
    mu_acc, limited_by = acceleration_columns(cmap)
    xs, ys, yaws, spins = (a.tolist() for a in (cmap.xs, cmap.ys, cmap.yaws, cmap.spins))
    cells = []
    for c, (s, k, j, i) in enumerate(np.ndindex(cmap.mu_path.shape)):
        ok = feasible[c]
        cells.append(
            schemas.MapCell(
                x=xs[i],
                y=ys[j],
                yaw=yaws[k],
                spin=spins[s],
                mu_path=mu[c] if ok else None,
                reason=None if ok else schemas.FailureReason(REASONS[reason[c]]),
                failed_waypoint=None if ok else failed[c],
                bottleneck_waypoint=at[c] if ok else None,
                bottleneck_joint=joint[c] if ok else None,
                branch=branches[branch[c]] if ok else None,
                mu_acc=mu_acc[c] if ok else None,
                limited_by=limited_by[c] if ok else None,
            )
        )
    return schemas.MapResponse(
        cells=cells,
        **answer_fields(
            cmap,
            robot,
            spin_mode=spin_mode,
            path_read=path_read,
            axis_correction=axis_correction,
        ),
    )


def answer_fields(
    cmap: CapabilityMap,
    robot: Robot,
    *,
    spin_mode: SpinMode,
    path_read: schemas.PathRead | None,
    axis_correction: float = 0.0,
) -> dict[str, Any]:
    """The map answer's fields but its cells, as both writers give them.

    :func:`map_response` and :func:`service.convert.map_json.map_json` take them from here, so a
    field added reaches both.
    """
    return {
        "best": extreme(cmap, best=True),
        "worst": extreme(cmap, best=False),
        "feasible_cells": int(np.sum(cmap.reason == FEASIBLE)),
        "spin_mode": spin_mode,
        "recognised": require_family(robot).recognised,
        "path_read": path_read,
        "robot_read": robot_read_of(robot),
        "axis_correction": axis_correction,
        **cell_model_to_api(cmap.cell_approximated, cmap.cell_unchecked),
    }
