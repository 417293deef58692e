"""What native code writes to the process's stderr, captured around one call.

pinocchio's URDF parser (urdfdom) says why it refuses a document on file descriptor 2 only and
raises a generic "The XML stream does not contain a valid URDF model". To put the cause in the
answer (robots.md section 4), the descriptor is pointed at a temporary file for the call. The
capture holds a lock (one capture at a time in the process), and whatever was written, by this
call or by another thread meanwhile, is written on to the real stderr afterwards: nothing is
lost from the server's log (:data:`ECHO`).
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import sys
import tempfile
import threading
from collections.abc import Iterator

_LOCK = threading.Lock()
ECHO: contextvars.ContextVar[bool] = contextvars.ContextVar("echo_native_stderr", default=True)
"""Whether what a capture took is written on to the real stderr afterwards (the server's log
keeps it). A command line whose own error carries the reason sets it False for its run: the
parser's lines (with its source file and line) would repeat it above the error."""


@contextlib.contextmanager
def native_stderr() -> Iterator[list[str]]:
    """Capture file descriptor 2 while the block runs.

    Yields:
        A list that holds, once the block has ended, the text written meanwhile (one item).
    """
    said: list[str] = []
    with _LOCK, tempfile.TemporaryFile() as sink:
        if sys.stderr is not None:  # None: a process started with its stderr closed
            sys.stderr.flush()
        try:
            saved = os.dup(2)
        except OSError:  # no stderr to capture (a closed descriptor): run as is
            yield said
            said.append("")
            return
        os.dup2(sink.fileno(), 2)
        try:
            yield said
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            written = sink.read()
            if written and ECHO.get():
                os.write(2, written)
            said.append(written.decode("utf-8", errors="replace"))


def first_error(text: str, *, limit: int = 100) -> str | None:
    """The first ``Error:`` line of urdfdom's output, or None when there is none.

    Its prefix and repeated spaces are dropped, and it is cut to ``limit`` characters (a request
    may carry a name of megabytes).
    """
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("Error:"):
            reason = " ".join(stripped[len("Error:") :].split())
            return reason if len(reason) <= limit else reason[:limit] + "..."
    return None
