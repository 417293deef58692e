"""Where a request's time goes besides its work: the round trip through HTTP (issue 23).

Run from the repository root::

    python bench/round_trip.py            # about a minute
    python bench/round_trip.py --smoke    # few repeats, to check that the script runs

Against a live uvicorn (``tests/live.py``), all in the same run, alternated, best (and median)
of N:

- ``GET /healthz`` through httpx (what ``bench/real_size.py`` uses), through the standard
  library's ``http.client`` (a lighter client), and through the app alone, called as an ASGI
  callable in this process (no socket, no HTTP parser);
- the ERK-size map (``POST /v1/map``, 546 placements) through both clients, against the same
  work in this process (the body's validation, the map, the JSON answer) on as many threads:
  the difference is what HTTP costs the map, client included.
"""

from __future__ import annotations

import argparse
import asyncio
import gc
import http.client
import json
import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import httpx

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from erk_http import ERK_GRID, EXAMPLE  # noqa: E402 - bench/erk_http.py, beside this

from service.config import Settings  # noqa: E402
from service.operations.map import computed_map  # noqa: E402
from service.schemas import MapRequest  # noqa: E402
from solver.core.parallel import ThreadRunner  # noqa: E402
from tests.live import start_server  # noqa: E402


def _asgi_get(path: str) -> Callable[[], None]:
    """A GET of ``path`` through the app as an ASGI callable, in this process."""
    from service.main import app

    scope = {
        "type": "http",
        "asgi": {"version": "3.0"},
        "http_version": "1.1",
        "method": "GET",
        "scheme": "http",
        "path": path,
        "raw_path": path.encode(),
        "query_string": b"",
        "root_path": "",
        "headers": [(b"host", b"bench")],
        "client": ("127.0.0.1", 1),
        "server": ("127.0.0.1", 2),
    }
    loop = asyncio.new_event_loop()

    async def receive() -> dict[str, Any]:
        return {"type": "http.request", "body": b"", "more_body": False}

    async def send(message: dict[str, Any]) -> None:
        pass

    return lambda: loop.run_until_complete(app({**scope, "state": {}}, receive, send))


def _times(runs: dict[str, Callable[[], object]], repeats: int) -> dict[str, list[float]]:
    """Each run ``repeats`` times, the runs alternated (s)."""
    for run in runs.values():
        run()  # warm up
    gc.collect()
    gc.freeze()  # as the service does after its start: no full collection walks the imports
    times: dict[str, list[float]] = {name: [] for name in runs}
    for _ in range(repeats):
        for name, run in runs.items():
            began = time.perf_counter()
            run()
            times[name].append(time.perf_counter() - began)
    return times


def round_trips(*, repeats: int) -> None:
    """Print the round trips of /healthz and of the ERK-size map, by client and in process."""
    body = {"robot": {"model": "ur5"}, "path": EXAMPLE["path"], "grid": ERK_GRID}
    raw = json.dumps(body).encode()
    settings = Settings()
    process, url = start_server({})
    try:
        connection = http.client.HTTPConnection("127.0.0.1", int(url.rsplit(":", 1)[1]))

        def stdlib(method: str, path: str, content: bytes | None = None) -> None:
            headers = {"content-type": "application/json"} if content else {}
            connection.request(method, path, content, headers)
            connection.getresponse().read()

        def in_process() -> None:
            request = MapRequest.model_validate_json(raw)
            runner = ThreadRunner(settings.threads)
            computed = computed_map(
                request, settings, png=False, progress=lambda _: None, runner=runner
            )
            computed.answer_json()

        with httpx.Client(base_url=url, timeout=120) as client:
            healthz = _times(
                {
                    "httpx": lambda: client.get("/healthz"),
                    "http.client": lambda: stdlib("GET", "/healthz"),
                    "the app alone (ASGI, in process)": _asgi_get("/healthz"),
                },
                10 * repeats,
            )
            maps = _times(
                {
                    "httpx": lambda: client.post("/v1/map", json=body).raise_for_status(),
                    "http.client": lambda: stdlib("POST", "/v1/map", raw),
                    f"in process ({settings.threads} threads)": in_process,
                },
                repeats,
            )
    finally:
        process.terminate()
        process.wait()
    print(
        f"GET /healthz (p50, best of {10 * repeats}): "
        + ", ".join(
            f"{name} {statistics.median(t) * 1e3:.2f} ms ({min(t) * 1e3:.2f})"
            for name, t in healthz.items()
        )
    )
    print(
        f"ERK-size map POST /v1/map (best, p50 of {repeats}; DTF_THREADS={settings.threads}, "
        f"{os.cpu_count()} cores): "
        + ", ".join(
            f"{name} {min(t) * 1e3:.2f} ms ({statistics.median(t) * 1e3:.2f})"
            for name, t in maps.items()
        )
    )


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="few repeats: check the script runs")
    args = parser.parse_args()
    round_trips(repeats=3 if args.smoke else 30)


if __name__ == "__main__":
    main()
