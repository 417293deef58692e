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
from typing import Any

from pydantic_core import to_json

from service import schemas
from service.convert.common import branch_to_api
from service.convert.maps import acceleration_columns, answer_fields
from solver.core.codes import FEASIBLE, REASONS
from solver.core.family import Branch
from solver.core.robots import Robot
from solver.path.capability_map import CapabilityMap
from solver.path.problem import SpinMode, require_family

_NO_CELLS = b'{"cells":[]'
_REASON_TEXTS = [to_json(r).decode() for r in REASONS]
"""Each reason as the model writes it."""


def map_json(
    cmap: CapabilityMap,
    robot: Robot,
    *,
    spin_mode: SpinMode,
    path_read: schemas.PathRead | None = None,
) -> bytes:
    """``map_response(cmap, robot, spin_mode=..., path_read=...).model_dump_json()``, as bytes."""
    family = require_family(robot)
    rest = schemas.MapResponse(
        cells=[], **answer_fields(cmap, robot, spin_mode=spin_mode, path_read=path_read)
    ).model_dump_json()
    branches = [_branch_text(b) for b in family.branches]
    feasible = (cmap.reason == FEASIBLE).ravel().tolist()
    reason, branch = cmap.reason.ravel().tolist(), cmap.branch.ravel().tolist()
    mu, failed, at, joint = (
        _texts(a.ravel().tolist())
        for a in (
            cmap.mu_path,
            cmap.failed_waypoint,
            cmap.bottleneck_waypoint,
            cmap.bottleneck_joint,
        )
    )
    mu_acc, limited_by = (_texts(column) for column in acceleration_columns(cmap))
    xs, ys, yaws, spins = (_texts(a.tolist()) for a in (cmap.xs, cmap.ys, cmap.yaws, cmap.spins))
    places = [  # C order of the map's (spin, yaw, y, x) axes, x fastest
        f'{{"x":{x},"y":{y},"yaw":{yaw},"spin":{spin},"mu_path":'
        for spin in spins
        for yaw in yaws
        for y in ys
        for x in xs
    ]
    columns = (places, feasible, mu, reason, failed, at, joint, branch, mu_acc, limited_by)
    cells = [
        f'{place}{m},"reason":null,"failed_waypoint":null,"bottleneck_waypoint":{a},'
        f'"bottleneck_joint":{jt},"branch":{branches[b]},"mu_acc":{ma},"limited_by":{lb}}}'
        if ok
        else f'{place}null,"reason":{_REASON_TEXTS[r]},"failed_waypoint":{f},'
        '"bottleneck_waypoint":null,"bottleneck_joint":null,"branch":null,"mu_acc":null,'
        '"limited_by":null}'
        for place, ok, m, r, f, a, jt, b, ma, lb in zip(*columns, strict=True)
    ]
    if not rest.startswith(_NO_CELLS.decode()):  # not reached: cells is the model's first field
        raise RuntimeError(f"MapResponse JSON starts {rest[:20]!r}")
    return ('{"cells":[' + ",".join(cells) + "]" + rest[len(_NO_CELLS) :]).encode()


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
