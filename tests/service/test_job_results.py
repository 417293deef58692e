"""A job's result in pages: listings read no result, a page equals the map route's cells."""

from __future__ import annotations

import json
import sqlite3
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from service.config import Settings
from service.jobs.job import DamagedJob
from service.jobs.results import CellPages
from service.jobs.store import JobStore
from service.jobs.worker import _map
from solver.core.parallel import SERIAL
from tests.cases import ROOT
from tests.service.conftest import served_with

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
SHORT_PATH = {"waypoints": EXAMPLE["path"]["waypoints"][:20]}
GRID_2500 = {  # 50 x 25 x 2 = 2,500 placements: three stored pages of 1,000 cells
    "x": {"min": -0.4, "max": 0.09, "step": 0.01},
    "y": {"min": 0.3, "max": 0.54, "step": 0.01},
    "z": 0.1,
    "yaw": [0.0, 0.5],
}
CELLS = [{"x": float(i), "y": 0.5, "yaw": 0.0, "mu_path": i / 7.0} for i in range(2500)]


def corrupt(path: Path, column: str, job_id: str) -> None:
    """Write text that is not JSON into a job's ``column``: reading it would fail."""
    with sqlite3.connect(path) as db:
        db.execute(f"UPDATE jobs SET {column} = '{{not json' WHERE id = ?", (job_id,))


def test_a_listing_reads_no_request_and_no_result(tmp_path: Path) -> None:
    path = tmp_path / "jobs.sqlite3"
    store = JobStore(path)
    job = store.create("map", {"grid": "..."}, total=2500)
    store.start(job.id)
    store.finish(job.id, "done", result={"cells": CELLS, "feasible_cells": 2500})
    corrupt(path, "request", job.id)
    corrupt(path, "result", job.id)
    (listed,) = store.jobs(status=None, limit=10)
    assert (listed.id, listed.status, listed.total, listed.cells) == (job.id, "done", 2500, 2500)
    assert not hasattr(listed, "result") and not hasattr(listed, "request")
    with pytest.raises(DamagedJob):  # what a listing that read them would meet
        store.get(job.id)


@pytest.mark.parametrize(
    ("offset", "limit"),
    [(0, 1000), (999, 2), (1500, 1000), (0, 2500), (1000, 1500), (2400, 500), (2500, 10)],
)
def test_a_page_is_the_same_cells_of_the_result(tmp_path: Path, offset: int, limit: int) -> None:
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("map", {}, total=2500)
    store.start(job.id)
    store.finish(job.id, "done", result={"cells": CELLS, "feasible_cells": 2500})
    assert store.cells(job.id, offset=offset, limit=limit) == CELLS[offset : offset + limit]
    text, count = store.cells_json(job.id, offset=offset, limit=limit)
    assert json.loads(text) == CELLS[offset : offset + limit] and count == len(json.loads(text))
    small, whole = store.get(job.id, inline_cells=2499), store.get(job.id)
    assert small is not None and small.result == {"feasible_cells": 2500}
    assert whole is not None and whole.result == {"cells": CELLS, "feasible_cells": 2500}
    store.delete(job.id)
    assert store.cells(job.id, offset=0, limit=10) == []


@pytest.fixture
def paged_store(tmp_path: Path) -> Iterator[Settings]:
    """The app with its jobs in ``tmp_path``, pages of 1,000 cells, room for a 2,500-cell map."""
    settings = Settings(
        data_dir=tmp_path,
        workers=1,
        job_page_cells=1000,
        max_job_cells=2500,
        max_job_poses=50_000,
    )
    with served_with(settings):
        yield settings


def done_job(client: TestClient, job_id: str) -> dict[str, Any]:
    deadline = time.monotonic() + 120
    while True:
        job: dict[str, Any] = client.get(f"/v1/jobs/{job_id}").json()
        if job["status"] not in ("queued", "running") or time.monotonic() > deadline:
            return job
        time.sleep(0.1)


def test_a_map_job_pages_equal_the_map_routes_cells(
    client: TestClient, paged_store: Settings
) -> None:
    request = {"robot": EXAMPLE["robot"], "path": SHORT_PATH, "grid": GRID_2500}
    submitted = client.post("/v1/jobs", json={"kind": "map", "request": request})
    assert submitted.status_code == 202, submitted.text
    job_id = submitted.json()["id"]
    early = client.get(f"/v1/jobs/{job_id}/result")
    job = done_job(client, job_id)
    assert job["status"] == "done", job
    if early.json().get("cells") is None:  # asked while queued or running
        assert early.status_code == 409 and "no result to page" in early.json()["detail"][0]["msg"]
    direct = client.post("/v1/map", json=request)
    assert direct.status_code == 200, direct.text
    expected = direct.json()
    assert "cells" not in job["result"]
    assert job["result"] == {k: v for k, v in expected.items() if k != "cells"}
    assert job["result_cells"] == {
        "total": 2500,
        "in_result": False,
        "page_limit": 1000,
        "first_page": f"/v1/jobs/{job_id}/result?offset=0&limit=1000",
    }
    cells, url = [], f"/v1/jobs/{job_id}/result?offset=0&limit=700"
    while url is not None:
        page = client.get(url)
        assert page.status_code == 200, page.text
        assert page.json()["offset"] == len(cells) and page.json()["total"] == 2500
        cells += page.json()["cells"]
        url = page.json()["next"]
    assert cells == expected["cells"]
    middle = client.get(f"/v1/jobs/{job_id}/result", params={"offset": 1990, "limit": 25})
    assert middle.json()["cells"] == expected["cells"][1990:2015]
    too_many = client.get(f"/v1/jobs/{job_id}/result", params={"limit": 1001})
    assert too_many.status_code == 422, too_many.text
    assert too_many.json()["detail"][0]["loc"] == ["query", "limit"]
    assert "DTF_JOB_PAGE_CELLS" in too_many.json()["detail"][0]["msg"]
    (listed,) = client.get("/v1/jobs").json()["jobs"]
    assert listed["id"] == job_id and listed["result"] is None
    assert listed["progress"]["total"] == 2500


def test_a_map_jobs_progress_leaves_its_storing_a_share(tmp_path: Path) -> None:
    """The placements done, a map job has its cells to write: their progress is reported as
    their share of the job (about four fifths on a UR5's map of the example path), so its ETA
    counts the storing (the jobs audit: a 2-million-cell job said 0.1 s left for 83 s)."""
    reported: list[float] = []
    request = {"robot": EXAMPLE["robot"], "path": EXAMPLE["path"], "grid": GRID_2500}
    settings = Settings(max_job_cells=10_000, max_job_poses=10**7).for_jobs()
    answer = _map(request, settings, reported.append, SERIAL)
    assert isinstance(answer, CellPages) and answer.count == 2500
    assert reported and reported == sorted(reported)
    assert 0.5 < reported[-1] < 0.9
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("map", request, total=2500)
    store.start(job.id)
    store.finish(job.id, "done", result=answer)
    state = store.state(job.id)
    assert state is not None and state.cells == 2500
