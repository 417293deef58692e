"""Bounds and hygiene of the error answers (issue 26): echoes cut, bodies bounded, JSON errors.

Every error answer is ``{"detail": [{"loc", "msg", "type"}]}`` (404, 408, 415, 429 and 500 as
the 422s), the spec declares them with their ``Location`` and ``Retry-After`` headers, a value
sent by the client is echoed at most 100 characters long, and a body that stops short of its
Content-Length is answered within DTF_BODY_READ_SECONDS instead of holding the connection.
"""

from __future__ import annotations

import asyncio
import json
import re
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient
from starlette.types import Message, Receive, Scope, Send

from service.body_limits import BodySizeLimitMiddleware
from service.config import get_settings
from service.jobs.job import QueueFull
from service.jobs.store import JobStore
from service.main import app
from tests.cases import ROOT

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
LONG = 5_000
"""Characters of a client's name (a link, a CL word) that must not come back whole."""


SPHERE = '<collision><geometry><sphere radius="0.1"/></geometry></collision>'


def _longest_run(text: str, letter: str) -> int:
    """The longest run of ``letter`` in ``text`` (how much of an echoed name came back)."""
    return max((len(run) for run in re.findall(f"{letter}+", text)), default=0)


def test_an_unknown_cl_word_is_echoed_cut(client: TestClient) -> None:
    word = "Q" * 500_000  # a 500 KB record of an unknown word, which the reader skips
    program = f"UNITS/MM\nMULTAX/ON\n{word}/1\nGOTO/0, 0, 0, 0, 0, 1\nGOTO/1, 0, 0, 0, 0, 1\n"
    answer = client.post("/v1/paths/import", json={"path": {"cl_data": program}})
    assert answer.status_code == 200, answer.text[:300]
    (skipped,) = answer.json()["skipped_records"]
    assert skipped["word"] == "Q" * 100 + "..." and skipped["count"] == 1
    assert len(answer.content) < 5_000


@pytest.fixture
def long_link_urdf(panda_urdf: str) -> str:
    """The Panda with its hand link renamed to 5,000 characters."""
    return panda_urdf.replace('"panda_hand"', f'"{"L" * LONG}"')


@pytest.mark.parametrize(
    ("edit", "loc"),
    [
        (lambda urdf: urdf, ["body", "robot", "tool_frame"]),  # listed among the frames
        (  # a second root link (with collision geometry: not left out), named in the message
            lambda urdf: urdf.replace(
                "</robot>", f'<link name="{"M" * LONG}">{SPHERE}</link></robot>'
            ),
            ["body", "robot", "urdf"],
        ),
    ],
    ids=["frames listed", "root links named"],
)
def test_a_long_link_name_is_echoed_cut(
    client: TestClient, long_link_urdf: str, edit: Any, loc: list[str]
) -> None:
    robot = {"urdf": edit(long_link_urdf), "base_frame": "panda_link0", "tool_frame": "nothing"}
    answer = client.post("/v1/evaluate", json={**EXAMPLE, "robot": robot})
    assert answer.status_code == 422, answer.text[:300]
    assert answer.json()["detail"][0]["loc"] == loc
    assert max(_longest_run(answer.text, "L"), _longest_run(answer.text, "M")) == 100


def test_links_left_out_of_a_urdf_are_named_cut_and_counted(
    client: TestClient, panda_urdf: str
) -> None:
    # 25 links no joint names, each named with 5,000 characters: left out (robot_read), the
    # first 20 named, each cut to 100 characters, all 25 counted; the arm answers as without
    # them.
    names = [f"{k:02d}{'N' * LONG}" for k in range(25)]
    strays = "".join(f'<link name="{name}"/>' for name in names)
    robot = {"urdf": panda_urdf, "base_frame": "panda_link0", "tool_frame": "panda_link8"}
    body = {**EXAMPLE, "robot": robot, "detail": "summary"}
    plain = client.post("/v1/evaluate", json=body)
    robot = {**robot, "urdf": panda_urdf.replace("</robot>", strays + "</robot>")}
    answer = client.post("/v1/evaluate", json={**body, "robot": robot})
    assert plain.status_code == answer.status_code == 200, answer.text[:300]
    read = answer.json()["robot_read"]
    assert read["left_out_count"] == 25
    assert read["left_out_links"] == [name[:100] + "..." for name in names[:20]]
    assert _longest_run(answer.text, "N") == 98
    assert plain.json()["robot_read"]["left_out_count"] == 0  # the fingers locked, no more
    assert {**answer.json(), "robot_read": None} == {**plain.json(), "robot_read": None}


