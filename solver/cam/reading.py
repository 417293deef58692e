"""Numbers, positions and unit vectors read from lines of text, each error naming the line.

Shared by the CL data and CSV readers (cam.md sections 5 and 6). A number is a plain decimal
(``12``, ``-0.5``, ``.25``, ``1.5E+02``): Python's ``float`` would also take ``nan``, ``inf`` and
``1_000``, which no CAM system writes and which must not pass silently.
"""

from __future__ import annotations

import math
import re

import numpy as np

from solver.core.exceptions import InvalidLineError
from solver.core.spatial import MAX_COORDINATE
from solver.core.tool_axis import NEAR_UNIT_TOLERANCE

_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?", re.ASCII)  # no other digits
r"""One way to match each number: ``\d+\.?\d*`` split a run of digits between its two
``\d`` in every way before refusing what followed it, time square in the run's length (a
40 kB token held the event loop 25 s)."""


BOM = "\ufeff"
"""The byte order mark a file saved as UTF-8 by Windows tools starts with, once decoded: the
CL reader refused such a program ('line 1: not a record'), the CSV reader its header."""


_LINE_BREAK = re.compile(r"\r*\n|\r")


def text_lines(text: str) -> list[str]:
    r"""The lines of a file as editors and ``grep -n`` count them: at LF, CR LF or CR only.

    ``str.splitlines`` also breaks at a form feed, a vertical tab, ``\x1c``-``\x1e``,
    ``\x85`` and U+2028: after one, every line number an answer named was one too many (the
    CAM reader audit, stop 54). CRs before a LF end one line with it, as ``grep -n`` counts
    them: a CR LF file converted once more in a text-mode transfer ends its lines with CR CR
    LF, and every line number was doubled (an NX listing then said to be twice its stated
    length: cut short or lines added; the CLI audit of stop 61). A CR alone ends a line (an
    old Mac file), so CR CR without a LF is an empty line. One break at the end makes no empty
    last line.
    """
    lines = _LINE_BREAK.split(text)
    return lines[:-1] if lines and lines[-1] == "" else lines


def is_number(token: str) -> bool:
    """Whether ``token`` (stripped) is a plain decimal number."""
    return _NUMBER.fullmatch(token.strip()) is not None


def parse_number(token: str, *, field: str, line: int, text: str) -> float:
    """A finite number from one token of a line.

    Args:
        token: the token, surrounding blanks allowed.
        field: the input's name, for the error.
        line: the line number (from 1), for the error.
        text: the line or record, echoed in the error.

    Raises:
        InvalidLineError: not a plain decimal number, or one that overflows a float.
    """
    stripped = token.strip()
    if not _NUMBER.fullmatch(stripped):
        try:
            value = float(stripped)
        except ValueError:
            value = 0.0
        if not math.isfinite(value):
            raise InvalidLineError(
                field, f"{stripped[:40]!r} is not a finite number", line=line, text=text
            )
        raise InvalidLineError(field, f"{stripped[:40]!r} is not a number", line=line, text=text)
    value = float(stripped)
    if not math.isfinite(value):
        raise InvalidLineError(
            field, f"{stripped[:40]!r} is not a finite number", line=line, text=text
        )
    return value


def parse_numbers(tokens: list[str], *, field: str, line: int, text: str) -> np.ndarray:
    """Every token as a finite number, shape (len(tokens),); see :func:`parse_number`."""
    return np.array([parse_number(t, field=field, line=line, text=text) for t in tokens])


def checked_position(position: np.ndarray, *, field: str, line: int, text: str) -> np.ndarray:
    """A position (m), shape (3,), refused beyond MAX_COORDINATE (a unit mix-up, not a cell).

    Raises:
        InvalidLineError: a coordinate farther than MAX_COORDINATE from the origin.
    """
    if np.max(np.abs(position)) > MAX_COORDINATE:
        raise InvalidLineError(
            field,
            f"position {position.tolist()} m is beyond +-{MAX_COORDINATE} m",
            line=line,
            text=text,
        )
    return position


def near_unit_vector(
    vector: np.ndarray, *, name: str, field: str, line: int, text: str
) -> tuple[np.ndarray, float]:
    """cam.md section 6: a direction or quaternion normalised if its norm is within 1e-3 of 1.

    Args:
        vector: shape (3,) or (4,), dimensionless.
        name: what the vector is (``tool axis``, ``quaternion``), for the error.
        field: the input's name, for the error.
        line: the line number, for the error.
        text: the line or record, echoed in the error.

    Returns:
        The unit vector and the correction | |v| - 1 |.

    Raises:
        InvalidLineError: a norm off 1 by more than NEAR_UNIT_TOLERANCE.
    """
    norm = float(np.linalg.norm(vector))
    correction = abs(norm - 1.0)
    if not correction <= NEAR_UNIT_TOLERANCE:
        raise InvalidLineError(
            field,
            f"the {name} {vector.tolist()} has length {norm:.6g}; a unit vector is needed "
            f"(within {NEAR_UNIT_TOLERANCE:g}, where it is normalised)",
            line=line,
            text=text,
        )
    return vector / norm, correction
