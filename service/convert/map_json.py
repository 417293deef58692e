"""The JSON body of ``POST /v1/map``, written from the map's columns (issue 23).

:func:`service.convert.maps.map_response` builds a :class:`service.schemas.MapResponse` of one
validated ``MapCell`` a placement, which took longer than its JSON (on the ERK-size map: cells
1.2-2 ms, JSON 0.55 ms). The route writes the same bytes from the columns instead: each column
of numbers written once by pydantic-core's own ``to_json`` (the serialiser ``model_dump_json``
runs, so every number is written alike) and split into its values, each cell formatted from
them with the model's keys in its order, and the rest of the answer (best, worst, counts) by
the model itself. A test holds the two bodies byte for byte
equal (tests/service/test_map_json.py).
"""

from __future__ import annotations

import functools
from collections.abc import Iterator
from typing import Any

from pydantic_core import to_json

from service import schemas
from service.convert.common import branch_to_api
from service.convert.maps import LIMITED_BY, answer_fields
from solver.core.codes import FEASIBLE, REASONS
from solver.core.family import Branch
from solver.core.robots import Robot
from solver.path.capability_map import CapabilityMap
from solver.path.problem import SpinMode, require_family

_NO_CELLS = b'{"cells":[]'
_REASON_TEXTS = [to_json(r).decode() for r in REASONS]
"""Each reason as the model writes it."""
_LIMITED_TEXTS = [to_json(b).decode() for b in LIMITED_BY]
"""What binds mu_acc (speed, acceleration) as the model writes it."""


def map_json(
    cmap: CapabilityMap,
    robot: Robot,
    *,
    spin_mode: SpinMode,
    path_read: schemas.PathRead | None = None,
    axis_correction: float = 0.0,
) -> bytes:
    """``map_response(cmap, robot, ...).model_dump_json()`` (the same keywords), as bytes."""
    rest = rest_json(
        cmap, robot, spin_mode=spin_mode, path_read=path_read, axis_correction=axis_correction
    )
    cells = ",".join(cell_pages(cmap, robot, page=max(1, cmap.mu_path.size)))
    return ('{"cells":[' + cells + "]" + rest[len(_NO_CELLS) :]).encode()


def rest_json(
    cmap: CapabilityMap,
    robot: Robot,
    *,
    spin_mode: SpinMode,
    path_read: schemas.PathRead | None = None,
    axis_correction: float = 0.0,
) -> str:
    """The map answer's JSON without cells (``{"cells":[],"best":...``), as the model writes it."""
    fields = answer_fields(
        cmap, robot, spin_mode=spin_mode, path_read=path_read, axis_correction=axis_correction
    )
    rest = schemas.MapResponse(cells=[], **fields).model_dump_json()
    if not rest.startswith(_NO_CELLS.decode()):  # not reached: cells is the model's first field
        raise RuntimeError(f"MapResponse JSON starts {rest[:20]!r}")
    return rest


def cell_pages(cmap: CapabilityMap, robot: Robot, *, page: int) -> Iterator[str]:
    """The map's cells as the model writes them, ``page`` at a time, in the answer's order.

    Each page is its cells' JSON objects joined by commas (the text between a JSON array's
    brackets). Made a page at a time from the columns' slices, so a map job of 2 million cells
    holds one page of text, not a model (or a dict) a cell.
    """
    branches = [_branch_text(b) for b in require_family(robot).branches]
    xs, ys, yaws, spins = (_texts(a.tolist()) for a in (cmap.xs, cmap.ys, cmap.yaws, cmap.spins))
    columns = [
        a.ravel()
        for a in (
            cmap.reason,
            cmap.branch,
            cmap.mu_path,
            cmap.failed_waypoint,
            cmap.bottleneck_waypoint,
            cmap.bottleneck_joint,
        )
    ]
    accelerations = cmap.mu_acc is not None and cmap.limited_by is not None
    if accelerations:
        columns += [cmap.mu_acc.ravel(), cmap.limited_by.ravel()]  # type: ignore[union-attr]
    n_x, n_y, n_yaw = len(xs), len(ys), len(yaws)
    heads = [f'{{"x":{x},"y":' for x in xs]  # C order of the (spin, yaw, y, x) axes, x fastest
    for start in range(0, cmap.mu_path.size, page):
        stop = min(start + page, cmap.mu_path.size)
        reason, branch, mu, failed, at, joint, *acc = (c[start:stop] for c in columns)
        feasible = (reason == FEASIBLE).tolist()
        reason_list, branch_list = reason.tolist(), branch.tolist()
        mu_t, failed_t, at_t, joint_t = (_texts(a.tolist()) for a in (mu, failed, at, joint))
        if acc:
            mu_acc = _texts(acc[0].tolist())
            limited_by = [_LIMITED_TEXTS[min(k, 1)] for k in acc[1].tolist()]
        else:
            mu_acc = limited_by = ["null"] * (stop - start)
        first_row = start // n_x  # the rows of x the page's cells are in, whole, then cut
        places = [
            head + tail
            for tail in (
                f'{ys[row % n_y]},"yaw":{yaws[row // n_y % n_yaw]},"spin":'
                f'{spins[row // (n_y * n_yaw)]},"mu_path":'
                for row in range(first_row, (stop - 1) // n_x + 1)
            )
            for head in heads
        ][start - first_row * n_x : stop - first_row * n_x]
        cells = (places, feasible, mu_t, reason_list, failed_t, at_t, joint_t, branch_list)
        yield ",".join(
            f'{place}{m},"reason":null,"failed_waypoint":null,"bottleneck_waypoint":{a},'
            f'"bottleneck_joint":{jt},"branch":{branches[b]},"mu_acc":{ma},"limited_by":{lb}}}'
            if ok
            else f'{place}null,"reason":{_REASON_TEXTS[r]},"failed_waypoint":{f},'
            '"bottleneck_waypoint":null,"bottleneck_joint":null,"branch":null,"mu_acc":null,'
            '"limited_by":null}'
            for place, ok, m, r, f, a, jt, b, ma, lb in zip(*cells, mu_acc, limited_by, strict=True)
        )


def _texts(column: list[Any]) -> list[str]:
    """Each value of a column of numbers, strings or None as pydantic-core writes it.

    One ``to_json`` call for the column, split at its commas (no value written holds one).
    """
    return to_json(column).decode()[1:-1].split(",") if column else []


@functools.lru_cache(maxsize=256)
def _branch_text(branch: Branch) -> str:
    """A branch as the model writes it, made once a branch (eight models a request otherwise)."""
    return to_json(_dumped(branch_to_api(branch))).decode()


def _dumped(branch: schemas.Branch | schemas.NumericBranch | None) -> dict[str, Any] | None:
    """A branch as the model writes it (its JSON-mode dump), None for none."""
    return None if branch is None else branch.model_dump(mode="json")
