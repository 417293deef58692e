"""The records of a CL file as CAM systems write them, and what each word means (cam.md 5, 9).

A record is ``WORD/arg, arg, ...`` or ``WORD`` alone; ``$`` ending a line continues the record
on the next, and ``$$`` starts a comment running to the end of the line. NX writes two words
of its own: ``TOOL PATH/<operation>,TOOL,<tool>`` (a blank inside the word, no ``/`` after its
first half) and ``END-OF-PATH``; an NX *information listing* starts with a header of
``label<TAB>value`` lines (``Information listing created by``, ``Date``, ``Current work part``,
``Node name``) and ends with ``Tool Path Listing has <n> lines.``: those lines are counted as
listing headers.

Words fall into four kinds:

- read: they set the geometry, the feed, the units, the passes or the operation names
  (:data:`READ`);
- skipped: they carry no geometry and no feed (tool and operation headers, display, selection,
  cutter data, coolant, spindle, comments, listing headers) and are counted
  (:data:`SKIPPED`, or a word starting with a prefix of :data:`SKIPPED_PREFIXES`);
- refused: they would change the geometry and the reader does not apply them
  (:data:`REFUSED`): a ``422`` naming the record and its line;
- unknown: any other word, reported with the skipped ones and marked as not recognised
  (cam.md section 5: reported, not refused).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass

from solver.cam.reading import BOM, is_number, text_lines
from solver.core.exceptions import InvalidLineError

READ = frozenset(
    {
        "GOTO",
        "CIRCLE",
        "FEDRAT",
        "RAPID",
        "UNITS",
        "UNIT",
        "MULTAX",
        "TLAXIS",
        "MSYS",
        "CSYS",
        "TRNTYP",
        "FROM",
        "LOADTL",
        "LOAD",
        "TOOL PATH",
        "END-OF-PATH",
        "PARTNO",
        "PPRINT",
    }
)
"""Words the reader applies."""

SKIPPED = frozenset(
    {
        "AUTOPS",
        "CLRSRF",
        "COOLNT",
        "CUTCOM",
        "CUTTER",
        "DELAY",
        "DISPLY",
        "END",
        "FINI",
        "INSERT",
        "INTOL",
        "MACHIN",
        "OPSKIP",
        "OPSTOP",
        "OUTTOL",
        "PAINT",
        "SELECT",
        "SEQNO",
        "SPINDL",
        "STOP",
        "TLDATA",
        "TOLER",
        "TOOLNO",
        "TPRINT",
    }
)
"""Words without geometry or feed. ``CUTCOM``: CL points are cutter locations already (the
tool centre the CAM system computed); compensation is the controller's wear offset."""

LITERAL = frozenset({"PARTNO", "PPRINT", "INSERT", "REMARK"})
"""Words whose text is taken as written, to the end of its line: APT does not continue them,
so a ``$`` ending one is text (``PPRINT/TOOL COST 5$`` joined the next line's GOTO to the
operation's name: a move lost without a word), and so is a ``$$`` in it (``PPRINT/ROUGH $$ 2``
was the operation ``ROUGH`` and a comment)."""

SKIPPED_PREFIXES = ("CSI_",)
"""SolidWorks CAM's ``CSI_SET_*`` tool data."""

COMMENT = "$$"
"""The word comments are counted under."""
LISTING_HEADER = "NX listing header"
"""The word NX information-listing header lines are counted under."""

REFUSED: dict[str, str] = {
    "GODLTA": "a move relative to the tool position",
    "TRACUT": "a transformation of the moves that follow",
    "COPY": "a transformed copy of earlier moves",
    "INDEX": "the start of moves to be copied",
    "ORIGIN": "a shift of the origin",
    "ROTABL": "a rotary table turn",
    "ROTHED": "a head turn",
    "ROTATE": "a rotation of the moves",
    "PIVOTZ": "a pivot offset of the tool point",
    "CYCLE": "a canned cycle, whose plunges are not written as GOTOs",
    "THREAD": "a threading cycle",
    "GOHOME": "a move to the FROM point, outside the GOTOs read",
    "INDIRV": "the direction of the next arc, which the reader takes from its CIRCLE",
    "INDIRP": "the direction of the next arc, which the reader takes from its CIRCLE",
    "RETRCT": "a retract move",
    "GOFWD": "a move along a drive surface or curve",
    "TLON": "a move along a drive surface or curve (TLON, GOFWD/...)",
    "ARC": "an arc given by its end point",
    "NURBS": "a spline move",
    "SPLINE": "a spline move",
    "REFSYS": "a reference system for the moves that follow",
    "TRANS": "a translation of the moves that follow",
    "GO": "GO TO written with a blank: APT ignores blanks, the reader does not (write GOTO)",
}
"""Words that change the geometry in ways the reader does not apply, and what they do."""

