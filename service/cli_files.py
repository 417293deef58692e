"""The files ``dtf-place`` reads, as text: UTF-8, or UTF-16 after its byte order mark.

Windows PowerShell writes files as UTF-16 with the mark (its ``>``), Windows editors UTF-8
with one; both were Python tracebacks (UnicodeDecodeError) or a refused first line.
"""

from __future__ import annotations

import codecs
import sys
from pathlib import Path

from solver.core.exceptions import InvalidInputError

MAX_FILE_BYTES = 8_000_000
"""The most bytes read of a file: 2,000,000 characters (the longest program, URDF or cell text
a request may hold) of up to 4 bytes in UTF-8. ``import /dev/zero`` read until memory ran out
(MemoryError, exit 1) before any limit was checked."""


STDIN = "-"
"""The program's name that reads it from standard input, as Unix commands take it
(``cam-post | dtf-place import -``): a post-processor need not write its program to a file
first. CL data only: a CSV is told by its file name (``.csv``)."""


def stdin_bytes(field: str) -> bytes:
    """The bytes of standard input, at most MAX_FILE_BYTES.

    Raises:
        InvalidInputError: on ``field``, when longer.
    """
    return _limited(sys.stdin.buffer.read(MAX_FILE_BYTES + 1), "standard input", field)


def file_bytes(file: Path, field: str) -> bytes:
    """The bytes of ``file``, at most MAX_FILE_BYTES.

    Raises:
        InvalidInputError: on ``field``: no such file, a folder, unreadable, or longer.
    """
    if not file.exists():
        raise InvalidInputError(field, f"no file {str(file)!r}")
    if file.is_dir():
        raise InvalidInputError(field, f"{str(file)!r} is a folder, not a file")
    try:
        with file.open("rb") as stream:
            data = stream.read(MAX_FILE_BYTES + 1)
    except OSError as error:
        raise InvalidInputError(field, f"cannot read {str(file)!r}: {error.strerror}") from error
    return _limited(data, repr(str(file)), field)


def _limited(data: bytes, name: str, field: str) -> bytes:
    """``data`` (read up to one byte over MAX_FILE_BYTES), refused on ``field`` where longer."""
    if len(data) > MAX_FILE_BYTES:
        raise InvalidInputError(
            field,
            f"{name} is longer than {MAX_FILE_BYTES:,} bytes: no program, URDF or cell "
            "the service reads is (2,000,000 characters at most)",
        )
    return data


def text_file(file: Path, field: str) -> str:
    """The text of ``file`` (UTF-8, or UTF-16 where it starts with its byte order mark).

    Raises:
        InvalidInputError: on ``field``, when the file is not such text (or not a file to
            read, :func:`file_bytes`).
    """
    try:
        return decoded(file_bytes(file, field))
    except UnicodeDecodeError as error:
        message = f"the file is not UTF-8 text ({error.reason} at byte {error.start})"
        raise InvalidInputError(field, message) from error


def decoded(data: bytes, *, errors: str = "strict") -> str:
    """Bytes as text: UTF-16 after its byte order mark, else UTF-8 without its mark.

    Windows PowerShell writes files as UTF-16 (with the mark), Windows editors UTF-8 with one.
    """
    if data[:2] in (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE):
        return data.decode("utf-16", errors=errors)
    return data.decode("utf-8-sig", errors=errors)
