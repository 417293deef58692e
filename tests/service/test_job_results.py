"""A job's result in pages: listings read no result, a page equals the map route's cells."""

from __future__ import annotations

import json
import sqlite3
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any
from uuid import UUID

import pytest
from fastapi.testclient import TestClient

from service.api.routes.job_results import job_picture
from service.config import Settings
from service.convert.common import robot_from_schema
from service.convert.stored_map import StoredCellsMismatch, stored_map
from service.jobs import store_reads
from service.jobs.job import DamagedJob
from service.jobs.results import CellPages
from service.jobs.store import JobStore
from service.jobs.worker import _map
from service.schemas import MapRequest
from solver.core.parallel import SERIAL
from solver.core.progress import Cancelled
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


def done_map_job(client: TestClient) -> str:
    """The id of a map job of GRID_2500 (three stored pages of cells), run to its end."""
    request = {"robot": EXAMPLE["robot"], "path": SHORT_PATH, "grid": GRID_2500}
    job_id: str = client.post("/v1/jobs", json={"kind": "map", "request": request}).json()["id"]
    assert done_job(client, job_id)["status"] == "done"
    return job_id


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
        # the same page by parameters, for a client that calls the operation with them
        offset = page.json()["next_offset"]
        assert (url is None) == (offset is None)
        assert url is None or url == f"/v1/jobs/{job_id}/result?offset={offset}&limit=700"
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


