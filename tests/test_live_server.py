"""A live server under load (issue 9): /healthz stays fast, a client that leaves stops its work,
SIGTERM stops the service in seconds.

Each test starts uvicorn as the README does and talks to it over real connections. Work limits
are lowered where a request at the default limit would take minutes, and the path limit to
5,000 waypoints: pydantic-core validates a body in one call that holds the GIL, 5 to 13 us a
waypoint on the development machine under load, so a 20,000-waypoint body (the default limit)
stalls /healthz once for 0.1 to 0.3 s (10,000 waypoints: 50 to 130 ms, sometimes in two parts).
"""

from __future__ import annotations

import json
import os
import signal
import socket
import statistics
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest

from tests import machine_stalls as stalls
from tests.cases import ROOT
from tests.live import start_server, stat_fields

# Response times are bounded here: scripts/run_tests.py runs these alone, after the rest.
pytestmark = pytest.mark.latency

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
N = len(EXAMPLE["path"]["waypoints"])
MAP_POSES = 8_000_000  # 2 M: the map at the limit ended in 8 probes once the kernels pruned
OPTIMIZE_WAYPOINTS = 100
PATH_WAYPOINTS = 5_000  # validating a body holds the GIL about 5-13 us a waypoint (pydantic-core)
LIMITS = {
    "DTF_MAX_PATH_WAYPOINTS": str(PATH_WAYPOINTS),
    "DTF_MAX_MAP_POSES": str(MAP_POSES),
    "DTF_MAX_MAP_CELLS": "100000",  # MAP_POSES of the README path: 60,150 cells
    "DTF_MAX_OPTIMIZE_WAYPOINTS": str(OPTIMIZE_WAYPOINTS),
    "DTF_MAX_SOLVER_SECONDS": "3",
}


def grid_of(cells: int, *, yaws: int = 1) -> dict[str, Any]:
    """A square grid of about ``cells`` placements per yaw around the ERK area."""
    side = max(int(cells**0.5), 1)
    step = 0.8 / side
    axis = {"min": -0.4, "max": -0.4 + step * (side - 1), "step": step}
    return {
        "x": axis,
        "y": {**axis, "min": 0.0, "max": step * (side - 1)},
        "z": 0.1,
        "yaw": [0.3 * k for k in range(yaws)],
    }


def line_path(n: int, spacing: float = 1e-4) -> dict[str, Any]:
    """A straight cut of ``n`` waypoints, ``spacing`` apart (m), the tool pointing down."""
    down = [1.0, 0.0, 0.0, 0.0]
    return {
        "waypoints": [{"position": [spacing * i, 0.0, 0.0], "orientation": down} for i in range(n)]
    }


