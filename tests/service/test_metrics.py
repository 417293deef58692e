"""GET /metrics: the per-route latency histogram reaches the times the routes take."""

from __future__ import annotations

import re

from fastapi.testclient import TestClient


def test_route_latencies_are_bucketed_up_to_a_minute(client: TestClient) -> None:
    """Buckets ended at 1 s (the instrumentator's own), where maps and optimisations run for
    many: a 2 s and a 40 s request fell in +Inf alike (operator audit, M4)."""
    assert client.get("/healthz").status_code == 200
    text = client.get("/metrics").text
    bounds = re.findall(
        r'^http_request_duration_seconds_bucket\{handler="/healthz",le="([^"]+)",method="GET"\}',
        text,
        flags=re.MULTILINE,
    )
    assert bounds == ["0.01", "0.05", "0.1", "0.5", "1.0", "2.5", "5.0", "10.0", "30.0", "60.0",
                      "+Inf"]  # fmt: skip


def test_a_readable_job_store_is_said_up_with_its_job_series(client: TestClient) -> None:
    lines = client.get("/metrics").text.splitlines()
    assert "dtf_job_store_up 1.0" in lines
    statuses = {line.split('"')[1] for line in lines if line.startswith('dtf_jobs{status="')}
    assert statuses == {"queued", "running", "done", "failed", "cancelled"}
