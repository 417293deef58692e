"""APT CL data read into a CamPath (cam.md section 5).

Records are ``WORD/arg, arg, ...`` (or ``WORD`` alone); a ``$`` ending a line continues the
record on the next, and ``$$`` starts a comment running to the end of the line. Read:

- ``UNITS/MM`` or ``UNITS/INCHES`` (default mm): lengths are converted to metres. The units
  may not change once a ``GOTO`` has been read.
- ``MULTAX/ON`` (or ``MULTAX``): ``GOTO/x, y, z, i, j, k``; ``MULTAX/OFF`` (the default):
  ``GOTO/x, y, z`` with the tool axis of the last ``TLAXIS/i, j, k`` (default 0, 0, 1). A
  ``GOTO`` with the other mode's count of numbers is an error (never guess an axis).
- ``FEDRAT/f`` (program units per minute), ``FEDRAT/MMPM, f``, ``FEDRAT/IPM, f`` (the unit word
  may also come last): the feed of the moves that follow, in m/s. It may change within a pass:
  :class:`solver.cam.cam_path.CamPath` keeps a feed per waypoint.
- ``RAPID``: the next ``GOTO`` is a rapid; its target belongs to no pass, and it ends the pass
  before it.
- Ignored: ``PARTNO``, ``PPRINT``, ``LOADTL``, ``SPINDL``, ``COOLNT``, ``CUTTER``, ``FROM``,
  ``END``, ``FINI``, ``MACHIN``, ``CLRSRF``, ``INSERT``.
- Anything else, ``CIRCLE`` included, is an error naming the line and the record.

Axes and quaternions follow cam.md section 6: normalised within 1e-3 of unit, the largest
correction reported.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from solver.cam.cam_path import METRES_PER_UNIT, CamPath, Units, assemble_cam_path
from solver.cam.reading import checked_position, near_unit_vector, parse_numbers
from solver.core.exceptions import InvalidLineError

IGNORED = frozenset(
    {
        "PARTNO",
        "PPRINT",
        "LOADTL",
        "SPINDL",
        "COOLNT",
        "CUTTER",
        "FROM",
        "END",
        "FINI",
        "MACHIN",
        "CLRSRF",
        "INSERT",
    }
)
_WORD = re.compile(r"\s*([A-Za-z][A-Za-z0-9_]*)\s*(.*)", re.DOTALL)
_UNIT_WORDS: dict[str, Units] = {"MM": "mm", "INCHES": "inches", "INCH": "inches"}
_FEED_UNIT_WORDS: dict[str, Units] = {"MMPM": "mm", "IPM": "inches"}


def read_cl_data(text: str, *, field: str = "path.cl_data") -> CamPath:
    """The cutting moves of an APT CL data program, split into passes at rapids.

    Args:
        text: the program.
        field: the input's name, for the errors.

    Returns:
        The path in metres, with its tool axes, passes, feeds and source lines.

    Raises:
        InvalidInputError: no cutting move.
        InvalidLineError: a record that is not read (``CIRCLE``, an unknown word), bad
            arguments (a count, a number that is malformed or not finite, an axis off unit by
            more than 1e-3, a position beyond 1 km), a continuation at the end of the text, a
            pass of one point, or a point repeating the one before it; each names its line.
    """
    reader = _Reader(field=field)
    for line, record in _records(text, field=field):
        reader.read(line, record)
    return assemble_cam_path(
        positions=reader.positions,
        directions=reader.axes,
        pass_ids=reader.pass_ids,
        lines=reader.lines,
        arrival_feeds=reader.feeds,
        units=reader.units,
        axis_correction=reader.correction,
        field=field,
    )


def _records(text: str, *, field: str) -> Iterator[tuple[int, str]]:
    """Each record and the line it starts on: comments removed, continuations joined."""
    start, parts = 0, list[str]()
    for number, raw in enumerate(text.splitlines(), start=1):
        content = raw.split("$$", 1)[0].strip()
        if not parts:
            start = number
        if content.endswith("$"):
            parts.append(content[:-1])
            continue
        parts.append(content)
        record = "".join(parts).strip()
        parts = []
        if record:
            yield start, record
    if parts:
        raise InvalidLineError(
            field,
            "the record is continued ($) past the end of the program",
            line=start,
            text="".join(parts),
        )


@dataclass
class _Reader:
    """The state of the program as it is read, and the cutting moves collected so far."""

    field: str
    units: Units = "mm"
    multax: bool = False
    tool_axis: np.ndarray = dataclasses.field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    feed: float = math.nan
    rapid: bool = False
    pass_id: int = 0
    moved: bool = False
    correction: float = 0.0
    positions: list[np.ndarray] = dataclasses.field(default_factory=list)
    axes: list[np.ndarray] = dataclasses.field(default_factory=list)
    pass_ids: list[int] = dataclasses.field(default_factory=list)
    lines: list[int] = dataclasses.field(default_factory=list)
    feeds: list[float] = dataclasses.field(default_factory=list)

    def error(self, message: str, line: int, record: str) -> InvalidLineError:
        """An error naming the line and echoing the record."""
        return InvalidLineError(self.field, message, line=line, text=record)

    def read(self, line: int, record: str) -> None:
        """Take one record into the state."""
        match = _WORD.fullmatch(record)
        if match is None:
            raise self.error("not a record (WORD/arguments)", line, record)
        word, rest = match.group(1).upper(), match.group(2).strip()
        if word in IGNORED:
            return
        if rest and not rest.startswith("/"):
            raise self.error(f"{word} needs a '/' before its arguments", line, record)
        args = [a.strip() for a in rest[1:].split(",")] if rest else []
        if word == "CIRCLE":
            raise self.error(
                "CIRCLE is not read (a circular move is never guessed): post the program "
                "with linear moves (GOTO)",
                line,
                record,
            )
        handlers = {
            "UNITS": self.read_units,
            "MULTAX": self.read_multax,
            "TLAXIS": self.read_tlaxis,
            "FEDRAT": self.read_fedrat,
            "RAPID": self.read_rapid,
            "GOTO": self.read_goto,
        }
        if word not in handlers:
            raise self.error(f"unknown record {word}; only the records of cam.md 5", line, record)
        handlers[word](args, line, record)

    def read_units(self, args: list[str], line: int, record: str) -> None:
        """``UNITS/MM`` or ``UNITS/INCHES``; no change once a GOTO was read."""
        if len(args) != 1 or args[0].upper() not in _UNIT_WORDS:
            raise self.error("UNITS needs MM or INCHES", line, record)
        units = _UNIT_WORDS[args[0].upper()]
        if self.moved and units != self.units:
            raise self.error(f"the units change from {self.units} after a GOTO", line, record)
        self.units = units

    def read_multax(self, args: list[str], line: int, record: str) -> None:
        """``MULTAX``, ``MULTAX/ON`` or ``MULTAX/OFF``."""
        if args and (len(args) != 1 or args[0].upper() not in ("ON", "OFF")):
            raise self.error("MULTAX takes ON or OFF", line, record)
        self.multax = not args or args[0].upper() == "ON"

    def read_tlaxis(self, args: list[str], line: int, record: str) -> None:
        """``TLAXIS/i, j, k``: the tool axis of later 3-number GOTOs."""
        if len(args) != 3:
            raise self.error(f"TLAXIS needs i, j, k; got {len(args)} arguments", line, record)
        values = parse_numbers(args, field=self.field, line=line, text=record)
        self.tool_axis = self.unit_axis(values, line, record)

    def read_fedrat(self, args: list[str], line: int, record: str) -> None:
        """``FEDRAT/f``, ``FEDRAT/MMPM, f``, ``FEDRAT/IPM, f`` or ``FEDRAT/f, IPM``, in m/s."""
        words = [a.upper() for a in args]
        if len(args) == 1:
            units, number = self.units, args[0]
        elif len(args) == 2 and words[0] in _FEED_UNIT_WORDS:
            units, number = _FEED_UNIT_WORDS[words[0]], args[1]
        elif len(args) == 2 and words[1] in _FEED_UNIT_WORDS:
            units, number = _FEED_UNIT_WORDS[words[1]], args[0]
        else:
            raise self.error("FEDRAT needs f, MMPM, f or IPM, f (a feed per minute)", line, record)
        (value,) = parse_numbers([number], field=self.field, line=line, text=record)
        if value <= 0.0:
            raise self.error(f"the feed {value:g} must be > 0", line, record)
        self.feed = value * METRES_PER_UNIT[units] / 60.0

    def read_rapid(self, args: list[str], line: int, record: str) -> None:
        """``RAPID``: the next GOTO is a rapid move."""
        if args:
            raise self.error("RAPID takes no arguments", line, record)
        self.rapid = True

    def read_goto(self, args: list[str], line: int, record: str) -> None:
        """``GOTO/x, y, z[, i, j, k]``: a cutting move, or a rapid's target."""
        expected = 6 if self.multax else 3
        if len(args) != expected:
            mode = "on: GOTO needs x, y, z, i, j, k" if self.multax else "off: GOTO needs x, y, z"
            raise self.error(f"MULTAX is {mode}; got {len(args)} numbers", line, record)
        values = parse_numbers(args, field=self.field, line=line, text=record)
        position = checked_position(
            values[:3] * METRES_PER_UNIT[self.units], field=self.field, line=line, text=record
        )
        axis = self.unit_axis(values[3:], line, record) if self.multax else self.tool_axis
        self.moved = True
        if self.rapid:  # the rapid's target belongs to no pass; the next cut starts one
            self.rapid = False
            self.pass_id += 1
            return
        self.positions.append(position)
        self.axes.append(axis)
        self.pass_ids.append(self.pass_id)
        self.lines.append(line)
        self.feeds.append(self.feed)

    def unit_axis(self, values: np.ndarray, line: int, record: str) -> np.ndarray:
        """A tool axis normalised (cam.md section 6), its correction kept."""
        axis, correction = near_unit_vector(
            values, name="tool axis", field=self.field, line=line, text=record
        )
        self.correction = max(self.correction, correction)
        return axis
