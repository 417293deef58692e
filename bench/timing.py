"""The benchmark's one timing rule: the fastest of a few runs (the machine's noise is upward).

And the thinnest client's request (:func:`plain_post`), timed beside httpx's by the HTTP lines;
and where a run's time goes (:func:`phase_seconds`), so that a goal's line says which part of
the work stands between it and the goal.
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


def phase_seconds(
    run: Callable[[], object], phases: dict[str, tuple[object, str]]
) -> dict[str, float]:
    """Seconds one ``run()`` spends in each phase, and in the rest (``"rest"``).

    A phase is a function its callers look up where it is defined at each call (a module's
    ``module.name(...)`` or module-level name, or a class's method): it is wrapped with a clock
    for the run and put back after. The functions named are called at most a few thousand times
    a map, so the clocks cost nothing the figures could show.
    """
    spent = dict.fromkeys(phases, 0.0)
    originals = {label: getattr(module, name) for label, (module, name) in phases.items()}

    def clocked(label: str, function: Callable[..., object]) -> Callable[..., object]:
        def timed(*args: object, **kwargs: object) -> object:
            start = time.perf_counter()
            try:
                return function(*args, **kwargs)
            finally:
                spent[label] += time.perf_counter() - start

        return timed

    for label, (module, name) in phases.items():
        setattr(module, name, clocked(label, originals[label]))
    try:
        start = time.perf_counter()
        run()
        total = time.perf_counter() - start
    finally:
        for label, (module, name) in phases.items():
            setattr(module, name, originals[label])
    return {**spent, "rest": total - sum(spent.values())}


def phase_text(seconds: dict[str, float]) -> str:
    """``seconds`` (:func:`phase_seconds`) as "label 12.3 ms, ..." in their order."""
    return ", ".join(f"{label} {value * 1e3:.1f} ms" for label, value in seconds.items())
