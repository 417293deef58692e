"""What a CL reader skipped, dropped and inferred, for the answer to show (cam.md section 9)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

UnitsSource = Literal["stated", "inferred", "request"]
"""How a file's length unit was known (solver.cam.cl_units)."""


@dataclass(frozen=True)
class SkippedRecord:
    """Records of one word that carry no geometry or feed, skipped.

    Attributes:
        word: the major word (``PAINT``, ``$$`` for comments), cut to 100 characters.
        count: how many records of it the file has.
        first_line: the line of the first, from 1.
        recognised: ``False`` for a word the reader does not know (check that it moves
            nothing); ``True`` for one known to carry no geometry or feed.
    """

    word: str
    count: int
    first_line: int
    recognised: bool


@dataclass(frozen=True)
class ReadReport:
    """How a CL file was read, beyond its waypoints.

    Attributes:
        skipped_records: one entry a skipped word, in the order first met.
        units_source: ``stated``, ``inferred`` or ``request`` (solver.cam.cl_units).
        units_note: the evidence for the units, e.g. ``UNITS/MM at line 2``.
        repeated_points: GOTOs to where the tool already was (same point and axis), dropped.
        arcs: CIRCLE moves interpolated.
        arc_tolerance: m, the chordal tolerance they were interpolated to.
        ended: whether the program ends as CAM systems end one (:mod:`solver.cam.cl_end`);
            ``False``: it may be cut short.
        end_note: the end record and its line, or where the program stops and what is missing.
    """

    skipped_records: tuple[SkippedRecord, ...]
    units_source: UnitsSource
    units_note: str
    repeated_points: int
    arcs: int
    arc_tolerance: float
    ended: bool
    end_note: str
