"""``/v1/jobs`` in process: checked as the routes check, 503 on a bad store, delete and cancel."""

from __future__ import annotations

import json
import re
import sqlite3
import time
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from service.config import Settings
from service.jobs.store import JobStore
from tests.cases import ROOT
from tests.service.conftest import served_with

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
GRID = {"x": {"min": -0.1, "max": 0.1, "step": 0.1}, "y": 0.45, "z": 0.1, "yaw": 0.0}
BAD_PATHS = [  # each refused by the route itself, not by the schema (invalid_line, ...)
    {"csv": "x,y,z\n1,2\n", "units": "mm"},
    {"cl_data": "GOTO/0,0,0\nNOT A RECORD\n"},
    {"waypoints": [EXAMPLE["path"]["waypoints"][0]] * 2},  # a repeated waypoint
]


def route_body(kind: str, path: dict[str, Any]) -> dict[str, Any]:
    body: dict[str, Any] = {"robot": EXAMPLE["robot"], "path": path}
    if kind == "evaluate":
        body["placement"] = EXAMPLE["placement"]
    elif kind == "map":
        body["grid"] = {**GRID, "y": {"min": 0.4, "max": 0.5, "step": 0.1}}
    else:
        body |= {"bounds": {"x": [-0.05, 0.05], "y": [0.4, 0.5], "yaw": [-0.2, 0.2]}, "z": 0.1}
    return body


@pytest.mark.parametrize("kind", ["evaluate", "map", "optimize"])
@pytest.mark.parametrize("path", BAD_PATHS, ids=["csv", "cl_data", "repeated"])
def test_a_job_is_refused_at_submit_as_its_route_refuses_it(
    client: TestClient, kind: str, path: dict[str, Any]
) -> None:
    body = route_body(kind, path)
    direct = client.post(f"/v1/{kind}", json=body)
    assert direct.status_code == 422, direct.text
    submitted = client.post("/v1/jobs", json={"kind": kind, "request": body})
    assert submitted.status_code == 422, submitted.text
    (expected,), (detail,) = direct.json()["detail"], submitted.json()["detail"]
    assert detail == {**expected, "loc": ["body", "request", *expected["loc"][1:]]}


def test_an_optimize_job_with_a_start_outside_its_bounds_is_refused(client: TestClient) -> None:
    body = route_body("optimize", EXAMPLE["path"]) | {
        "start": {"x": 1.0, "y": 0.45, "z": 0.1, "yaw": 0.0}
    }
    submitted = client.post("/v1/jobs", json={"kind": "optimize", "request": body})
    assert submitted.status_code == 422, submitted.text
    assert submitted.json()["detail"][0]["loc"] == ["body", "request", "start"]


SPIN_PATH = {"max_spin_step": 0.05}
REFUSED_SEARCHES = {  # each refused by the optimiser's own checks, not by the schema
    "scipy": {"method": "scipy", "spin_path": SPIN_PATH},
    "free-spin": {"spin_mode": "free", "spin_path": SPIN_PATH},
    "two-passes": {
        "path": {"cl_data": (ROOT / "examples" / "cam" / "nx_slot_plate.cls").read_text()},
        "spin_mode": "fixed",
        "spin_path": SPIN_PATH,
    },
}


@pytest.mark.parametrize("changes", REFUSED_SEARCHES.values(), ids=REFUSED_SEARCHES.keys())
def test_an_optimize_job_is_refused_as_the_optimiser_refuses_its_spin_path(
    client: TestClient, changes: dict[str, Any]
) -> None:
    body = route_body("optimize", EXAMPLE["path"]) | changes
    direct = client.post("/v1/optimize", json=body)
    assert direct.status_code == 422, direct.text
    submitted = client.post("/v1/jobs", json={"kind": "optimize", "request": body})
    assert submitted.status_code == 422, submitted.text
    (expected,), (detail,) = direct.json()["detail"], submitted.json()["detail"]
    assert expected["loc"] == ["body", "spin_path"]
    assert detail == {**expected, "loc": ["body", "request", "spin_path"]}


