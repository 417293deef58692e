"""STL files, ASCII or binary, read into triangles (cell.md section 1), bounded in size.

Only the facets' corners are read (normals are recomputed by whoever needs them). A file that
is neither a well-formed ASCII STL (its ``endsolid`` after its last facet) nor a binary STL
whose length matches its triangle count is an error naming the field, never a guess: either
check tells a file cut short from a whole one.
"""

from __future__ import annotations

import re

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.spatial import MAX_COORDINATE

UNITS = {"m": 1.0, "mm": 0.001, "cm": 0.01, "in": 0.0254}
_HEADER = 80
_RECORD = 50  # bytes per binary triangle: normal, three corners (float32), attribute
# ASCII STL's keywords in any case: exporters write SOLID, FACET NORMAL, VERTEX too
_VERTEX = re.compile(rb"vertex[ \t]+([^\r\n]*)", re.I)
_FACET = re.compile(rb"facet\s+normal", re.I)
_END = re.compile(rb"endsolid", re.I)


def read_stl(
    data: bytes,
    *,
    max_triangles: int,
    units: str = "m",
    field: str = "stl",
    setting: str = "max_mesh_triangles",
) -> np.ndarray:
    """The triangles of an STL file, in m.

    Args:
        data: the file's bytes (ASCII text or binary).
        max_triangles: the most triangles taken (a setting); more is an error.
        units: ``m``, ``mm``, ``cm`` or ``in``, the file's length unit.
        field: the request's field, named in errors.
        setting: the name of the triangle limit, named in its error.

    Returns:
        shape (T, 3, 3), m, the corners of each triangle.

    Raises:
        InvalidInputError: not an STL, no triangles, too many, or a corner not finite or beyond
            +-MAX_COORDINATE m.
    """
    if units not in UNITS:
        raise InvalidInputError(f"{field}.units", f"unknown unit {units!r}; use {', '.join(UNITS)}")
    if data.lstrip()[:5].lower() == b"solid" and not _fits_binary(data) and _FACET.search(data):
        triangles = _ascii(data, (max_triangles, setting), field)
    else:
        triangles = _binary(data, (max_triangles, setting), field)
    if not len(triangles):
        raise InvalidInputError(field, "the STL has no triangles")
    if not np.all(np.isfinite(triangles)):
        raise InvalidInputError(field, "the STL has a corner that is not a finite number")
    scaled: np.ndarray = triangles * UNITS[units]
    if np.abs(scaled).max() > MAX_COORDINATE:  # as a waypoint's position (and no hull of it)
        raise InvalidInputError(
            field, f"the STL has a corner beyond +-{MAX_COORDINATE:g} m (units: {units})"
        )
    return scaled


def _ascii(data: bytes, limit: tuple[int, str], field: str) -> np.ndarray:
    """Triangles of an ASCII STL: every three ``vertex`` lines."""
    count = len(_FACET.findall(data))
    if count > limit[0]:
        raise _too_many(count, limit, field)
    vertices = list(_VERTEX.finditer(data))
    rows = [vertex.group(1).split() for vertex in vertices]
    try:
        if any(len(row) != 3 for row in rows):
            raise ValueError(next(b" ".join(row) for row in rows if len(row) != 3).decode())
        corners = np.array([[float(v) for v in row] for row in rows], dtype=float)
    except (ValueError, UnicodeDecodeError) as exc:
        message = f"not an STL: a vertex is not three numbers ({str(exc)[:60]})"
        raise InvalidInputError(field, message) from exc
    if len(corners) != 3 * count:
        raise InvalidInputError(
            field, f"not an STL: {count} facets but {len(corners)} vertices (three a facet)"
        )
    # A file cut after a whole facet (a transfer, a full disk) read as the part of the solid
    # it held: a fixture with half its triangles checked as the whole, placements that hit it
    # answered free of it. Every ASCII STL ends with endsolid, so one without is refused.
    last = vertices[-1].end() if vertices else 0
    if _END.search(data, last) is None:
        line = data.count(b"\n", 0, last) + 1
        raise InvalidInputError(
            field,
            f"not a whole STL: no endsolid after its last vertex (line {line}): the file may "
            "be cut short, and a solid is not checked from part of its triangles",
        )
    return corners.reshape(-1, 3, 3)


def _fits_binary(data: bytes) -> bool:
    """Whether the bytes are as long as a binary STL of the count they hold.

    A binary STL may start with ``solid`` in its header; an ASCII one is told apart by its
    facets, anywhere in it (a 5,000-character ``solid`` line put them past the 4 kB looked at
    before: a valid ASCII STL refused as a binary one; the contract audit, stop 54).
    """
    if len(data) < _HEADER + 4:
        return False
    count = int(np.frombuffer(data, dtype="<u4", count=1, offset=_HEADER)[0])
    return len(data) == _HEADER + 4 + _RECORD * count


def _binary(data: bytes, limit: tuple[int, str], field: str) -> np.ndarray:
    """Triangles of a binary STL: an 80-byte header, a count, 50 bytes a triangle."""
    if len(data) < _HEADER + 4:
        raise InvalidInputError(field, "not an STL: neither ASCII facets nor a binary header")
    count = int(np.frombuffer(data, dtype="<u4", count=1, offset=_HEADER)[0])
    if len(data) != _HEADER + 4 + _RECORD * count:
        raise InvalidInputError(
            field,
            f"not an STL: a binary STL of {count} triangles is {_HEADER + 4 + _RECORD * count} "
            f"bytes, this is {len(data)}",
        )
    if count > limit[0]:
        raise _too_many(count, limit, field)
    record = np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attribute", "<u2")])
    rows = np.frombuffer(data, dtype=record, count=count, offset=_HEADER + 4)
    return rows["corners"].astype(float)


def _too_many(count: int, limit: tuple[int, str], field: str) -> InvalidInputError:
    """The error of a mesh over the triangle limit (its value and name)."""
    return InvalidInputError(field, f"{count} triangles; at most {limit[0]} ({limit[1]})")
