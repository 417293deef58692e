"""Errors as the API's details: a solver error's ``loc`` and type, pydantic's in the request's.

Shared by the routes' error answers (:mod:`service.errors`), the job worker (a failed job's
errors) and the command line, none of which it depends on.
"""

from __future__ import annotations

import re
from typing import Any

from service.schemas import ErrorDetail
from solver.core.exceptions import SolverError


def solver_error_type(error: SolverError) -> str:
    """``RepeatedWaypointError`` -> ``"repeated_waypoint"``."""
    name = type(error).__name__.removesuffix("Error")
    return re.sub(r"(?<!^)(?=[A-Z])", "_", name).lower()


def solver_error_location(error: SolverError) -> list[str | int]:
    """Where a solver error is, as a FastAPI ``loc``: ``["body", *field, waypoint?]``.

    ``"path.waypoints"`` with waypoint 3 gives ``["body", "path", "waypoints", 3]``.
    """
    parts: list[str | int] = [int(p) if p.isdigit() else p for p in error.field.split(".")]
    if error.waypoint is not None:
        parts.append(error.waypoint)
    return ["body", *parts]


def request_location(loc: tuple[str | int, ...] | list[str | int]) -> list[str | int]:
    """A pydantic ``loc`` as a path into the request: the union variants' tags left out.

    A ``oneOf`` variant is tagged ``"robot:model"``, ``"path:waypoints"``...; a union of types
    (a number or a list of numbers: ``grid.yaw``) by pydantic's names of them,
    ``"constrained-float"``, ``"list[constrained-float]"``, ``"float"``. The API's field names
    are snake_case words (tests/service/test_errors.py holds every one to it), so the tags are
    the parts with a colon, a bracket or a hyphen, and the bare type names.
    """
    return [part for part in loc if not (isinstance(part, str) and _is_tag(part))]


_TYPE_NAMES = frozenset({"float", "int", "str", "bool"})


def _is_tag(part: str) -> bool:
    """Whether a ``loc`` part names a union variant, not a field."""
    return any(c in part for c in ":[-(") or part in _TYPE_NAMES


def request_errors(errors: list[Any]) -> list[ErrorDetail]:
    """Pydantic's errors as details (``loc`` in the request), less what a union's variants add.

    A value of a union of types (a number or a list: ``grid.yaw``) failing is refused by every
    variant: ``[0, 5000]`` as 'not a valid number' at ``grid.yaw`` and as 'at most 1000' at
    ``grid.yaw.1``; ``5000`` as 'at most 1000' and as 'not a valid array'. A variant's detail
    goes where another detail says more: at a place inside its own, or at its place where it
    only names the type it wanted (a ``*_type`` error) and the other does not. Details saying
    the same of one place are given once.
    """
    found = [
        (ErrorDetail(loc=request_location(e["loc"]), msg=e["msg"], type=e["type"]), len(e["loc"]))
        for e in errors
    ]
    places = [tuple(detail.loc) for detail, _ in found]
    inside = {place[:cut] for place in places for cut in range(len(place))}  # proper prefixes
    said_more = {
        place
        for place, (detail, _) in zip(places, found, strict=True)
        if not detail.type.endswith("_type")
    }
    kept: dict[tuple[tuple[str | int, ...], str, str], ErrorDetail] = {}
    for place, (detail, depth) in zip(places, found, strict=True):
        tagged = len(place) < depth
        wanted_type = detail.type.endswith("_type")
        if tagged and (place in inside or (wanted_type and place in said_more)):
            continue
        kept.setdefault((place, detail.msg, detail.type), detail)
    return list(kept.values())