@pytest.mark.parametrize(
    "kind", [{}, {"kind": "optimise"}, {"kind": None}, {"kind": ["map"]}], ids=str
)
def test_a_job_without_a_known_kind_is_refused_on_kind(
    client: TestClient, kind: dict[str, Any]
) -> None:
    body = kind | {"request": route_body("optimize", EXAMPLE["path"])}
    submitted = client.post("/v1/jobs", json=body)
    assert submitted.status_code == 422, submitted.text
    (detail,) = submitted.json()["detail"]
    assert detail["loc"] == ["body", "kind"]
    assert all(f'"{name}"' in detail["msg"] for name in ("map", "optimize", "evaluate"))


def wait_for(client: TestClient, job_id: str, done: Any, timeout: float = 60) -> dict[str, Any]:
    deadline = time.monotonic() + timeout
    while True:
        job: dict[str, Any] = client.get(f"/v1/jobs/{job_id}").json()
        if done(job) or time.monotonic() > deadline:
            return job
        time.sleep(0.05)


def test_delete_removes_a_job_and_cancel_keeps_it(client: TestClient, own_store: Path) -> None:
    job = {"kind": "map", "request": route_body("map", EXAMPLE["path"])}
    submitted = client.post("/v1/jobs", json=job)
    assert submitted.status_code == 202, submitted.text
    first = submitted.json()["id"]
    assert client.delete(f"/v1/jobs/{first}").status_code == 204
    assert client.get(f"/v1/jobs/{first}").status_code == 404
    assert client.delete(f"/v1/jobs/{first}").status_code == 404
    assert first not in [j["id"] for j in client.get("/v1/jobs").json()["jobs"]]
    second = client.post("/v1/jobs", json=job).json()["id"]
    cancelled = client.post(f"/v1/jobs/{second}/cancel")
    assert cancelled.status_code == 200, cancelled.text
    assert cancelled.json()["id"] == second
    ended = wait_for(client, second, lambda j: j["status"] not in ("queued", "running"))
    assert ended["status"] in ("cancelled", "done")  # done if it ended before the cancel
    assert client.post(f"/v1/jobs/{uuid.uuid4()}/cancel").status_code == 404


def test_the_job_listing_is_read_in_pages_with_after(client: TestClient, own_store: Path) -> None:
    job = {"kind": "evaluate", "request": route_body("evaluate", EXAMPLE["path"])}
    submitted = [client.post("/v1/jobs", json=job) for _ in range(3)]
    assert all(answer.status_code == 202 for answer in submitted), submitted[-1].text
    everything = [j["id"] for j in client.get("/v1/jobs").json()["jobs"]]
    assert sorted(everything) == sorted(answer.json()["id"] for answer in submitted)
    first = client.get("/v1/jobs", params={"limit": 2}).json()["jobs"]
    second = client.get("/v1/jobs", params={"limit": 2, "after": first[-1]["id"]}).json()["jobs"]
    assert [j["id"] for j in first + second] == everything
    last = client.get("/v1/jobs", params={"after": everything[-1]})
    assert last.status_code == 200 and last.json()["jobs"] == []
    unknown = client.get("/v1/jobs", params={"after": str(uuid.uuid4())})
    assert unknown.status_code == 404, unknown.text
    assert unknown.json()["detail"][0]["loc"] == ["query", "after"]


def test_a_listing_goes_on_after_a_job_deleted_between_its_pages(
    client: TestClient, own_store: Path
) -> None:
    """Another client deleting the last job of a page made the next page a 404 (audit 26, F4):
    the listing goes on after its place, as if it were there."""
    job = {"kind": "evaluate", "request": route_body("evaluate", EXAMPLE["path"])}
    ids = [client.post("/v1/jobs", json=job).json()["id"] for _ in range(4)]
    everything = [j["id"] for j in client.get("/v1/jobs").json()["jobs"]]
    assert sorted(everything) == sorted(ids)
    first = [j["id"] for j in client.get("/v1/jobs", params={"limit": 2}).json()["jobs"]]
    assert client.delete(f"/v1/jobs/{first[-1]}").status_code == 204  # another client's delete
    second = client.get("/v1/jobs", params={"limit": 2, "after": first[-1]})
    assert second.status_code == 200, second.text
    assert [j["id"] for j in second.json()["jobs"]] == everything[2:]
    assert client.get(f"/v1/jobs/{first[-1]}").status_code == 404  # the job itself is gone


