"""A CL program cut short is said: no end record after its last move, or an NX listing too short.

The fixtures are the NX and SolidWorks programs of ``tests/solver/cam/dialects.py``, whole, cut
at each line and with a line taken out or added; what each should say is read from their text
here (the lines of their records, the lines NX counts), never from the reader.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from solver.cam.cam_path import Units
from solver.cam.cl_data import read_cl_data
from solver.core.exceptions import InvalidInputError
from tests.solver.cam.dialects import NX_LISTING, SOLIDWORKS

MOVE = re.compile(r"\s*(GOTO|CIRCLE)\b", re.I)


def _read(lines: list[str], units: Units | None = None) -> tuple[bool, str]:
    report = read_cl_data("\n".join(lines) + "\n", units=units).report
    assert report is not None
    return report.ended, report.end_note


def _listing_lines(lines: list[str]) -> tuple[int, int]:
    """The first line after the NX header block and the footer's line (from 1), from the text."""
    first = next(n for n, text in enumerate(lines, 1) if text.startswith("TOOL PATH"))
    footer = next(n for n, text in enumerate(lines, 1) if text.startswith("Tool Path Listing"))
    return first, footer


def test_whole_programs_name_their_end_record() -> None:
    fini = next(n for n, text in enumerate(SOLIDWORKS, 1) if text == "FINI")
    assert _read(SOLIDWORKS) == (True, f"FINI at line {fini}")
    first, footer = _listing_lines(NX_LISTING)
    stated = int(re.search(r"has (\d+) lines", NX_LISTING[footer - 1]).group(1))  # type: ignore[union-attr]
    assert stated == footer - first  # the fixture is as long as it says, counted as NX counts
    assert _read(NX_LISTING) == (
        True,
        f"END-OF-PATH at line {footer - 1}; {stated} lines, as the listing's last line states",
    )


@pytest.mark.parametrize("program", [SOLIDWORKS, NX_LISTING], ids=["solidworks", "nx"])
def test_a_program_cut_after_a_move_is_said_to_be_cut_short(program: list[str]) -> None:
    """Every cut at the end of a line that leaves a move last (a cut that splits an arc from
    its end is refused already)."""
    cuts = 0
    for k in range(len(program)):
        kept = program[:k]
        records = [text for text in kept if text.strip() and not text.startswith("$$")]
        if not records or not MOVE.match(records[-1]):
            continue
        try:
            ended, note = _read(kept)
        except InvalidInputError:
            continue
        last = max(n for n, text in enumerate(kept, 1) if MOVE.match(text))
        word = MOVE.match(kept[last - 1]).group(1).upper()  # type: ignore[union-attr]
        assert not ended, k
        assert note.startswith(
            f"no FINI or END-OF-PATH after the last move ({word} at line {last}): "
            "the program may be cut short"
        ), (k, note)
        cuts += 1
    assert cuts >= 5  # cuts were tested, not all skipped


@pytest.mark.parametrize("change", ["a line taken out", "a line added"])
def test_an_nx_listing_not_as_long_as_it_states_is_said(change: str) -> None:
    first, footer = _listing_lines(NX_LISTING)
    paint = NX_LISTING.index("PAINT/COLOR,186")
    if change == "a line taken out":
        lines = NX_LISTING[:paint] + NX_LISTING[paint + 1 :]
    else:
        lines = [*NX_LISTING[:paint], "PAINT/COLOR,186", *NX_LISTING[paint:]]
    moved = len(lines) - len(NX_LISTING)
    ended, note = _read(lines)
    assert not ended
    assert note == (
        f"END-OF-PATH at line {footer - 1 + moved}, but the listing's line {footer + moved} "
        f"states {footer - first} lines and it has {footer - first + moved} "
        f"(lines {first} to {footer - 1 + moved}): lines are missing or were added"
    )


def test_comments_after_fini_and_an_end_between_operations() -> None:
    """What follows the end record but moves nothing leaves the program whole; an operation's
    END-OF-PATH followed by more moves is no end."""
    program = ["UNITS/MM", "GOTO/0,0,0", "GOTO/5,0,0", "FINI", "$$ written by hand", ""]
    assert _read(program, "mm") == (True, "FINI at line 4")
    operations = ["GOTO/0,0,0", "GOTO/5,0,0", "END-OF-PATH", "TOOL PATH/NEXT", "GOTO/5,5,0"]
    operations += ["GOTO/9,5,0"]
    ended, note = _read(operations, "mm")
    assert not ended and note.startswith(
        "no FINI or END-OF-PATH after the last move (GOTO at line 6)"
    )


@pytest.mark.parametrize("line_end", ["\r\n", "\r\r\n", "\r"], ids=["crlf", "crcrlf", "cr"])
@pytest.mark.parametrize("program", [SOLIDWORKS, NX_LISTING], ids=["solidworks", "nx"])
def test_line_ends_of_any_transfer_read_as_the_lines_of_the_text(
    program: list[str], line_end: str
) -> None:
    """CR CR LF (a CR LF file converted again in a text-mode transfer) ends one line each, as
    ``grep -n`` counts: the NX listing was said to be twice as long as it states (the CLI
    audit of stop 61, on the published NX files converted once more), every line named
    doubled. Each report, the waypoints and their lines as with LF, the lines counted here."""
    plain = read_cl_data("\n".join(program) + "\n")
    other = read_cl_data(line_end.join(program) + line_end)
    assert other.report == plain.report and other.report is not None
    assert other.report.ended
    assert other.lines.tolist() == plain.lines.tolist()
    moves = [n for n, text in enumerate(program, 1) if MOVE.match(text)]
    assert set(other.lines.tolist()) <= set(moves)
    np.testing.assert_array_equal(other.positions, plain.positions)
    np.testing.assert_array_equal(other.axes, plain.axes)


def test_cr_alone_ends_a_line_and_two_make_an_empty_one() -> None:
    """An old Mac file: a CR alone is a line end, CR CR an empty line between (no LF follows)."""
    text = "\r".join(["UNITS/MM", "GOTO/0,0,0", "", "GOTO/5,0,0", "FINI"]) + "\r"
    path = read_cl_data(text)
    assert path.lines.tolist() == [2, 4]
    assert path.report is not None and path.report.end_note == "FINI at line 5"