def at_the_limit() -> dict[str, tuple[str, dict[str, Any]]]:
    """A request at each route's limit (this server's settings, or the default where none)."""
    robot = {"model": "ur5"}
    map_body = {"robot": robot, "path": EXAMPLE["path"], "grid": grid_of(MAP_POSES // N)}
    png_body = {**map_body, "grid": grid_of(MAP_POSES // N // 24, yaws=24)}
    long_path = line_path(PATH_WAYPOINTS, 1e-5)  # 5 cm: all of it within the arm's reach
    optimize_path = line_path(OPTIMIZE_WAYPOINTS)
    return {
        "map": ("/v1/map", map_body),
        "png": ("/v1/map/png", png_body),
        "evaluate": (
            "/v1/evaluate",
            {
                # Numeric IK on seven joints, the costliest evaluation of a path of this length
                # (the Jaco2's, about 3 s before the compiled chain, now 0.2 s: 5 probes): the
                # body's validation, which holds the GIL, is then one /healthz probe of dozens.
                # A UR arm's evaluation took 0.6 s, 15 probes: the p90 was the second worst, and
                # the validation, cut in two by a garbage collection, was two.
                "robot": {"model": "panda"},
                "path": long_path,
                "placement": EXAMPLE["placement"],
            },
        ),
        "optimize": (
            "/v1/optimize",
            {
                "robot": robot,
                "path": optimize_path,
                "bounds": {"x": [-0.3, 0.3], "y": [0.3, 0.6], "yaw": [-3.14, 3.14]},
                "z": 0.1,
                "method": "scipy",
            },
        ),
    }


@pytest.fixture(scope="module")
def server() -> Iterator[tuple[Any, str]]:
    process, url = start_server(LIMITS, "--timeout-graceful-shutdown", "2")
    yield process, url
    process.kill()
    process.wait()


def _post(url: str, route: str, body: dict[str, Any], answers: list[int]) -> None:
    answers.append(httpx.post(url + route, json=body, timeout=120).status_code)


@pytest.mark.parametrize("name", ["map", "png", "evaluate", "optimize"])
def test_healthz_stays_fast_while_a_request_at_the_limit_runs(
    server: tuple[Any, str], name: str
) -> None:
    _, url = server
    route, body = at_the_limit()[name]
    answers: list[int] = []
    work = threading.Thread(target=_post, args=(url, route, body, answers))
    posted = stalls.now()
    work.start()
    probes = []
    with stalls.MachineStalls() as machine, httpx.Client(base_url=url) as client:
        while work.is_alive():
            began = stalls.now()
            assert client.get("/healthz").status_code == 200
            probes.append((began, stalls.now()))
            time.sleep(0.02)
        ended = stalls.now()
    work.join()
    assert answers == [200]  # the request at the limit is accepted and answered
    assert len(probes) >= 10, "the request ended before /healthz could be measured"
    # Each probe less the machine's stalls it overlapped (tests/machine_stalls.py: after the
    # suite's minutes of load the host takes a CPU away for about 100 ms at times while both
    # CPUs are busy); the server's own blocking stays in.
    latencies = sorted(machine.less_stalls(start, end) for start, end in probes)
    said = _probes_said(probes, machine, posted, ended)
    assert statistics.median(latencies) < 0.010, said
    assert latencies[int(0.9 * len(latencies))] < 0.050, said


def _probes_said(
    probes: list[tuple[float, float]], machine: stalls.MachineStalls, posted: float, ended: float
) -> str:
    """A failure's figures, short enough that pytest prints them whole (a CI log cut the lists
    of every probe, stop 71): the slowest probes, when each began after the request was sent,
    and the machine's stalls."""
    slowest = sorted(probes, key=lambda p: machine.less_stalls(*p), reverse=True)[:6]
    each = ", ".join(
        f"{1e3 * machine.less_stalls(start, end):.0f} ms ({1e3 * (end - start):.0f} raw) at "
        f"{start - posted:.2f} s"
        for start, end in slowest
    )
    return (
        f"{len(probes)} probes while the request ran {ended - posted:.2f} s; slowest: {each}; "
        f"the machine's stalls: {len(machine.stalls)}, {1e3 * machine.total:.0f} ms in all"
    )


def _cpu_seconds(pid: int) -> float:
    """User + system CPU time of a process so far (s), from /proc."""
    fields = stat_fields(Path("/proc") / str(pid) / "stat")
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


LONG_WAYPOINTS = 4_000
"""The cut of :func:`long_map`: a longer path is more work for the same placements (the map's
answer stays small)."""


def long_map(pairs: int) -> dict[str, Any]:
    """A UR5 map of about ``pairs`` placement-waypoint pairs along a 4,000-waypoint cut.

    Its time must outlast each test's window whatever the machine, and the kernels keep getting
    faster: 20 million pairs took 3.9 s on 2 threads on a fast day of 2026-11; on 2026-12-04 40
    million took about 1.3 s, and once answered before the SIGTERM test's signal at 1 s. About
    60 ns a pair on one thread that day: 80 million pairs about 2.5 s on 2 threads, 160 million
    about 5 s. (A map at the shared server's limit, 2 million, took under 0.5 s, and ended
    before the client left.)
    """
    cut = line_path(LONG_WAYPOINTS, 2.5e-5)  # 10 cm, as the 1,000-waypoint cut was
    return {"robot": {"model": "ur5"}, "path": cut, "grid": grid_of(pairs // LONG_WAYPOINTS)}


def test_a_client_that_leaves_stops_its_work() -> None:
    """And /metrics counts it as the client's doing (4xx), as a body its client left: both were
    counted 5xx, every impatient client raising the server-error rate (stop 61's soak audit)."""
    process, url = start_server({"DTF_MAX_MAP_POSES": "80000000"})
    try:
        with pytest.raises(httpx.ReadTimeout):
            httpx.post(url + "/v1/map", json=long_map(80_000_000), timeout=0.5)  # left at 0.5 s
        time.sleep(0.5)
        before = _cpu_seconds(process.pid)
        time.sleep(1.0)
        assert _cpu_seconds(process.pid) - before < 0.2  # idle: the map stopped
        port = int(url.rsplit(":", 1)[1])
        with socket.create_connection(("127.0.0.1", port)) as half:  # 100 of 1,000 bytes
            head = "POST /v1/evaluate HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
            half.sendall((head + "Content-Length: 1000\r\n\r\n" + "{" * 100).encode())
            time.sleep(0.3)
        time.sleep(0.5)
        counted = {
            line.split("{", 1)[1].split("}", 1)[0]: float(line.rsplit(" ", 1)[1])
            for line in httpx.get(url + "/metrics").text.splitlines()
            if line.startswith("http_requests_total{")
        }
        assert counted['handler="/v1/map",method="POST",status="4xx"'] == 1.0
        assert counted['handler="/v1/evaluate",method="POST",status="4xx"'] == 1.0
        assert not [labels for labels in counted if 'status="5xx"' in labels], counted
    finally:
        process.kill()
        process.wait()


# The evaluate that the client leaves: it leaves LEAVES_AT s after sending, the server must be
# idle STOPS_WITHIN s later, and the work must be known to last LONG_ENOUGH s uncancelled.
LEAVES_AT, STOPS_WITHIN = 1.5, 1.0
LONG_ENOUGH = LEAVES_AT + STOPS_WITHIN + 1.0 + 0.5


def _busy(pid: int, seconds: float) -> float:
    """The fraction of ``seconds`` in which a thread of the process is running or runnable.

    A thread waiting for a core on a busy machine is still counted (state R), so this tells
    computing from idle whatever the load, which CPU time does not.
    """
    samples, busy = 0, 0
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        states = []
        for task in (Path("/proc") / str(pid) / "task").iterdir():
            try:
                states.append(stat_fields(task / "stat")[0])
            except OSError:
                continue  # the thread ended meanwhile
        samples, busy = samples + 1, busy + ("R" in states)
        time.sleep(0.02)
    return busy / max(samples, 1)


def _guarded_cut(n: int) -> dict[str, Any]:
    """An xArm7 evaluation of a 5 cm cut of ``n`` waypoints, free spin, in a cell it never touches.

    Numeric IK on seven joints with the spin's three-variable LP at every waypoint (it reports
    as it goes, so a client that leaves stops the work: run_stoppable), then the cell's check
    against 24 boxes far away (there to be checked: the evaluation runs to the path's end;
    since the closest-pair check skips what cannot come nearer, they cost little).
    """
    boxes = [
        {
            "shape": "box",
            "name": f"far {k}",
            "size": [0.1, 0.1, 0.1],
            "pose": {"position": [3.0 + 0.2 * k, 3.0, 3.0], "orientation": [0, 0, 0, 1]},
        }
        for k in range(24)
    ]
    return {
        "robot": {"model": "xarm7"},
        "path": line_path(n, 0.05 / n),
        "placement": EXAMPLE["placement"],
        "spin_mode": "free",
        "cell": {"fixed": boxes},
    }


def test_an_evaluate_whose_client_leaves_stops_within_a_second() -> None:
    # The work is known to outlast the window: the whole path, run to its end on the same
    # server first, takes LONG_ENOUGH or more, so it would keep the server busy past the window
    # (1.5 s to 3.5 s after the request) had the client's leaving not stopped it; a test that
    # cannot tell a stop from an end says so instead of passing. 6,000 waypoints: about 11 s
    # over HTTP on the development machine with its other core busy (2026-12-06); the 20,000
    # this test sent took about 5.8 s in process on 2026-12-04, and 40 to 60 s since free spin
    # solves the spun poses (6d167b3), most of the latency run. (The Panda in fixed spin took
    # 7 s until the closest-pair check skipped the far boxes, then 3.2 s, under LONG_ENOUGH;
    # in free spin 4.3 s, too near it.)
    # The idle server is not quite still (the job supervisor looks at its store every 50 ms).
    process, url = start_server({"DTF_MAX_MAP_POSES": "1000000000"})
    full = _guarded_cut(6_000)
    errors: list[Exception] = []

    def leaves() -> None:
        try:
            httpx.post(url + "/v1/evaluate", json=full, timeout=LEAVES_AT)
        except httpx.ReadTimeout as error:
            errors.append(error)

    try:
        began = time.monotonic()
        whole = httpx.post(url + "/v1/evaluate", json=full, timeout=300)
        whole_seconds = time.monotonic() - began
        assert whole.status_code == 200 and whole.json()["feasible"]
        assert whole_seconds >= LONG_ENOUGH, "the work may end by itself within the window"
        client = threading.Thread(target=leaves)
        client.start()
        time.sleep(LEAVES_AT - 0.6)
        working = _busy(process.pid, 0.5)
        client.join()
        assert len(errors) == 1  # the client left before an answer
        time.sleep(STOPS_WITHIN - 0.1)
        assert working > 0.8  # the evaluation ran before the client left
        assert _busy(process.pid, 1.0) < 0.5  # and had stopped a second after
    finally:
        process.kill()
        process.wait()


def test_sigterm_stops_the_service_within_seconds() -> None:
    process, url = start_server(
        {"DTF_MAX_MAP_POSES": "160000000"}, "--timeout-graceful-shutdown", "2"
    )
    answers: list[int] = []
    work = threading.Thread(target=_post, args=(url, "/v1/map", long_map(160_000_000), answers))
    work.start()  # about 5 s of work on a fast day: still running at the signal
    time.sleep(1.0)
    process.send_signal(signal.SIGTERM)
    began = time.monotonic()
    process.wait(timeout=30)
    work.join()
    assert time.monotonic() - began < 5.0
    assert answers in ([503], [])  # told to retry, or the connection closed
