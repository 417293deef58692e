"""The service's own log lines (``dtf.*``), sent to stderr once.

The jobs', the start's, and the requests' refused (:mod:`service.refusals`) or left by their
client before the answer.
"""

from __future__ import annotations

import logging

log = logging.getLogger("dtf.jobs")
startup_log = logging.getLogger("dtf.startup")
"""The start's lines: the kernels' warm-up (its first time compiles them, about 30 s)."""
request_log = logging.getLogger("dtf.requests")
"""Requests refused, with their answer's first detail (uvicorn's access line has the status
alone), and requests whose client left before the answer (uvicorn writes no line for them)."""


FORMAT = "%(asctime)s %(levelname)s %(name)s %(message)s"
"""The lines' form where no logging configuration of the operator's places them."""


def log_to_stderr() -> None:
    """Send the service's own log lines (``dtf.*``, INFO and up) to stderr, once.

    Unless logging is configured already (``uvicorn --log-config`` of a file that gives the
    root logger a handler, or ``dtf`` one): the lines then go where that configuration sends
    them, in its form and at its levels. A handler of their own besides wrote each line twice
    there, one copy without a level, and INFO whatever the configuration said (the operator
    audit of 2026-12-07, M3). Each line says its level (``WARNING``, ``ERROR``).
    """
    logger = logging.getLogger("dtf")
    if logger.handlers or logging.getLogger().handlers:
        return
    handler = logging.StreamHandler()
    handler.setFormatter(logging.Formatter(FORMAT))
    logger.addHandler(handler)
    logger.setLevel(logging.INFO)


def duration(seconds: float) -> str:
    """A length of time as a person reads it: ``7 days``, ``3 h``, ``45 min``, ``7 s``."""
    if seconds >= 86400.0:
        days = f"{seconds / 86400.0:.3g}"
        return f"{days} day" if days == "1" else f"{days} days"
    for unit, size in (("h", 3600.0), ("min", 60.0)):
        if seconds >= size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.3g} s"
