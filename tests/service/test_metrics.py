"""GET /metrics: the per-route latency histogram reaches the times the routes take."""

from __future__ import annotations

import os
import re
import sqlite3
from pathlib import Path
from typing import Any
from unittest import mock

from fastapi.testclient import TestClient

from service.jobs.store import JobStore
from service.metrics import _JobCollector


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


def test_the_job_stores_size_on_disk_and_its_ended_jobs(client: TestClient, tmp_path: Path) -> None:
    """An operator saw the store reach 318 MB only by looking at the disk (operator audit, L3):
    the gauge is the file's and its write-ahead log's sizes, read here with os.stat."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    for _ in range(3):
        job = store.create("evaluate", {"robot": "ur5e", "padding": "x" * 50_000})
        assert store.start(job.id)
        store.finish(job.id, "done", result={"feed": 0.1, "padding": "y" * 50_000})
    collected = {m.name: m for m in _JobCollector(lambda: store).collect()}
    [sample] = collected["dtf_job_store_bytes"].samples
    files = [tmp_path / "jobs.sqlite3", tmp_path / "jobs.sqlite3-wal"]
    assert sample.value == sum(os.stat(f).st_size for f in files if f.exists())
    assert sample.value > 3 * 100_000  # the bodies are in it
    ended = {s.labels["status"]: s.value for s in collected["dtf_jobs_ended"].samples}
    assert ended == {"done": 3, "failed": 0, "cancelled": 0}
    scraped = re.search(r"^dtf_job_store_bytes (\S+)$", client.get("/metrics").text, re.M)
    assert scraped is not None and float(scraped[1]) > 0  # the service's own store
    text = client.get("/metrics").text
    for status in ("done", "failed", "cancelled"):
        assert re.search(rf'^dtf_jobs_ended_total{{status="{status}"}} \d', text, re.M), status


def test_a_scrape_reads_the_store_once_in_one_transaction(tmp_path: Path) -> None:
    """The jobs by status and the ended jobs came from two connections, each its own read: a
    job that ended between them was counted running by one and ended by the other. Every
    statement of a scrape now runs on one connection, inside one BEGIN ... COMMIT (SQLite's
    trace of the statements, read here)."""
    store = JobStore(tmp_path / "jobs.sqlite3")
    job = store.create("evaluate", {"robot": "ur5e"})
    assert store.start(job.id)
    store.finish(job.id, "done", result={"feed": 0.1})
    opened: list[list[str]] = []
    connect = sqlite3.connect

    def traced(*args: Any, **kwargs: Any) -> sqlite3.Connection:
        db = connect(*args, **kwargs)
        statements: list[str] = []
        opened.append(statements)
        db.set_trace_callback(statements.append)
        return db

    with mock.patch.object(sqlite3, "connect", traced):
        collected = {m.name: m for m in _JobCollector(lambda: store).collect()}
    assert len(opened) == 1
    [statements] = opened
    assert statements[0] == "BEGIN" and statements[-1] == "COMMIT"
    assert sum(s.startswith("SELECT") for s in statements) == 3
    held = {s.labels["status"]: s.value for s in collected["dtf_jobs"].samples}
    ended = {s.labels["status"]: s.value for s in collected["dtf_jobs_ended"].samples}
    assert held["done"] == ended["done"] == 1
