"""Benchmark of the service at real size: prints figures, asserts nothing (issue 23).

Run from the repository root::

    python bench/real_size.py           # about two minutes
    python bench/real_size.py --smoke   # small sizes, to check that the script runs

Each figure is taken against a live uvicorn (``tests/live.py``), with its baseline in the same
run:

- the ERK-size map (UR5, 546 placements, 133 waypoints) through ``POST /v1/map`` on all cores
  (DTF_THREADS, default the cores) and on one, from ``http.client`` and from httpx, against
  the scalar loop of ``bench/run.py`` (timed on a subset and extrapolated), and where its time
  goes in the route (in process: validation, the map, the response's cells, its JSON);
- ``GET /v1/jobs?limit=1000`` with 50 large map jobs stored, against reading and parsing their
  results as the listing did before (``SELECT *`` and ``json.loads`` of every result), and
  ``GET /v1/jobs/{id}`` and one page of cells of one of them;
- a 386,163-cell map job's answer stored from the map's columns in pages, against a model a
  cell dumped and written (the job's way before), after the same placements; its picture
  drawn from the stored cells (``GET /v1/jobs/{id}/png``) against the computed map drawn;
- the scipy method on 5,000- and 10,487-move programs (its differential evolution on sets of
  the waypoints), and on a 2,000-move one against the whole-path evolution;
- the cycle time of a 10,487-move program under acceleration limits, its TOPP-RA compiled
  against toppra on the same grids (``bench/cycle_time.py``);
- ``/healthz`` every 20 ms while the largest body (20,000 waypoints, DTF_MAX_PATH_WAYPOINTS)
  is read, validated and computed: a UR5 evaluation to its end, and a Panda evaluation (numeric
  IK, a minute of work) for its first seconds, after which the client leaves.
"""

from __future__ import annotations

import argparse
import json
import sqlite3
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import httpx

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from active_set import _line, _optimised  # noqa: E402 - bench/active_set.py, beside this
from cycle_time import cycle_time_lines  # noqa: E402 - bench/cycle_time.py
from erk_http import ERK_GRID, EXAMPLE, erk_map_over_http  # noqa: E402 - bench/erk_http.py
from timing import best_time  # noqa: E402

from service.config import Settings  # noqa: E402
from service.convert.stored_map import stored_map  # noqa: E402
from service.jobs.store import JobStore  # noqa: E402
from service.jobs.worker import _map  # noqa: E402
from service.operations.map import ComputedMap, computed_map, map_png  # noqa: E402
from service.schemas import MapRequest  # noqa: E402
from solver.core.parallel import ThreadRunner  # noqa: E402
from tests.live import start_server  # noqa: E402


def erk_route_parts(*, repeats: int) -> None:
    """Where the ERK-size map's time goes in the route, in this process (no HTTP).

    The body's validation, the map on one thread and on DTF_THREADS, the response's cells, its
    JSON (the model's way), and the same body written from the columns (the route's way).
    """
    body = {"robot": {"model": "ur5"}, "path": EXAMPLE["path"], "grid": ERK_GRID}
    raw = json.dumps(body).encode()
    request = MapRequest.model_validate_json(raw)
    settings = Settings()

    def computed(threads: int) -> ComputedMap:
        runner = ThreadRunner(threads)
        return computed_map(request, settings, png=False, progress=lambda _: None, runner=runner)

    answer = computed(settings.threads)
    response = answer.answer()
    parts = {
        "validation": best_time(lambda: MapRequest.model_validate_json(raw), repeats),
        "map on 1 thread": best_time(lambda: computed(1), repeats),
        f"map on {settings.threads}": best_time(lambda: computed(settings.threads), repeats),
        "response cells": best_time(answer.answer, 10),
        "JSON": best_time(response.model_dump_json, repeats),
        "written body (cells and JSON, what the route does)": best_time(
            answer.answer_json, repeats
        ),
    }
    print(
        "  in the route (in process, best of "
        f"{repeats}): " + ", ".join(f"{name} {t * 1e3:.2f} ms" for name, t in parts.items())
    )