_WORD = re.compile(r"\s*(TOOL\s+PATH|[A-Za-z][A-Za-z0-9_]*(?:-[A-Za-z0-9_]+)*)\s*(.*)", re.I | re.S)
_HEADER = re.compile(
    r"(Information listing created by|Date|Current work part|Node name)\s*[\t:]"
    r"|Tool Path Listing has \d+ lines",
    re.I,
)


@dataclass(frozen=True)
class Record:
    """One record of a CL file.

    Attributes:
        line: the line it starts on, from 1.
        word: the major word, upper case (``GOTO``, ``TOOL PATH``; ``$$`` for a comment, or
            :data:`LISTING_HEADER`).
        rest: what follows the word, stripped (``/1, 2, 3`` or free text).
        text: the whole record, for the errors.
    """

    line: int
    word: str
    rest: str
    text: str

    def arguments(self, field: str) -> list[str]:
        """The comma-separated arguments after the ``/``, stripped; [] for a bare word.

        Raises:
            InvalidLineError: text after the word that does not start with ``/``.
        """
        if not self.rest:
            return []
        if not self.rest.startswith("/"):
            raise InvalidLineError(
                field,
                f"{self.word} needs a '/' before its arguments",
                line=self.line,
                text=self.text,
            )
        body = self.rest[1:].strip()
        return [a.strip() for a in body.split(",")] if body else []


def kind_of(word: str) -> str:
    """``read``, ``skipped``, ``refused`` or ``unknown`` (see the module's docstring)."""
    if word in READ:
        return "read"
    if word in SKIPPED or word in (COMMENT, LISTING_HEADER) or word.startswith(SKIPPED_PREFIXES):
        return "skipped"
    return "refused" if word in REFUSED else "unknown"


def records(text: str, *, field: str) -> Iterator[Record]:
    """Each record of a CL file, comments and listing headers included, continuations joined.

    Raises:
        InvalidLineError: a line that is no record, or a continuation past the end.
    """
    start, parts = 0, list[str]()
    text = text.removeprefix(BOM)  # the encoding's mark (Windows editors write it), not text
    for number, raw in enumerate(text_lines(text), start=1):
        literal = not parts and _literal(raw.strip())  # its text runs to the end of the line
        content, hash_, comment = (raw, "", "") if literal else raw.partition(COMMENT)
        if hash_:
            yield Record(number, COMMENT, comment.strip(), raw.strip())
        content = content.strip()
        if not parts and _HEADER.match(content):
            yield Record(number, LISTING_HEADER, content, content)
            continue
        if not parts:
            start = number
        if content.endswith("$") and not (not parts and _literal(content)):
            parts.append(content[:-1])
            continue
        parts.append(content)
        record = "".join(parts).strip()
        parts = []
        if record:
            yield _record(start, record, field=field)
    if parts:
        raise InvalidLineError(
            field,
            "the record is continued ($) past the end of the program",
            line=start,
            text="".join(parts),
        )


def _literal(line: str) -> bool:
    """Whether a line starts a record of a :data:`LITERAL` word."""
    match = _WORD.match(line)
    return match is not None and match.group(1).upper() in LITERAL


def _record(line: int, text: str, *, field: str) -> Record:
    """A record split into its word and the rest."""
    match = _WORD.fullmatch(text)
    if match is None:
        message = "not a record (WORD/arguments)"
        numbers = text.split(",")
        if len(numbers) >= 3 and all(is_number(n) for n in numbers):  # x, y, z, ...
            message += (
                ": numbers alone are a CSV's line; a CSV is read as one with its units "
                "(path.csv and path.units; dtf-place reads a file named .csv as one)"
            )
        raise InvalidLineError(field, message, line=line, text=text)
    word = " ".join(match.group(1).upper().split())
    return Record(line, word, match.group(2).strip(), text)
