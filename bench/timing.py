"""The benchmark's one timing rule: the fastest of a few runs (the machine's noise is upward).

And the thinnest client's request (:func:`plain_post`), timed beside httpx's by the HTTP lines.
"""

from __future__ import annotations

import http.client
import time
from collections.abc import Callable


def best_time(run: Callable[[], object], repeats: int) -> float:
    """The fastest of ``repeats`` runs (s)."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return min(times)


def plain_post(connection: http.client.HTTPConnection, path: str, body: bytes) -> None:
    """POST a JSON ``body`` to ``path`` with the standard library's client, its answer read.

    Raises:
        RuntimeError: the answer is not a 200.
    """
    connection.request("POST", path, body=body, headers={"Content-Type": "application/json"})
    answer = connection.getresponse()
    answer.read()
    if answer.status != 200:
        raise RuntimeError(f"{path} answered {answer.status}")
