"""The files ``dtf-place`` reads, as text: UTF-8, or UTF-16 after its byte order mark.

Windows PowerShell writes files as UTF-16 with the mark (its ``>``), Windows editors UTF-8
with one; both were Python tracebacks (UnicodeDecodeError) or a refused first line.
"""

from __future__ import annotations

import codecs
from pathlib import Path

from solver.core.exceptions import InvalidInputError


def text_file(file: Path, field: str) -> str:
    """The text of ``file`` (UTF-8, or UTF-16 where it starts with its byte order mark).

    Raises:
        InvalidInputError: on ``field``, when the file is not such text.
    """
    try:
        return decoded(file.read_bytes())
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
