"""The length unit of a CL file, never assumed (cam.md section 9).

1. ``UNITS/MM``, ``UNITS/INCHES``, ``UNIT/MM``, ``UNIT/INCH`` (``INCH`` and ``INCHES`` alike)
   state it: ``stated``. The request's ``units``, when given, must agree.
2. No statement but a feed in inches per minute (``FEDRAT/IPM, f``, as NX inch listings write)
   and none in mm: inches, ``inferred``; a request's other ``units`` are refused, naming the
   feed (read as mm, an NX inch part came out 25.4 times too small, exit 0).
3. Otherwise (feeds in both units too) the request's ``units``: ``request``.
4. Otherwise a ``422`` on ``path.units`` saying what the file gave away.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from solver.cam.cam_path import FEED_RANGE, METRES_PER_UNIT, Units
from solver.cam.cl_records import Record
from solver.cam.read_report import UnitsSource
from solver.cam.reading import parse_number
from solver.core.exceptions import InvalidInputError, InvalidLineError

UNIT_WORDS: dict[str, Units] = {"MM": "mm", "INCHES": "inches", "INCH": "inches"}
FEED_UNIT_WORDS: dict[str, Units] = {"MMPM": "mm", "IPM": "inches"}


@dataclass(frozen=True)
class UnitsReading:
    """The file's length unit and how it was known.

    Attributes:
        units: ``mm`` or ``inches``.
        source: ``stated`` (a UNITS record), ``inferred`` (an inch feed, no UNITS record) or
            ``request`` (the request's ``units``).
        note: the evidence, e.g. ``UNITS/INCHES at line 3``.
    """

    units: Units
    source: UnitsSource
    note: str


def stated_units(record: Record, *, field: str) -> Units:
    """The unit a ``UNITS``/``UNIT`` record states.

    Raises:
        InvalidLineError: anything but MM, INCH or INCHES.
    """
    args = [a.upper() for a in record.arguments(field)]
    if len(args) != 1 or args[0] not in UNIT_WORDS:
        raise InvalidLineError(
            field, f"{record.word} needs MM or INCHES", line=record.line, text=record.text
        )
    return UNIT_WORDS[args[0]]


def units_of(
    records: Sequence[Record], *, requested: Units | None, field: str, units_field: str
) -> UnitsReading:
    """The unit of a CL file's lengths (see the module's docstring).

    Args:
        records: the file's records.
        requested: the request's ``units``, or ``None``.
        field: the file's input name, for the errors.
        units_field: the request's units field (``path.units``), for the errors.

    Raises:
        InvalidInputError: on ``units_field``, no unit to be had, or a request that contradicts
            the file's statement.
        InvalidLineError: a UNITS record that states no unit.
    """
    statement = next((r for r in records if r.word in ("UNITS", "UNIT")), None)
    if statement is not None:
        units = stated_units(statement, field=field)
        move = next((r for r in records if r.word == "GOTO"), None)
        if move is not None and move.line < statement.line:
            raise InvalidLineError(
                field,
                f"{statement.word} comes after the first move (GOTO at line {move.line}): the "
                "reader takes one unit for the whole program, stated before its moves",
                line=statement.line,
                text=statement.text,
            )
        note = f"{statement.word}/{statement.arguments(field)[0].upper()} at line {statement.line}"
        if requested is not None and requested != units:
            raise InvalidInputError(
                units_field, f"the request says {requested}, but the file states {note}"
            )
        return UnitsReading(units, "stated", note)
    feeds = [r for r in records if r.word == "FEDRAT"]
    inch_feed = next((r for r in feeds if _feed_unit(r, field) == "inches"), None)
    mm_feed = next((r for r in feeds if _feed_unit(r, field) == "mm"), None)
    if requested is not None:
        if inch_feed is not None and mm_feed is None and requested != "inches":
            raise InvalidInputError(
                units_field,
                f"the request says {requested}, but the file states no units and its feed is in "
                f"inches per minute (FEDRAT/IPM at line {inch_feed.line}): such a program is "
                "in inches (NX inch listings write no UNITS); give inch, or leave units out",
            )
        return UnitsReading(requested, "request", "the request's units (the file states none)")
    if inch_feed is not None and mm_feed is not None:  # no single unit is suggested
        raise InvalidInputError(
            units_field,
            "the program states no units (no UNITS or UNIT record) and its feeds are in inches "
            f"per minute (FEDRAT/IPM at line {inch_feed.line}) and in mm per minute "
            f"(FEDRAT/MMPM at line {mm_feed.line}): give units (mm or inch) with the program",
        )
    if inch_feed is not None:
        return UnitsReading(
            "inches",
            "inferred",
            f"no UNITS record; a feed in inches per minute, FEDRAT/IPM at line {inch_feed.line}",
        )
    raise InvalidInputError(units_field, _no_units_message(feeds, field))


def _feed_unit(record: Record, field: str) -> Units | None:
    """The unit word of a FEDRAT record, first or last, or None."""
    args = [a.upper() for a in record.arguments(field)]
    for word in (args[:1] + args[-1:]) if args else []:
        if word in FEED_UNIT_WORDS:
            return FEED_UNIT_WORDS[word]
    return None


def _no_units_message(feeds: Sequence[Record], field: str) -> str:
    """What a file without a unit gave away, and what to do."""
    mm_feed = next((r for r in feeds if _feed_unit(r, field) == "mm"), None)
    if mm_feed is not None:
        hint = (
            f"its feed is in mm per minute (FEDRAT/MMPM at line {mm_feed.line}), which suggests "
            "mm but does not state it"
        )
    elif feeds:
        hint = f"its feeds carry no unit (FEDRAT at line {feeds[0].line})"
    else:
        hint = "it has no FEDRAT"
    return (
        f"the program states no units (no UNITS or UNIT record) and {hint}: give units "
        "(mm or inch) with the program"
    )


def feed_of(record: Record, *, units: Units, field: str) -> float:
    """m/s, the feed of ``FEDRAT/f``, ``FEDRAT/MMPM, f``, ``FEDRAT/IPM, f`` or ``FEDRAT/f, IPM``.

    Args:
        record: the FEDRAT record.
        units: the file's length unit, that of a feed without a unit word (per minute).
        field: the input's name, for the errors.

    Raises:
        InvalidLineError: another form (a feed per revolution), or a feed that is not > 0 or
            outside FEED_RANGE once in m/s.
    """
    args = record.arguments(field)
    words = [a.upper() for a in args]
    if len(args) == 1:
        unit, number = units, args[0]
    elif len(args) == 2 and words[0] in FEED_UNIT_WORDS:
        unit, number = FEED_UNIT_WORDS[words[0]], args[1]
    elif len(args) == 2 and words[1] in FEED_UNIT_WORDS:
        unit, number = FEED_UNIT_WORDS[words[1]], args[0]
    else:
        raise InvalidLineError(
            field,
            "FEDRAT needs f, MMPM, f or IPM, f (a feed per minute)",
            line=record.line,
            text=record.text,
        )
    value = parse_number(number, field=field, line=record.line, text=record.text)
    if value <= 0.0:
        raise InvalidLineError(
            field, f"the feed {value:g} must be > 0", line=record.line, text=record.text
        )
    feed = value * METRES_PER_UNIT[unit] / 60.0
    low, high = FEED_RANGE
    if not low <= feed <= high:
        raise InvalidLineError(
            field,
            f"the feed {value:g} ({unit} per minute) is {feed:.3g} m/s; a feed is taken from "
            f"{low:g} to {high:g} m/s ({low * 60e3:g} to {high * 60e3:g} mm/min)",
            line=record.line,
            text=record.text,
        )
    return feed
