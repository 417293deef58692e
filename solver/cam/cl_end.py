"""Where a CL program ends: a program cut short is said, never read as if it were whole.

A CL file written by a CAM system ends its moves with ``FINI`` (APT, SolidWorks CAM, CATIA,
Mastercam) or ``END-OF-PATH`` (NX, after each operation); an NX information listing then states
its length on its last line, ``Tool Path Listing has <n> lines.``, counting the lines from the
first after its header block to the line before that one (all four published listings of
``../shared/realworld``: 350, 388 and 162 lines with no header, 11,294 after a header of 6).
A file cut in a transfer, by a full disk or by hand has none of these after its last move, or
its listing is not as long as it says: its moves are read (they are the program's, as far as it
goes), and the answer says that the path may be only part of the program, with the line where
it stops.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from solver.cam.cl_records import LISTING_HEADER, Record

END_WORDS = ("FINI", "END-OF-PATH")
"""The records that end a program's moves."""
MOVE_WORDS = frozenset({"GOTO", "CIRCLE"})
"""The records that move the tool (a CIRCLE starts an arc that its GOTO ends)."""
_LISTING_LENGTH = re.compile(r"Tool Path Listing has (\d+) lines", re.I)


@dataclass(frozen=True)
class ProgramEnd:
    """How a CL program ends.

    Attributes:
        ended: whether an end record follows its last move and, where an NX listing states its
            length, the listing is that long; ``False``: the program may be cut short.
        note: what was found (the end record and its line, the stated length), or where the
            program stops and what is missing.
    """

    ended: bool
    note: str


def program_end(records: Sequence[Record]) -> ProgramEnd:
    """The end of the program made of ``records`` (every record, comments and headers included).

    Args:
        records: :func:`solver.cam.cl_records.records` of the file, in order; at least one move.
    """
    last_move = max((r.line for r in records if r.word in MOVE_WORDS), default=0)
    ends = [r for r in records if r.word in END_WORDS and r.line > last_move]
    stated = [
        (r, m)
        for r in records
        if r.word == LISTING_HEADER and (m := _LISTING_LENGTH.match(r.rest)) is not None
    ]
    if not ends:
        last = next(r for r in reversed(records) if r.word in MOVE_WORDS)
        return ProgramEnd(
            False,
            f"no {' or '.join(END_WORDS)} after the last move ({last.word} at line {last.line}): "
            "the program may be cut short, and the path is only what was read",
        )
    end = ends[0]
    said = f"{end.word} at line {end.line}"
    if not stated:
        return ProgramEnd(True, said)
    footer, match = stated[-1]
    first = next(r.line for r in records if r.word != LISTING_HEADER)
    length, counted = int(match.group(1)), footer.line - first
    if length == counted:
        return ProgramEnd(True, f"{said}; {length} lines, as the listing's last line states")
    return ProgramEnd(
        False,
        f"{said}, but the listing's line {footer.line} states {length} lines and it has "
        f"{counted} (lines {first} to {footer.line - 1}): lines are missing or were added",
    )