def test_a_page_read_while_another_client_deletes_the_job_is_a_404(
    client: TestClient, paged_store: Settings, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Audit 26's F10: the job's state read, then deleted by another client, then its cells
    read (none): the page answered 200 with the whole total, no cells and itself as next."""
    job_id = done_map_job(client)
    read = JobStore.cells_json

    def deleted_first(store: JobStore, job: str, *, offset: int, limit: int) -> tuple[str, int]:
        store.delete(job)  # the other client's DELETE, between the two reads
        return read(store, job, offset=offset, limit=limit)

    monkeypatch.setattr(JobStore, "cells_json", deleted_first)
    page = client.get(f"/v1/jobs/{job_id}/result", params={"offset": 1000, "limit": 100})
    assert page.status_code == 404, page.text
    assert page.json()["detail"][0]["loc"] == ["path", "job_id"]
    assert "deleted while its page was read" in page.json()["detail"][0]["msg"]


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


def _job_png(client: TestClient, request: dict[str, Any]) -> bytes:
    submitted = client.post("/v1/jobs", json={"kind": "map", "request": request})
    assert submitted.status_code == 202, submitted.text
    job_id = submitted.json()["id"]
    assert done_job(client, job_id)["status"] == "done"
    picture = client.get(f"/v1/jobs/{job_id}/png")
    assert picture.status_code == 200, picture.text
    assert picture.headers["content-type"] == "image/png"
    return picture.content


def test_a_map_jobs_picture_is_the_map_routes_picture(
    client: TestClient, paged_store: Settings
) -> None:
    # 2,500 cells in three stored pages, two yaws, cells out of reach among them: drawn from the
    # store, the picture is the one the PNG route draws of the map computed again, byte for byte
    grid = {**GRID_2500, "x": {"min": -0.98, "max": 0.0, "step": 0.02}}  # far cells out of reach
    request = {"robot": EXAMPLE["robot"], "path": SHORT_PATH, "grid": grid}
    direct = client.post("/v1/map/png", json=request)
    assert direct.status_code == 200, direct.text
    reasons = {c["reason"] for c in client.post("/v1/map", json=request).json()["cells"]}
    assert {None, "unreachable"} <= reasons  # feasible cells and others in their colour
    assert _job_png(client, request) == direct.content


@pytest.mark.parametrize(
    "grid",
    [
        {
            "x": {"min": -0.1, "max": 0.1, "step": 0.05},
            "y": {"min": 0.35, "max": 0.45, "step": 0.05},
        },
        # nothing feasible (out of reach): the bar still says mu_acc, as the route's picture does
        {"x": {"min": 2.0, "max": 2.1, "step": 0.05}, "y": {"min": 2.0, "max": 2.1, "step": 0.05}},
    ],
)
def test_a_map_jobs_picture_with_acceleration_limits(
    client: TestClient, paged_store: Settings, grid: dict[str, Any]
) -> None:
    robot = {**EXAMPLE["robot"], "joint_acceleration_limits": [3.0] * 6}
    request = {"robot": robot, "path": SHORT_PATH, "grid": {**grid, "z": 0.1, "yaw": 0.3}}
    direct = client.post("/v1/map/png", json=request)
    assert direct.status_code == 200, direct.text
    assert _job_png(client, request) == direct.content


def test_a_jobs_picture_is_refused_unless_a_done_map_within_the_panel_limit(
    client: TestClient, paged_store: Settings
) -> None:
    missing = client.get("/v1/jobs/00000000-0000-4000-8000-000000000000/png")
    assert missing.status_code == 404, missing.text
    evaluate = {"kind": "evaluate", "request": {**EXAMPLE, "path": SHORT_PATH}}
    job_id = client.post("/v1/jobs", json=evaluate).json()["id"]
    assert done_job(client, job_id)["status"] == "done"
    answer = client.get(f"/v1/jobs/{job_id}/png")
    assert answer.status_code == 409 and "is an evaluate job" in answer.json()["detail"][0]["msg"]
    yaws = [0.1 * k for k in range(paged_store.max_png_panels + 1)]
    grid = {"x": {"min": 0.0, "max": 0.0, "step": 0.1}, "y": {"min": 0.4, "max": 0.4, "step": 0.1}}
    request = {
        "robot": EXAMPLE["robot"],
        "path": SHORT_PATH,
        "grid": {**grid, "z": 0.1, "yaw": yaws},
    }
    job_id = client.post("/v1/jobs", json={"kind": "map", "request": request}).json()["id"]
    assert done_job(client, job_id)["status"] == "done"
    answer = client.get(f"/v1/jobs/{job_id}/png")
    assert answer.status_code == 409, answer.text
    said = answer.json()["detail"][0]["msg"]
    assert f"= {len(yaws)} PNG panels; the limit is {paged_store.max_png_panels}" in said
    assert "(DTF_MAX_PNG_PANELS)" in said and f"GET /v1/jobs/{job_id}/result" in said


def test_stored_cells_that_are_not_the_grids_are_refused() -> None:
    body = MapRequest.model_validate(
        {"robot": EXAMPLE["robot"], "path": SHORT_PATH, "grid": GRID_2500}
    )
    robot = robot_from_schema(body.robot)
    cell = {"mu_path": 0.1, "mu_acc": None, "reason": None}
    with pytest.raises(StoredCellsMismatch, match="2499 cells stored, the grid has 2500"):
        stored_map(body, robot, [[cell] * 1000, [cell] * 1000, [cell] * 499])
    with pytest.raises(StoredCellsMismatch, match="more cells stored than the grid's 2500"):
        stored_map(body, robot, [[cell] * 2000, [cell] * 501])
    with pytest.raises(StoredCellsMismatch, match="'overheated' is unknown"):
        stored_map(body, robot, [[{**cell, "reason": "overheated"}] * 2500])
    with pytest.raises(StoredCellsMismatch, match=r"'\[1\]' is unknown"):  # not even a string
        stored_map(body, robot, [[{**cell, "reason": [1]}] * 2500])
    with pytest.raises(StoredCellsMismatch, match="near cell 0: no 'mu_path'"):  # was a KeyError
        stored_map(body, robot, [[{"reason": None}] * 2500])
    whole = stored_map(body, robot, [[cell] * 2500])
    assert whole.mu_path.shape == (1, 2, 25, 50) and whole.mu_acc is None


def test_a_map_job_stored_with_a_request_this_release_cannot_read_is_a_409(
    client: TestClient, paged_store: Settings
) -> None:
    # a done map job of an older release's store, its request without a grid: no 500
    store = JobStore(paged_store.data_dir / "jobs.sqlite3")
    job = store.create("map", {"robot": EXAMPLE["robot"], "path": SHORT_PATH}, total=1)
    store.start(job.id)
    store.finish(job.id, "done", result={"cells": [CELLS[0]], "feasible_cells": 1})
    answer = client.get(f"/v1/jobs/{job.id}/png")
    assert answer.status_code == 409, answer.text
    said = answer.json()["detail"][0]["msg"]
    assert "not a map request this release reads (grid: Field required)" in said
    assert f"GET /v1/jobs/{job.id}/result" in said


def test_a_jobs_cells_are_read_whole_when_it_is_deleted_meanwhile(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A page a query: deleted after the first page is read, the job's cells were cut short
    # (the picture's route then said the job was damaged); one snapshot reads them all.
    monkeypatch.setattr(store_reads, "READ_PAGES", 1)
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("map", {}, total=2500)
    store.start(job.id)
    store.finish(job.id, "done", result={"cells": CELLS, "feasible_cells": 2500})
    pages = store.cell_pages(job.id)
    first = next(pages)
    assert JobStore(tmp_path / "jobs.sqlite3").delete(job.id)
    assert [cell for page in (first, *pages) for cell in page] == CELLS
    assert list(store.cell_pages(job.id)) == []  # read after: nothing


def test_a_map_jobs_picture_of_a_job_deleted_while_read_is_a_404(
    client: TestClient, paged_store: Settings, monkeypatch: pytest.MonkeyPatch
) -> None:
    job_id = done_map_job(client)

    def deleted_first(self: JobStore, job: str) -> Iterator[list[dict[str, Any]]]:
        self.delete(job)  # as a DELETE just before the cells are read
        yield from ()

    monkeypatch.setattr(JobStore, "cell_pages", deleted_first)
    answer = client.get(f"/v1/jobs/{job_id}/png")
    assert answer.status_code == 404, answer.text


def test_a_jobs_picture_stops_reading_when_its_client_leaves(
    client: TestClient, paged_store: Settings, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The reading of 2 million cells takes seconds: it is told after each page, and stops
    (its store connection closed) when the client has left, as a map route's work does."""
    job_id = done_map_job(client)
    read, closed = [], []
    pages_of = JobStore.cell_pages

    def counted(self: JobStore, job: str) -> Iterator[list[dict[str, Any]]]:
        try:
            for page in pages_of(self, job):
                read.append(len(page))
                yield page
        finally:
            closed.append(True)

    def left(fraction: float) -> None:
        told.append(fraction)
        raise Cancelled

    told: list[float] = []
    monkeypatch.setattr(JobStore, "cell_pages", counted)
    with pytest.raises(Cancelled) as stopped:
        job_picture(UUID(job_id), paged_store, left)
    # While the exception (its traceback holds the reading's frames) lives on, as it does until
    # the route's answer is made on another thread, the reading is closed already: its
    # connection and read transaction gone, a checkpoint of the store not held up.
    assert stopped.value is not None
    assert told == [0.4] and read == [1000] and closed == [True]  # one page of three read
    with sqlite3.connect(paged_store.data_dir / "jobs.sqlite3") as db:
        assert db.execute("PRAGMA wal_checkpoint(TRUNCATE)").fetchone()[0] == 0  # not busy


def test_a_map_jobs_picture_of_a_job_deleted_before_its_request_is_read_is_a_404(
    client: TestClient, paged_store: Settings, monkeypatch: pytest.MonkeyPatch
) -> None:
    job_id = done_map_job(client)

    def gone(self: JobStore, job: str) -> None:
        self.delete(job)  # as a DELETE between the job's state and its request
        return None

    monkeypatch.setattr(JobStore, "request", gone)
    answer = client.get(f"/v1/jobs/{job_id}/png")
    assert answer.status_code == 404, answer.text  # was a 409 'not a map request'
