"""A CSV path read into a CamPath (cam.md section 5): one waypoint a line, one pass.

Each line is ``x, y, z, i, j, k`` (the tool tip and the tool axis, tip towards holder) or
``x, y, z, qx, qy, qz, qw`` (the tool pose, quaternion scalar last), every line alike; lengths
are in the ``units`` the caller gives (``mm``, ``inch`` or ``m``). The first line may be a
header; it must then name the columns, ``x,y,z,i,j,k`` or ``x,y,z,qx,qy,qz,qw`` (any case,
blanks allowed), so that a file written in another order (``qw`` first) is refused rather than
misread. Blank lines are skipped. Axes and quaternions within 1e-3 of unit are normalised
(cam.md section 6).
"""

from __future__ import annotations

import math

from solver.cam.cam_path import METRES_PER_UNIT, CamPath, Units, assemble_cam_path
from solver.cam.reading import (
    BOM,
    checked_position,
    is_number,
    near_unit_vector,
    parse_numbers,
    text_lines,
)
from solver.core.exceptions import InvalidInputError, InvalidLineError
from solver.core.spatial import rotation_from_quaternion

_UNITS: dict[str, Units] = {"mm": "mm", "inch": "inches", "inches": "inches", "m": "m"}
HEADERS = {
    6: ("x", "y", "z", "i", "j", "k"),
    7: ("x", "y", "z", "qx", "qy", "qz", "qw"),
}


def read_csv_path(text: str, *, units: str, field: str = "path.csv") -> CamPath:
    """The waypoints of a CSV path, as one pass without a feed.

    Args:
        text: the file.
        units: ``mm``, ``inch`` or ``m``, the unit of x, y, z.
        field: the input's name, for the errors.

    Returns:
        The path in metres: tool axes for 6 columns, rotations for 7.

    Raises:
        InvalidInputError: units other than mm, inch or m; fewer than 2 waypoints.
        InvalidLineError: a header that does not name the columns, a line with another count
            of numbers, a number that is malformed or not finite, an axis or quaternion off unit
            by more than 1e-3, a position beyond 1 km, or a waypoint repeating the one before
            it; each names its line.
    """
    if units not in _UNITS:
        raise InvalidInputError(
            "units", f"units {units!r}: a CSV path is in mm or m (metric) or inch"
        )
    scale = METRES_PER_UNIT[_UNITS[units]]
    rows = _rows(text)
    columns = None
    if _has_header(rows):
        line, header = rows.pop(0)
        columns = _header_columns(header, line=line, field=field)
    positions, directions, lines = [], [], []
    correction = 0.0
    for line, row in rows:
        cells = row.split(",")
        if columns is None:
            columns = len(cells)
        if len(cells) != columns or columns not in HEADERS:
            raise InvalidLineError(
                field,
                f"{len(cells)} values; every line needs {_forms(columns)}",
                line=line,
                text=row,
            )
        values = parse_numbers(cells, field=field, line=line, text=row)
        positions.append(checked_position(values[:3] * scale, field=field, line=line, text=row))
        name = "tool axis" if columns == 6 else "quaternion"
        unit, fix = near_unit_vector(values[3:], name=name, field=field, line=line, text=row)
        correction = max(correction, fix)
        directions.append(unit if columns == 6 else rotation_from_quaternion(unit, field=field))
        lines.append(line)
    if len(positions) == 1:
        raise InvalidLineError(
            field, "a path needs at least 2 waypoints; this is the only one", line=lines[0]
        )
    return assemble_cam_path(
        positions=positions,
        directions=directions,
        pass_ids=[0] * len(positions),
        lines=lines,
        arrival_feeds=[math.nan] * len(positions),
        units=_UNITS[units],
        axis_correction=correction,
        field=field,
    )


def csv_waypoints(text: str) -> int:
    """How many waypoints :func:`read_csv_path` reads from ``text``: its rows after any header.

    The waypoint limit counts this (cam.md section 9: one counting rule).
    """
    rows = _rows(text)
    return len(rows) - int(_has_header(rows))


def _rows(text: str) -> list[tuple[int, str]]:
    """The non-blank lines, stripped, with their numbers (from 1), the BOM dropped.

    Excel's "CSV UTF-8" starts with the mark: a headerless file's first row, counted as a
    header with it, let 20,001 waypoints past a limit of 20,000.
    """
    text = text.removeprefix(BOM)
    return [(n, raw.strip()) for n, raw in enumerate(text_lines(text), start=1) if raw.strip()]


def _has_header(rows: list[tuple[int, str]]) -> bool:
    """Whether the first row is a header: not all numbers."""
    return bool(rows) and not all(is_number(cell) for cell in rows[0][1].split(","))


def _forms(columns: int | None) -> str:
    """The line forms allowed, given the column count fixed so far."""
    if columns in HEADERS:
        return ", ".join(HEADERS[columns])
    return " or ".join(", ".join(names) for names in HEADERS.values())


def _header_columns(header: str, *, line: int, field: str) -> int:
    """The column count a header names; InvalidLineError unless it is one of HEADERS."""
    names = tuple(cell.strip().lower() for cell in header.split(","))
    for count, expected in HEADERS.items():
        if names == expected:
            return count
    raise InvalidLineError(
        field,
        f"the header must name the columns as {_forms(None)} (in this order)",
        line=line,
        text=header,
    )