def test_the_job_listing_is_filtered_by_kind(client: TestClient, own_store: Path) -> None:
    """The page listed its earlier maps among the newest 100 jobs of every kind: a client's
    evaluations could hide its maps. ``kind`` lists one kind, with ``status`` and ``after``."""
    kinds = ["map", "evaluate", "map", "evaluate"]
    ids = [
        client.post("/v1/jobs", json={"kind": k, "request": route_body(k, EXAMPLE["path"])}).json()[
            "id"
        ]
        for k in kinds
    ]
    maps = client.get("/v1/jobs", params={"kind": "map"}).json()["jobs"]
    assert [j["id"] for j in maps] == [ids[2], ids[0]] and {j["kind"] for j in maps} == {"map"}
    after = client.get("/v1/jobs", params={"kind": "map", "after": ids[2]}).json()["jobs"]
    assert [j["id"] for j in after] == [ids[0]]
    none = client.get("/v1/jobs", params={"kind": "optimize"}).json()["jobs"]
    assert none == []
    bad = client.get("/v1/jobs", params={"kind": "maps"})
    assert bad.status_code == 422 and bad.json()["detail"][0]["loc"] == ["query", "kind"]


def test_a_finished_job_expires_while_the_service_runs(client: TestClient, tmp_path: Path) -> None:
    job = {"kind": "evaluate", "request": route_body("evaluate", EXAMPLE["path"])}
    with served_with(Settings(data_dir=tmp_path, workers=1, job_ttl=1.0)):
        job_id = client.post("/v1/jobs", json=job).json()["id"]
        done = wait_for(client, job_id, lambda j: j.get("status") == "done")
        assert done["status"] == "done", done
        # expired while the service runs, not only at its next startup
        gone = wait_for(client, job_id, lambda j: "status" not in j, timeout=10)
        assert "status" not in gone and gone["detail"][0]["type"] == "not_found", gone
        assert job_id not in [j["id"] for j in client.get("/v1/jobs").json()["jobs"]]


@pytest.fixture
def corrupt_store(tmp_path: Path) -> Iterator[Path]:
    """The app with its jobs in ``tmp_path``, whose store file is not a database."""
    path = tmp_path / "jobs.sqlite3"
    path.write_bytes(b"not a database" * 100)
    with served_with(Settings(data_dir=tmp_path, workers=1)):
        yield path


def test_a_corrupt_store_takes_down_the_job_routes_only(
    client: TestClient, corrupt_store: Path
) -> None:
    job = {"kind": "evaluate", "request": route_body("evaluate", EXAMPLE["path"])}
    for method, url, body in [
        ("GET", "/v1/jobs", None),
        ("GET", f"/v1/jobs/{uuid.uuid4()}", None),
        ("POST", "/v1/jobs", job),
        ("POST", f"/v1/jobs/{uuid.uuid4()}/cancel", None),
        ("DELETE", f"/v1/jobs/{uuid.uuid4()}", None),
    ]:
        answer = client.request(method, url, json=body)
        assert answer.status_code == 503, (method, url, answer.text)
        assert answer.headers["retry-after"] == "30"
        (detail,) = answer.json()["detail"]
        assert detail["type"] == "job_store_unavailable"
        assert str(corrupt_store) in detail["msg"] and "file is not a database" in detail["msg"]
    assert client.get("/healthz").status_code == 200
    evaluated = client.post("/v1/evaluate", json=job["request"])
    assert evaluated.status_code == 200, evaluated.text


DAMAGES = {  # what a hand edit may leave in a row; whether the job's state (not only its result)
    "status": ("status = 'paused'", True),
    "error": ("status = 'failed', error = '5'", True),
    "result": ("status = 'done', result = '{'", False),
}


@pytest.mark.parametrize("damage", DAMAGES.values(), ids=DAMAGES.keys())
def test_a_damaged_job_is_a_503_naming_it_and_the_others_are_served(
    client: TestClient, tmp_path: Path, damage: tuple[str, bool]
) -> None:
    change, in_state = damage
    store = JobStore(tmp_path / "jobs.sqlite3")  # filled before the service looks at it
    good, bad = (store.create("evaluate", route_body("evaluate", EXAMPLE["path"])) for _ in "ab")
    with sqlite3.connect(store.path) as db:
        db.execute("UPDATE jobs SET status = 'cancelled', finished = created")
        db.execute(f"UPDATE jobs SET {change} WHERE id = ?", (bad.id,))
    with served_with(Settings(data_dir=tmp_path, workers=1)):
        listed = client.get("/v1/jobs")
        assert listed.status_code == 200, listed.text
        ids = [job["id"] for job in listed.json()["jobs"]]
        assert good.id in ids and (bad.id in ids) == (not in_state)  # left out, not a 500
        assert client.get(f"/v1/jobs/{good.id}").status_code == 200
        for method, url in [("GET", f"/v1/jobs/{bad.id}"), ("POST", f"/v1/jobs/{bad.id}/cancel")]:
            answer = client.request(method, url)
            if method == "POST" and not in_state:
                assert answer.status_code == 200, answer.text  # a cancel reads no result
                continue
            assert answer.status_code == 503, (method, answer.text)
            (detail,) = answer.json()["detail"]
            assert detail["type"] == "job_store_unavailable"
            assert str(store.path) in detail["msg"] and bad.id in detail["msg"]
        assert client.delete(f"/v1/jobs/{bad.id}").status_code == 204
        assert client.get(f"/v1/jobs/{bad.id}").status_code == 404


