"""``/v1/jobs`` in process: 503 on a bad store, the compute routes up."""

from __future__ import annotations

import json
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from service.config import Settings
from service.deps import _settings
from service.main import app
from tests.cases import ROOT

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())


def evaluate_body() -> dict[str, Any]:
    return {k: EXAMPLE[k] for k in ("robot", "path", "placement")}


@pytest.fixture
def corrupt_store(tmp_path: Path) -> Iterator[Path]:
    """The app with its jobs in ``tmp_path``, whose store file is not a database."""
    path = tmp_path / "jobs.sqlite3"
    path.write_bytes(b"not a database" * 100)
    settings = Settings(data_dir=tmp_path, workers=1)

    async def corrupt() -> Settings:
        return settings

    app.dependency_overrides[_settings] = corrupt
    yield path
    app.dependency_overrides.pop(_settings)


def test_a_corrupt_store_takes_down_the_job_routes_only(
    client: TestClient, corrupt_store: Path
) -> None:
    job = {"kind": "evaluate", "request": evaluate_body()}
    for method, url, body in [
        ("GET", "/v1/jobs", None),
        ("GET", f"/v1/jobs/{uuid.uuid4()}", None),
        ("POST", "/v1/jobs", job),
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