def test_a_post_without_content_type_is_415(client: TestClient) -> None:
    answer = client.post("/v1/evaluate", content=json.dumps(EXAMPLE).encode())
    assert "content-type" not in answer.request.headers
    assert answer.status_code == 415, answer.text[:300]
    assert answer.json()["detail"][0]["loc"] == ["header", "content-type"]
    cancel = client.post(f"/v1/jobs/{uuid.uuid4()}/cancel")  # no body: no content type needed
    assert cancel.status_code == 404


@pytest.fixture
def read_timeout(monkeypatch: pytest.MonkeyPatch) -> Iterator[float]:
    """A 0.2 s body read timeout, set through the environment as a deployment would."""
    monkeypatch.setenv("DTF_BODY_READ_SECONDS", "0.2")
    get_settings.cache_clear()
    yield 0.2
    get_settings.cache_clear()


def test_a_body_short_of_its_length_is_408_in_time(read_timeout: float) -> None:
    sent: list[Message] = []
    reached_app: list[bool] = []
    first = {"type": "http.request", "body": b'{"robot": ', "more_body": True}

    async def app_(scope: Scope, receive: Receive, send: Send) -> None:
        reached_app.append(True)

    async def receive() -> Message:
        nonlocal first
        if first:
            message, first = first, {}
            return message
        await asyncio.sleep(3600)  # the rest of the body never comes
        raise AssertionError("unreachable")

    async def send(message: Message) -> None:
        sent.append(message)

    headers = [(b"content-type", b"application/json"), (b"content-length", b"1000")]
    scope: Scope = {"type": "http", "method": "POST", "path": "/v1/dtf", "headers": headers}

    async def run() -> None:
        await asyncio.wait_for(BodySizeLimitMiddleware(app_)(scope, receive, send), timeout=5)

    asyncio.run(run())
    assert reached_app == []
    assert sent[0]["status"] == 408
    detail = json.loads(sent[1]["body"])["detail"][0]
    assert detail["type"] == "body_timeout" and "0.2 s" in detail["msg"]


def _is_error_list(answer: Any, status: int) -> dict[str, Any]:
    assert answer.status_code == status, answer.text[:300]
    assert answer.headers["content-type"] == "application/json"
    (detail,) = answer.json()["detail"]
    assert set(detail) == {"loc", "msg", "type"}
    return dict(detail)


def test_an_unknown_job_is_a_json_404_naming_the_id(client: TestClient) -> None:
    job_id = uuid.uuid4()
    for answer in (
        client.get(f"/v1/jobs/{job_id}"),
        client.delete(f"/v1/jobs/{job_id}"),
        client.post(f"/v1/jobs/{job_id}/cancel"),
    ):
        detail = _is_error_list(answer, 404)
        assert detail["loc"] == ["path", "job_id"] and detail["type"] == "not_found"
    assert _is_error_list(client.get("/v1/nowhere"), 404)["type"] == "not_found"


def test_a_full_queue_is_a_json_429_with_retry_after(
    client: TestClient, monkeypatch: pytest.MonkeyPatch
) -> None:
    def full(self: JobStore, *args: Any, **kwargs: Any) -> None:
        raise QueueFull(1)

    monkeypatch.setattr(JobStore, "create", full)
    body = {
        "kind": "evaluate",
        "request": {k: EXAMPLE[k] for k in ("robot", "path", "placement")},
    }
    answer = client.post("/v1/jobs", json=body)
    detail = _is_error_list(answer, 429)
    assert detail["type"] == "queue_full"
    assert int(answer.headers["retry-after"]) > 0
    # the page shows this beside its form: that the jobs are every client's, and when to retry
    # (audit 26, O1: it said the limit only, to a user whose own queue was empty)
    assert "every client's" in detail["msg"] and "Retry-After" in detail["msg"]