def test_the_spec_declares_the_503_of_the_job_routes(client: TestClient) -> None:
    paths = client.get("/openapi.json").json()["paths"]
    for path, method in [("/v1/jobs", "post"), ("/v1/jobs/{job_id}", "get")]:
        declared = paths[path][method]["responses"]["503"]
        assert "job store" in declared["description"], (path, declared)
    assert "503" not in paths["/metrics"]["get"]["responses"]  # dtf_job_store_up 0 instead


def test_every_error_type_a_job_can_fail_with_is_in_the_contract() -> None:
    """Read from the job code's own literals (a regex), each type is explained in JobInfo.error's
    description, the client's only account of whose fault a failure is ('unavailable' was in
    no document)."""
    from service.schemas.jobs import JobInfo

    sources = (ROOT / "service" / "jobs").glob("*.py")
    emitted = {
        kind
        for source in sources
        for kind in re.findall(r'"type": "([a-z_]+)"', source.read_text())
    }
    assert {"unavailable", "interrupted", "damaged", "internal"} <= emitted
    description = JobInfo.model_fields["error"].description or ""
    assert [kind for kind in sorted(emitted) if f"{kind} (" not in description] == []


@pytest.mark.parametrize("kind", ["evaluate", "map"])
def test_a_jobs_request_is_read_back_as_submitted(client: TestClient, kind: str) -> None:
    """A client that lost the body (a page reloaded while its map ran) could not learn what a
    job computes, nor evaluate a map's cells with their own request."""
    body = route_body(kind, EXAMPLE["path"]) | {"ik": {"max_joint_step": 0.3}}
    submitted = client.post("/v1/jobs", json={"kind": kind, "request": body})
    assert submitted.status_code == 202, submitted.text
    job = submitted.json()
    read = client.get(f"/v1/jobs/{job['id']}/request")
    assert read.status_code == 200
    assert read.json() == {"kind": kind, "request": body}
    assert client.delete(f"/v1/jobs/{job['id']}").status_code == 204
    gone = client.get(f"/v1/jobs/{job['id']}/request")
    assert gone.status_code == 404
    assert gone.json()["detail"][0]["loc"] == ["path", "job_id"]


def test_health_says_when_the_jobs_cannot_run_and_when_they_can_again(
    client: TestClient, tmp_path: Path
) -> None:
    """A service whose job store could not be used answered /healthz "ok" alone (the operator
    audit, M2): ``jobs`` says the supervisor's last look, without reading the store."""
    assert client.get("/healthz").json()["jobs"] == "ok"
    blocked = tmp_path / "not-a-directory"
    blocked.write_text("a file where the data directory should be")
    with served_with(Settings(data_dir=blocked, workers=1)):
        assert client.get("/v1/jobs").status_code == 503  # the runner made, its store refused
        deadline = time.monotonic() + 10
        while (jobs := client.get("/healthz").json()["jobs"]) == "ok":
            assert time.monotonic() < deadline, "the supervisor never looked"
            time.sleep(0.05)
        assert jobs.startswith("unavailable: the job store ") and str(blocked) in jobs, jobs
        blocked.unlink()
        blocked.mkdir()  # the directory now there: the next looks succeed
        deadline = time.monotonic() + 15
        while (jobs := client.get("/healthz").json()["jobs"]) != "ok":
            assert time.monotonic() < deadline, jobs
            time.sleep(0.05)
    assert client.get("/healthz").json() == {"status": "ok", "jobs": "ok"}
