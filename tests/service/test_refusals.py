"""Each refused request is logged with the reason its answer gives (operator audit, M4).

uvicorn's access line gave the status alone ("POST /v1/map HTTP/1.1" 422): nothing said which
field, which limit or which queue. Requests through the app (a TestClient), the lines of
``dtf.requests`` read back and compared with the answer's own first detail.
"""

from __future__ import annotations

import asyncio
import json
import logging
import re
import time

import httpx
import pytest
from fastapi.testclient import TestClient
from starlette.types import Message, Receive, Scope, Send

from service import refusals
from service.refusals import KEEP, RefusalLogMiddleware, reason_of
from tests.cases import ROOT

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())


def _said(caplog: pytest.LogCaptureFixture) -> list[tuple[str, str]]:
    return [(r.levelname, r.getMessage()) for r in caplog.records if r.name == "dtf.requests"]


def _line(method: str, path: str, answer: httpx.Response) -> tuple[str, str]:
    """The line an answer should give: its first detail's loc and msg, and how many more."""
    details = answer.json()["detail"]
    where = ".".join(str(part) for part in details[0]["loc"])
    reason = f"{where}: {details[0]['msg']}" if where else details[0]["msg"]
    more = f" (and {len(details) - 1} more)" if len(details) > 1 else ""
    return ("INFO", f"{method} {path} {answer.status_code}: {reason}{more}")


def test_a_refusal_is_logged_with_its_first_detail(
    client: TestClient, caplog: pytest.LogCaptureFixture
) -> None:
    bad = {**EXAMPLE, "placement": {**EXAMPLE["placement"], "x": "far", "y": None}}
    unknown = "/v1/jobs/00000000-0000-4000-8000-000000000000"
    with caplog.at_level(logging.INFO, logger="dtf.requests"):
        answer = client.post("/v1/evaluate", json=bad)
        missing = client.get(unknown)
        refused = client.post("/v1/evaluate", content=b"x", headers={"content-type": "text/plain"})
        fine = client.get("/healthz")
    assert (answer.status_code, missing.status_code, refused.status_code) == (422, 404, 415)
    assert fine.status_code == 200  # no line
    assert len(answer.json()["detail"]) == 2
    assert _said(caplog) == [
        _line("POST", "/v1/evaluate", answer),
        _line("GET", unknown, missing),
        _line("POST", "/v1/evaluate", refused),
    ]
    assert _said(caplog)[0][1].endswith(" (and 1 more)")


def test_a_body_without_a_detail_list_is_said_so() -> None:
    assert reason_of(b"<html>") == "no detail list"
    assert reason_of(b'{"detail": "a string"}') == "no detail list"
    assert reason_of(b'{"detail": [{"loc": [], "msg": "' + b"m" * 300 + b'"}]}') == "m" * 200


def test_a_long_detail_list_cut_still_gives_its_first_detail() -> None:
    """A refusal of thousands of details (a long path wrong everywhere) is kept to its first
    KEEP bytes, which do not parse: the first detail is read from them."""
    details = [
        {"loc": ["body", "path", "waypoints", k, "x"], "msg": 'not a "number"', "type": "t"}
        for k in range(3000)
    ]
    body = json.dumps({"detail": details}, separators=(",", ":")).encode()
    assert len(body) > KEEP
    assert reason_of(body[:KEEP], cut=True) == 'body.path.waypoints.0.x: not a "number" (and more)'
    assert reason_of(b'{"detail":[{"lo', cut=True) == f"an answer over {KEEP} bytes"


def _through_the_middleware(
    answer: list[Message], caplog: pytest.LogCaptureFixture, *, after: float = 0.0
) -> tuple[list[Message], list[tuple[str, str]]]:
    """The messages an app's ``answer`` (sent ``after`` seconds) reaches the server as, and the
    lines it gave."""

    async def app(scope: Scope, receive: Receive, send: Send) -> None:
        await asyncio.sleep(after)
        for message in answer:
            await send(message)

    async def receive() -> Message:
        return {"type": "http.request", "body": b"", "more_body": False}

    sent: list[Message] = []

    async def send(message: Message) -> None:
        sent.append(message)

    scope: Scope = {"type": "http", "method": "POST", "path": "/v1/evaluate", "headers": []}
    with caplog.at_level(logging.INFO, logger="dtf.requests"):
        asyncio.run(RefusalLogMiddleware(app)(scope, receive, send))
    return sent, _said(caplog)


def test_the_middleware_keeps_a_long_answers_start_and_passes_every_message_on(
    caplog: pytest.LogCaptureFixture,
) -> None:
    details = [{"loc": ["body", "path", k], "msg": "bad", "type": "t"} for k in range(4000)]
    body = json.dumps({"detail": details}, separators=(",", ":")).encode()
    half = len(body) // 2
    answer: list[Message] = [
        {"type": "http.response.start", "status": 422, "headers": []},
        {"type": "http.response.body", "body": body[:half], "more_body": True},
        {"type": "http.response.body", "body": body[half:], "more_body": False},
    ]
    sent, said = _through_the_middleware(answer, caplog)
    assert sent == answer
    assert said == [("INFO", "POST /v1/evaluate 422: body.path.0: bad (and more)")]


def test_a_client_that_left_has_no_refusal_line(caplog: pytest.LogCaptureFixture) -> None:
    """A 499 is said by service.errors.client_left already: no second line, its body passed on."""
    body = json.dumps({"detail": [{"loc": [], "msg": "the client left", "type": "t"}]}).encode()
    answer: list[Message] = [
        {"type": "http.response.start", "status": 499, "headers": []},
        {"type": "http.response.body", "body": body, "more_body": False},
    ]
    sent, said = _through_the_middleware(answer, caplog)
    assert sent == answer
    assert said == []


def test_a_slow_answer_is_logged_with_its_time_and_a_fast_one_is_not(
    caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    """uvicorn's access line has no duration: which request was slow could not be told (the
    operator audit of 2026-12-07). Slow is SLOW_SECONDS; lowered here to keep the test short."""
    ok: list[Message] = [
        {"type": "http.response.start", "status": 200, "headers": []},
        {"type": "http.response.body", "body": b"{}", "more_body": False},
    ]
    assert refusals.SLOW_SECONDS == 1.0
    assert _through_the_middleware(ok, caplog)[1] == []  # fast: uvicorn's line is enough
    monkeypatch.setattr(refusals, "SLOW_SECONDS", 0.05)
    began = time.perf_counter()
    sent, said = _through_the_middleware(ok, caplog, after=0.08)
    took = time.perf_counter() - began
    assert sent == ok and len(said) == 1, said
    level, line = said[0]
    found = re.fullmatch(r"POST /v1/evaluate 200 in (\S+) s", line)
    assert level == "INFO" and found is not None, line
    assert 0.08 <= float(found[1]) <= took + 0.001
    caplog.clear()
    refused: list[Message] = [
        {"type": "http.response.start", "status": 422, "headers": []},
        {"type": "http.response.body", "body": b'{"detail":[]}', "more_body": False},
    ]
    assert _through_the_middleware(refused, caplog, after=0.08)[1] == [
        ("INFO", "POST /v1/evaluate 422: no detail list")
    ]  # its refusal line alone
