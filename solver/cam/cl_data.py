"""APT CL data read into a CamPath as NX, SolidWorks CAM, CATIA and Mastercam write it.

Records (:mod:`solver.cam.cl_records`) are read in order:

- ``GOTO/x, y, z[, i, j, k]``: a cutting move, or a rapid's target; a 3-number GOTO keeps the
  last tool axis (from a 6-number GOTO or ``TLAXIS``, else 0, 0, 1), ``MULTAX`` or not. A GOTO
  to where the tool is (same point, same axis) is dropped and counted.
- ``CIRCLE/xc, yc, zc, i, j, k[, r, ...][, TIMES, n]`` and the ``GOTO`` of its end: an arc
  (:mod:`solver.cam.arcs`), interpolated within ``arc_tolerance``; in an NX file (one with
  ``TOOL PATH``, ``TLDATA``, ``MSYS`` or ``END-OF-PATH``) clockwise about (i, j, k) as NX
  documents it, elsewhere counter-clockwise about it (APT's right-hand rule: SolidWorks CAM
  writes the axis -z for an arc clockwise seen from above, 458 of the corpus' 1,026 arcs; the
  shorter way read an arc of more than half a turn backwards, cam.md section 9's "unless the
  file says otherwise").
- ``FEDRAT``: the feed of the moves that follow (m/s); ``RAPID``: the next GOTO is a rapid,
  its target in no pass.
- ``UNITS``/``UNIT``: the length unit (:mod:`solver.cam.cl_units`, decided before any move is
  read); it may not change.
- ``MSYS``, ``CSYS`` (after ``TRNTYP/WORLD, 0, 0, 0``): the system points are written in
  (:mod:`solver.cam.cl_systems`); the path is in the part frame. A change between two cutting
  moves of a pass is refused with its line.
- ``TOOL PATH/<name>``, ``PARTNO``, ``PPRINT``: the operation name of the passes that start
  after it. ``TOOL PATH``, ``END-OF-PATH`` and a tool change (``LOADTL``, ``LOAD/TOOL``) end
  the pass. ``FROM/x, y, z``: the tool position, not a move.
- Words without geometry or feed are skipped and counted; unknown words are reported the same
  way, marked; words that would move the tool in a way the reader does not apply are refused.

A pass left with one point is dropped and counted. Axes follow cam.md section 6.
"""

from __future__ import annotations

import dataclasses

from solver.cam.cam_path import METRES_PER_UNIT, CamPath, Units, assemble_cam_path
from solver.cam.cl_end import program_end
from solver.cam.cl_reader import ClReader
from solver.cam.cl_records import SKIPPED, records
from solver.cam.cl_units import UnitsReading, units_of
from solver.cam.read_report import ReadReport
from solver.core.exceptions import InvalidInputError

DEFAULT_ARC_TOLERANCE = 1e-5
"""m: 0.01 mm, the chordal tolerance arcs are interpolated to by default."""
NX_WORDS = frozenset({"TOOL PATH", "TLDATA", "MSYS", "END-OF-PATH"})
"""Words only NX writes: a file with one of them states its arcs' sense (clockwise)."""
IGNORED = SKIPPED | {"PARTNO", "PPRINT", "FROM"}
"""Words that never change the waypoints (the free-text and header records)."""


def read_cl_data(
    text: str,
    *,
    units: Units | None = None,
    arc_tolerance: float = DEFAULT_ARC_TOLERANCE,
    max_waypoints: int | None = None,
    field: str = "path.cl_data",
    units_field: str = "path.units",
) -> CamPath:
    """The cutting moves of an APT CL program, split into passes, with what was skipped.

    Args:
        text: the program.
        units: the request's length unit, used when the file states none (see
            :mod:`solver.cam.cl_units`); ``None`` for none.
        arc_tolerance: m, > 0, the largest chordal distance of an arc's points from the arc.
        max_waypoints: refuse a program with more waypoints, as soon as they are read.
        field: the input's name, for the errors.
        units_field: the request's units field, for the errors.

    Returns:
        The path in metres in the part frame, with passes, feeds, lines, operations and its
        :class:`solver.cam.read_report.ReadReport`.

    Raises:
        InvalidInputError: no cutting move; no units (on ``units_field``); too many waypoints.
        InvalidLineError: a record that cannot be read or is not applied, naming its line.
    """
    if not 0.0 < arc_tolerance < float("inf"):
        raise InvalidInputError("path.arc_tolerance", f"{arc_tolerance!r} must be > 0, finite")
    all_records = list(records(text, field=field))
    if any(r.word == "GOTO" for r in all_records):
        reading = units_of(all_records, requested=units, field=field, units_field=units_field)
    else:  # no length to scale: its records are still checked, then "no cutting move"
        reading = UnitsReading(units or "mm", "request", "no GOTO")
    reader = ClReader(
        field=field,
        units=reading.units,
        scale=METRES_PER_UNIT[reading.units],
        tolerance=arc_tolerance,
        clockwise=any(r.word in NX_WORDS for r in all_records),
        max_waypoints=max_waypoints,
    )
    for record in all_records:
        reader.read(record)
    if reader.circle is not None:
        raise reader.error("CIRCLE is not followed by the GOTO of its end", reader.circle.record)
    path = assemble_cam_path(
        positions=reader.positions,
        directions=reader.axes,
        pass_ids=reader.pass_ids,
        lines=reader.lines,
        arrival_feeds=reader.feeds,
        units=reading.units,
        axis_correction=reader.correction,
        field=field,
        operations=reader.operations,
        drop_one_point_passes=True,
    )
    end = program_end(all_records)
    report = ReadReport(
        skipped_records=tuple(reader.skipped.values()),
        units_source=reading.source,
        units_note=reading.note,
        repeated_points=reader.repeated,
        arcs=reader.arcs,
        arc_tolerance=arc_tolerance,
        ended=end.ended,
        end_note=end.note,
    )
    return dataclasses.replace(path, report=report)
