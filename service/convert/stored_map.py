"""A map job's stored cells back into the map's columns, to draw it (``GET /v1/jobs/{id}/png``).

A map job stores its cells as the map route writes them (:mod:`service.convert.map_json`), in
the answer's order: x fastest, then y, yaw and spin. The picture needs the map's columns
(:class:`solver.path.capability_map.CapabilityMap`: the feed index and the reason of each cell);
they are read back here from the cells, a page at a time, and the axes from the job's own
request, as its map took them. A float written by the route reads back as the same float, so
the picture is the one ``POST /v1/map/png`` draws of the same request.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from typing import Any

import numpy as np

from service.convert.maps import MapGrid
from service.schemas import MapRequest
from solver.core.codes import FEASIBLE, REASONS
from solver.core.robots import Robot
from solver.path.capability_map import CapabilityMap, grid_axis

_REASON_INDEX = {reason: k for k, reason in enumerate(REASONS)}


def reported(
    pages: Iterable[list[dict[str, Any]]], progress: Callable[[float], None], *, total: int
) -> Iterator[list[dict[str, Any]]]:
    """``pages``, ``progress`` told the fraction of ``total`` cells read after each.

    ``progress`` may raise (the client left: :class:`solver.core.progress.Cancelled`): the
    pages are then no longer read (their generator closed, its store connection with it).
    """
    read = 0
    for page in pages:
        yield page
        read += len(page)
        progress(min(read / total, 1.0))


class StoredCellsMismatch(ValueError):
    """The stored cells are not the request's grid (their count, or a cell's reason)."""


def stored_grid(body: MapRequest) -> MapGrid:
    """The grid's values, as the job's map took them (its size was checked when it was run)."""
    grid = body.grid
    return MapGrid(
        xs=grid_axis(grid.x.min, grid.x.max, grid.x.step, field="grid.x"),
        ys=grid_axis(grid.y.min, grid.y.max, grid.y.step, field="grid.y"),
        yaws=np.array(grid.yaws(), dtype=float),
        spins=np.array(grid.spins(), dtype=float),
    )


def stored_map(
    body: MapRequest, robot: Robot, pages: Iterable[list[dict[str, Any]]]
) -> CapabilityMap:
    """The map whose cells a job stored, from its request and its cells' ``pages``.

    Only what the picture reads is filled: the axes, ``mu_path``, ``reason`` and, where the
    robot has acceleration limits, ``mu_acc`` (the map's colour then); the waypoints, joints
    and branches are -1.

    Raises:
        StoredCellsMismatch: the cells are more or fewer than the grid's, or one names a reason
            the service does not have.
    """
    grid = stored_grid(body)
    shape = (len(grid.spins), len(grid.yaws), len(grid.ys), len(grid.xs))
    total = int(np.prod(shape))
    mu_path = np.full(total, np.nan)
    # mu_acc only where the map has it (the robot's acceleration limits): the map's colour then
    mu_acc = None if robot.qddot_max is None else np.full(total, np.nan)
    reason = np.full(total, FEASIBLE, dtype=np.int64)
    filled = 0
    for page in pages:
        end = filled + len(page)
        if end > total:
            raise StoredCellsMismatch(f"more cells stored than the grid's {total}")
        try:
            mu_path[filled:end] = [np.nan if c["mu_path"] is None else c["mu_path"] for c in page]
            if mu_acc is not None:
                accs = [c.get("mu_acc") for c in page]
                mu_acc[filled:end] = [np.nan if a is None else a for a in accs]
            codes = [c["reason"] for c in page]
        except (KeyError, TypeError, ValueError) as error:  # a cell the service never writes
            what = f"no {error.args[0]!r}" if isinstance(error, KeyError) else str(error)[:80]
            raise StoredCellsMismatch(f"a stored cell near cell {filled}: {what}") from None
        unknown = [
            c for c in codes if c is not None and not (isinstance(c, str) and c in _REASON_INDEX)
        ]
        if unknown:
            raise StoredCellsMismatch(f"a cell's reason {str(unknown[0])[:40]!r} is unknown")
        reason[filled:end] = [FEASIBLE if code is None else _REASON_INDEX[code] for code in codes]
        filled = end
    if filled != total:
        raise StoredCellsMismatch(f"{filled} cells stored, the grid has {total}")
    none = np.full(shape, -1, dtype=np.int64)
    return CapabilityMap(
        xs=grid.xs,
        ys=grid.ys,
        yaws=grid.yaws,
        z=float(body.grid.z),
        spins=grid.spins,
        mu_path=mu_path.reshape(shape),
        reason=reason.reshape(shape),
        failed_waypoint=none,
        branch=none,
        bottleneck_waypoint=none,
        bottleneck_joint=none,
        mu_acc=None if mu_acc is None else mu_acc.reshape(shape),
    )
