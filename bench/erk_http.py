"""The ERK-size map through ``POST /v1/map`` against the scalar loop (issue 23's 5,000x).

Printed by ``bench/real_size.py``; kept here so that script stays one concept a module. The
map is timed on a live uvicorn (``tests/live.py``) with DTF_THREADS 1 and the default (the
cores), from two clients alternated: the standard library's ``http.client`` (the service's
figure) and httpx (the client's own work included). The scalar loop is ``bench/run.py``'s,
timed on a subset of the cells and extrapolated.
"""

from __future__ import annotations

import http.client
import json
import math
import os
import sys
from pathlib import Path
from typing import Any

import httpx

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from run import load_path, scalar_loop_seconds  # noqa: E402 - bench/run.py, beside this script
from timing import best_time, plain_post  # noqa: E402

from solver.families import get_robot  # noqa: E402
from solver.path.capability_map import grid_axis  # noqa: E402
from tests.live import start_server  # noqa: E402

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
ERK_GRID = {
    "x": {"min": -0.25, "max": 0.25, "step": 0.02},
    "y": {"min": 0.25, "max": 0.65, "step": 0.02},
    "z": 0.1,
    "yaw": 0.0,
}


def _bounds(axis: Any) -> tuple[float, float, float]:
    """An axis of ERK_GRID as grid_axis takes it: min, max, step."""
    return axis["min"], axis["max"], axis["step"]


def _map_seconds(body: dict[str, Any], threads: int | None, repeats: int) -> dict[str, float]:
    """POST /v1/map of ``body``, best of ``repeats``, on a server with DTF_THREADS ``threads``.

    From two clients, alternated: the standard library's ``http.client`` on one keep-alive
    connection with the body encoded once (the thinnest client, so the figure is the service's,
    as in ``bench/run.py``'s /v1/evaluate line), and httpx encoding the body each time (about
    1.5 ms more of its own work on this 140 kB answer).
    """
    process, url = start_server({} if threads is None else {"DTF_THREADS": str(threads)})
    raw = json.dumps(body).encode()
    try:
        connection = http.client.HTTPConnection("127.0.0.1", int(url.rsplit(":", 1)[1]))
        with httpx.Client(base_url=url, timeout=120) as client:

            def plain() -> None:
                plain_post(connection, "/v1/map", raw)

            def with_httpx() -> None:
                client.post("/v1/map", json=body).raise_for_status()

            sends = {"http.client": plain, "httpx": with_httpx}
            for send in sends.values():
                send()  # warm up
            best = dict.fromkeys(sends, math.inf)
            for _ in range(repeats):
                for name, send in sends.items():
                    best[name] = min(best[name], best_time(send, 1))
            connection.close()
            return best
    finally:
        process.terminate()
        process.wait()


def erk_map_over_http(*, repeats: int, subset: int, smoke: bool = False) -> None:
    """The ERK-size map through POST /v1/map (1 thread, all cores) against the scalar loop.

    ``smoke``: the line says its figures are a smoke run's (a scalar loop of ``subset`` cells,
    best of ``repeats``), not a measurement.
    """
    body = {"robot": {"model": "ur5"}, "path": EXAMPLE["path"], "grid": ERK_GRID}
    t_one = _map_seconds(body, 1, repeats)["http.client"]
    t_http = _map_seconds(body, None, repeats)
    robot, path = get_robot("ur5"), load_path("curved_line")
    xs, ys = (grid_axis(*_bounds(ERK_GRID[name]), field=name) for name in ("x", "y"))
    cells = len(xs) * len(ys)
    seconds = scalar_loop_seconds(
        robot, path, (xs, ys, ERK_GRID["z"]), subset=subset, repeats=1 if smoke else 3
    )
    t_scalar = seconds / subset * cells
    plain, heavy = t_http["http.client"], t_http["httpx"]
    print(
        f"ERK-size map through POST /v1/map ({cells} placements, best of {repeats}, "
        f"http.client): {plain * 1e3:.1f} ms on DTF_THREADS={os.cpu_count()} (the default), "
        f"{t_one * 1e3:.1f} ms on 1 ({t_one / plain:.2f}x); scalar loop {t_scalar:.1f} s "
        f"(extrapolated from {subset} cells): {t_scalar / plain:,.0f}x (goal >= 5,000x); "
        f"from httpx {heavy * 1e3:.1f} ms, {t_scalar / heavy:,.0f}x"
        + (
            " [smoke run: too few repeats and cells to measure; run without --smoke]"
            if smoke
            else ""
        )
    )