def test_a_fault_is_a_json_500(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    def broken(*args: Any, **kwargs: Any) -> None:
        raise RuntimeError("a bug")

    monkeypatch.setattr("service.operations.dtf.dtf", broken)
    body = {"robot": {"model": "ur5"}, "q": [0.1, -1.2, 1.3, -1.5, -1.4, 0.2], "u_T": [1, 0, 0]}
    answer = TestClient(app, raise_server_exceptions=False).post("/v1/dtf", json=body)
    detail = _is_error_list(answer, 500)
    assert detail["type"] == "internal" and "RuntimeError" in detail["msg"]


def _responses(method: str, path: str) -> dict[str, Any]:
    spec = json.loads((ROOT / "openapi" / "openapi.json").read_text())
    return dict(spec["paths"][path][method]["responses"])


ERROR_SCHEMA = {"$ref": "#/components/schemas/ErrorResponse"}


@pytest.mark.parametrize(
    ("method", "path", "status", "header"),
    [
        ("post", "/v1/jobs", "202", "Location"),
        ("post", "/v1/jobs", "429", "Retry-After"),
        ("get", "/v1/jobs/{job_id}", "404", None),
        ("get", "/v1/jobs/{job_id}", "503", "Retry-After"),
        ("post", "/v1/evaluate", "503", "Retry-After"),
        ("post", "/v1/evaluate", "408", None),
        ("get", "/v1/robots", "500", None),
        ("post", "/v1/map", "500", None),
    ],
)
def test_the_spec_declares_error_bodies_and_headers(
    method: str, path: str, status: str, header: str | None
) -> None:
    answer = _responses(method, path)[status]
    if status != "202":
        assert answer["content"]["application/json"]["schema"] == ERROR_SCHEMA
    if header is not None:
        assert header in answer["headers"]


def _two_waypoints() -> dict[str, Any]:
    points = ([0.0, 0.4, 0.0], [0.01, 0.4, 0.0])  # two points along x, the tool pointing down
    return {"waypoints": [{"position": p, "orientation": [1, 0, 0, 0]} for p in points]}


@pytest.mark.parametrize(
    ("route", "body"),
    [
        (
            "/v1/map",
            {
                "grid": {
                    "x": {"min": 1e-16, "max": 1e-16, "step": 1000},
                    "y": {"min": 0.0, "max": 0.0, "step": 0.1},
                    "z": 0.1,
                    "yaw": 0.0,
                }
            },
        ),
        (
            "/v1/optimize",
            {"z": 1e-21, "bounds": {"x": [-0.02, 0.02], "y": [-0.02, 0.02], "yaw": [0.0, 0.1]}},
        ),
        (
            "/v1/optimize",
            {"bounds": {"x": [1e-21, 0.01], "y": [0, 0.01], "yaw": [1e-21, 0.1], "z": [0.1, 0.1]}},
        ),
    ],
)
def test_an_axis_of_one_value_written_to_many_decimals_is_answered(
    client: TestClient, route: str, body: dict[str, Any]
) -> None:
    """A one-value axis whose value is written to 16 or 21 decimals (a grid axis narrower than
    its step, a fixed height, a box narrower than the coarse map's 20 mm): the stride of its
    written decimals passed int64, a 500 on both routes and their jobs (audit 22)."""
    request = {"robot": {"model": "ur5"}, "path": _two_waypoints(), **body}
    answer = client.post(route, json=request)
    assert answer.status_code == 200, answer.text
    kind = route.removeprefix("/v1/")
    queued = client.post("/v1/jobs", json={"kind": kind, "request": request})
    assert queued.status_code == 202, queued.text
    assert client.delete(f"/v1/jobs/{queued.json()['id']}").status_code == 204
