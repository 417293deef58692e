"""The service's own log lines (``dtf.*``): the jobs' and the start's, sent to stderr once."""

from __future__ import annotations

import logging

log = logging.getLogger("dtf.jobs")
startup_log = logging.getLogger("dtf.startup")
"""The start's lines: the kernels' warm-up (its first time compiles them, about 30 s)."""


def log_to_stderr() -> None:
    """Send the service's own log lines (``dtf.*``, INFO and up) to stderr, once."""
    logger = logging.getLogger("dtf")
    if not logger.handlers:
        handler = logging.StreamHandler()
        handler.setFormatter(logging.Formatter("%(asctime)s %(name)s %(message)s"))
        logger.addHandler(handler)
        logger.setLevel(logging.INFO)