def _cells(n: int) -> list[dict[str, Any]]:
    """``n`` map cells as POST /v1/map answers them (about 220 bytes each)."""
    return [
        {
            "x": -0.5 + 0.001 * (i % 1000),
            "y": 0.001 * (i // 1000),
            "yaw": 0.0,
            "spin": 0.0,
            "mu_path": 0.2 + 1e-7 * i,
            "reason": None,
            "failed_waypoint": None,
            "bottleneck_waypoint": i % 133,
            "bottleneck_joint": i % 6,
            "branch": {"shoulder": "left", "elbow": "up", "wrist": "noflip"},
            "mu_acc": None,
            "limited_by": None,
        }
        for i in range(n)
    ]


def job_listing(*, jobs: int, cells: int) -> None:
    """GET /v1/jobs with ``jobs`` done map jobs of ``cells`` cells each stored."""
    with tempfile.TemporaryDirectory() as data:
        store = JobStore(Path(data) / "jobs.sqlite3")
        result = {"cells": _cells(cells), "best": None, "worst": None, "feasible_cells": cells}
        ids = []
        for _ in range(jobs):
            job = store.create("map", {"grid": "not read"}, total=cells)
            store.start(job.id)
            store.finish(job.id, "done", result=result)
            ids.append(job.id)

        def as_before() -> None:  # the listing before: every row read, every result parsed
            with sqlite3.connect(store.path) as db:
                for row in db.execute("SELECT * FROM jobs ORDER BY created DESC LIMIT 1000"):
                    json.loads(row[4])
                for row in db.execute("SELECT cells FROM job_cells"):
                    json.loads(row[0])

        t_before = best_time(as_before, 3)
        process, url = start_server({"DTF_DATA_DIR": data, "DTF_WORKERS": "1"})
        try:
            with httpx.Client(base_url=url, timeout=120) as client:
                client.get("/v1/jobs")  # warm up
                listing = [client.get("/v1/jobs", params={"limit": 1000}) for _ in range(20)]
                took = [a.elapsed.total_seconds() for a in listing]
                one = client.get(f"/v1/jobs/{ids[0]}")
                page = client.get(f"/v1/jobs/{ids[0]}/result", params={"offset": cells // 2})
        finally:
            process.terminate()
            process.wait()
    print(
        f"GET /v1/jobs?limit=1000 with {jobs} map jobs of {cells:,} cells stored: "
        f"p50 {statistics.median(took) * 1e3:.1f} ms, max {max(took) * 1e3:.1f} ms, "
        f"{len(listing[0].content):,} bytes; reading and parsing their results as before: "
        f"{t_before:.2f} s ({t_before / statistics.median(took):,.0f}x)"
    )
    print(
        f"  GET /v1/jobs/{{id}} of one: {one.elapsed.total_seconds() * 1e3:.1f} ms, "
        f"{len(one.content):,} bytes "
        f"({'with' if one.json()['result_cells']['in_result'] else 'without'} its cells); "
        "a page of "
        f"{len(page.json()['cells']):,} cells: {page.elapsed.total_seconds() * 1e3:.1f} ms, "
        f"{len(page.content):,} bytes"
    )


def map_job_storing(*, step: float) -> None:
    """A large map job's answer written to the store, two ways, after the same placements.

    From the map's columns a page at a time (service.jobs.worker._map, the job's way) against a
    model a cell, dumped and written (its way before), in this process.
    """
    grid = {
        "x": {"min": -0.5, "max": 0.5, "step": step},
        "y": {"min": 0.0, "max": 0.8, "step": step},
        "z": 0.1,
        "yaw": [0.0, 1.0, 2.0],
    }
    request = {"robot": {"model": "ur5"}, "path": EXAMPLE["path"], "grid": grid}
    settings = Settings().for_jobs()
    runner = ThreadRunner(settings.threads)
    with tempfile.TemporaryDirectory() as data:
        store = JobStore(Path(data) / "jobs.sqlite3")

        def stored(result: Any) -> float:
            job = store.create("map", request, total=1)
            store.start(job.id)
            began = time.perf_counter()
            store.finish(job.id, "done", result=result)
            ids.append(job.id)
            return time.perf_counter() - began

        ids: list[str] = []

        began = time.perf_counter()
        computed = computed_map(
            MapRequest.model_validate(request), settings, png=False,
            progress=lambda _: None, runner=runner,
        )  # fmt: skip
        placements = time.perf_counter() - began
        began = time.perf_counter()
        dumped = computed.answer()
        before = time.perf_counter() - began
        before += stored(dumped.model_dump(mode="json"))
        del dumped
        paged = _map(request, settings, lambda _: None, runner)  # its pages made as stored
        now = stored(paged)
        # GET /v1/jobs/{id}/png's work: the stored cells read back, then drawn; the map drawn
        # from its computed columns, the baseline
        body = MapRequest.model_validate(request)
        began = time.perf_counter()
        read = stored_map(body, computed.robot, store.cell_pages(ids[-1]))
        reading = time.perf_counter() - began
        map_png(read, computed.robot)  # the figure made and kept, as a serving process keeps it
        drawing = best_time(lambda: map_png(read, computed.robot), 1)
        direct = best_time(lambda: map_png(computed.result, computed.robot), 1)
    cells = computed.result.mu_path.size
    print(
        f"a {cells:,}-cell map job: placements {placements:.2f} s; its answer stored in "
        f"{now:.2f} s from the columns in pages, {before:.2f} s as a model a cell "
        f"({before / now:.1f}x); its picture (GET /v1/jobs/{{id}}/png): the stored cells read "
        f"in {reading:.2f} s ({reading / cells * 1e6:.2f} us a cell), drawn in {drawing:.2f} s; "
        f"the computed map drawn in {direct:.2f} s"
    )


def line_path(n: int, spacing: float) -> dict[str, Any]:
    """A straight cut of ``n`` waypoints, ``spacing`` apart (m), the tool pointing down."""
    down = [1.0, 0.0, 0.0, 0.0]
    return {
        "waypoints": [{"position": [spacing * i, 0.0, 0.0], "orientation": down} for i in range(n)]
    }


def _healthz_during(url: str, body: dict[str, Any], *, leave_after: float) -> list[float]:
    """/healthz latencies (s), one every 20 ms, while POST /v1/evaluate of ``body`` runs."""
    finished = threading.Event()

    def post() -> None:
        try:
            httpx.post(url + "/v1/evaluate", json=body, timeout=leave_after)
        except httpx.ReadTimeout:
            pass  # the client left; the service stops the work
        finished.set()

    work = threading.Thread(target=post)
    work.start()
    latencies = []
    with httpx.Client(base_url=url) as client:
        while not finished.is_set():
            began = time.perf_counter()
            client.get("/healthz")
            latencies.append(time.perf_counter() - began)
            time.sleep(0.02)
    work.join()
    return latencies


def healthz_during_the_largest_body(*, waypoints: int) -> None:
    """/healthz p50, p90 and max while a body of ``waypoints`` waypoints is evaluated."""
    process, url = start_server({})
    try:
        for model, leave_after in (("ur5", 120.0), ("panda", 8.0)):
            body = {
                "robot": {"model": model},
                "path": line_path(waypoints, 2.5e-6),
                "placement": EXAMPLE["placement"],
            }
            size = len(json.dumps(body))
            leaves = f", client leaves at {leave_after:g} s" if model == "panda" else ""
            latencies = sorted(_healthz_during(url, body, leave_after=leave_after))
            p90 = latencies[int(0.9 * len(latencies))]
            print(
                f"/healthz during POST /v1/evaluate of {waypoints:,} waypoints ({model}, "
                f"{size / 1e6:.2f} MB body{leaves}): "
                f"p50 {statistics.median(latencies) * 1e3:.1f} ms, p90 {p90 * 1e3:.1f} ms "
                f"(goal < 50 ms), max {latencies[-1] * 1e3:.1f} ms, {len(latencies)} probes"
            )
    finally:
        process.terminate()
        process.wait()


def scipy_on_sets(*, smoke: bool) -> None:
    """The scipy method on long programs (its evolutions on sets), and against the whole path.

    As ``bench/active_set.py`` optimises (UR5e, x -0.4..0.2 m, y 0.2..0.6 m, any yaw, free
    spin, two threads), with the service's DTF_MAX_SEARCH_POSES; the baseline, same run: the
    whole-path differential evolution (``active_set=False``, its limit lifted) on a program
    just over MAX_SEARCH_ROWS.
    """
    _optimised(200, method="scipy")  # the kernels and the catalogue load outside the figures
    print("scipy on long programs (evolutions on sets of the waypoints):")
    for moves in (1_500,) if smoke else (5_000, 10_487):
        read, seconds, optimum = _optimised(moves, method="scipy")
        print(_line("synthetic NX-like program", moves, read, seconds, optimum))
    moves = 1_100 if smoke else 2_000
    _, whole_seconds, whole = _optimised(moves, method="scipy", active_set=False)
    _, seconds, optimum = _optimised(moves, method="scipy")
    print(_line("whole-path DE", moves, None, whole_seconds, whole))
    print(_line("DE on sets   ", moves, None, seconds, optimum))
    if whole.mu_path is not None and optimum.mu_path is not None:
        print(
            f"  on sets / whole path: {seconds / whole_seconds:.2f}x the time, mu_path "
            f"relative difference {abs(optimum.mu_path / whole.mu_path - 1):.1e}"
        )


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="small sizes: check the script runs")
    args = parser.parse_args()
    erk_map_over_http(
        repeats=2 if args.smoke else 10, subset=2 if args.smoke else 12, smoke=args.smoke
    )
    erk_route_parts(repeats=2 if args.smoke else 10)
    job_listing(jobs=5 if args.smoke else 50, cells=2_000 if args.smoke else 20_000)
    map_job_storing(step=0.05 if args.smoke else 0.0025)
    healthz_during_the_largest_body(waypoints=2_000 if args.smoke else 20_000)
    scipy_on_sets(smoke=args.smoke)
    cycle_time_lines(smoke=args.smoke)


if __name__ == "__main__":
    main()
