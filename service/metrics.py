"""``GET /metrics``: Prometheus text, from the maintained prometheus-fastapi-instrumentator.

Request counts and latencies per route come from the instrumentator; the service adds the jobs
by status and the count and seconds of the jobs that ran to an end (read from the job store at
each scrape, since jobs run in other processes; totals that only grow, as a Prometheus summary
must), the jobs that ended by status (a total that only grows), the store's size on disk, and
the placements its synchronous maps computed.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Protocol

from fastapi import FastAPI
from fastapi.responses import PlainTextResponse
from prometheus_client import CONTENT_TYPE_LATEST, REGISTRY, Counter, generate_latest
from prometheus_client.core import CounterMetricFamily, GaugeMetricFamily, SummaryMetricFamily
from prometheus_client.registry import Collector
from prometheus_fastapi_instrumentator import Instrumentator

from service.errors import JSON_ERROR, SERVER_ERROR_RESPONSE
from service.jobs.job import JobStoreUnavailable

JOB_SECONDS = (
    "Seconds of the jobs that ran to an end, since the store began (a run a restart "
    "interrupted counts, with no seconds: how long it ran is not known)."
)

STORE_UP = "1 when the job store could be read at this scrape, 0 when not (no job series then)."

ENDED = (
    "Jobs that ended since the store began, by status (a job deleted or expired stays counted; "
    "a job cancelled before it ran counts)."
)

STORE_BYTES = (
    "Bytes the job store takes on disk: its SQLite file and its write-ahead log (results are "
    "kept DTF_JOB_TTL seconds; DTF_DATA_DIR's disk must hold them)."
)

PLACEMENTS = Counter("dtf_placements", "Placements computed by /v1/map (synchronous maps).")


class JobStatistics(Protocol):
    """What the collector reads from the job store (:class:`service.jobs.store.JobStore`)."""

    path: Path
    """The store's SQLite file."""

    def figures(self) -> tuple[dict[str, int], tuple[int, float], dict[str, int]]:
        """Jobs by status, the jobs that ran to an end and their seconds, the ended ones.

        Read in one transaction; the last two only grow.
        """
        ...


def store_bytes(path: Path) -> int:
    """The bytes of a SQLite store on disk: the file and its write-ahead log, where they are."""
    sizes = (f.stat().st_size for f in (path, path.with_name(path.name + "-wal")) if f.exists())
    return sum(sizes)


class _JobCollector(Collector):
    """Jobs by status and finished jobs' durations, read from the store at each scrape."""

    def __init__(self, store: Callable[[], JobStatistics]) -> None:
        """Read the store that ``store()`` gives at each scrape (opened on first use)."""
        self.store = store

    def describe(self) -> Iterable[GaugeMetricFamily | SummaryMetricFamily | CounterMetricFamily]:
        """The job metrics, without values: registering the collector reads no store."""
        yield GaugeMetricFamily("dtf_job_store_up", STORE_UP)
        yield GaugeMetricFamily("dtf_jobs", "Jobs by status.", labels=["status"])
        yield SummaryMetricFamily("dtf_job_seconds", JOB_SECONDS)
        yield CounterMetricFamily("dtf_jobs_ended", ENDED, labels=["status"])
        yield GaugeMetricFamily("dtf_job_store_bytes", STORE_BYTES)

    def collect(self) -> Iterable[GaugeMetricFamily | SummaryMetricFamily | CounterMetricFamily]:
        """Whether the job store can be read and, when it can, the job metrics.

        A store that cannot be used gives ``dtf_job_store_up 0`` and no job series (none that
        would read as no jobs), and the scrape goes on: it answered 503, and Prometheus lost
        the request metrics too, for as long as the store was down, when they were most
        wanted (operator audit of 2026-12-07, M2). Why it cannot be used is in the log and
        in the job routes' 503.
        """
        try:
            store = self.store()
            counts, (finished, seconds), ended = store.figures()
        except JobStoreUnavailable:
            yield GaugeMetricFamily("dtf_job_store_up", STORE_UP, value=0)
            return
        yield GaugeMetricFamily("dtf_job_store_up", STORE_UP, value=1)
        by_status = GaugeMetricFamily("dtf_jobs", "Jobs by status.", labels=["status"])
        for status in ("queued", "running", "done", "failed", "cancelled"):
            by_status.add_metric([status], counts.get(status, 0))
        yield by_status
        summary = SummaryMetricFamily("dtf_job_seconds", JOB_SECONDS)
        summary.add_metric([], count_value=finished, sum_value=seconds)
        yield summary
        by_end = CounterMetricFamily("dtf_jobs_ended", ENDED, labels=["status"])
        for status in ("done", "failed", "cancelled"):
            by_end.add_metric([status], ended.get(status, 0))
        yield by_end
        try:
            size = store_bytes(store.path)
        except OSError:  # the file gone between the read and the stat: no figure, no 500
            return
        yield GaugeMetricFamily("dtf_job_store_bytes", STORE_BYTES, value=size)


ROUTE_BUCKETS = (0.01, 0.05, 0.1, 0.5, 1.0, 2.5, 5.0, 10.0, 30.0, 60.0)
"""Seconds: the per-route latency histogram's buckets (``http_request_duration_seconds``).

The instrumentator's own (0.1, 0.5, 1) ended at a second, where maps and optimisations run
for many (an IPOPT solve alone may take DTF_MAX_SOLVER_SECONDS, 20 s): every slow request
fell in +Inf alike (operator audit of 2026-12-07, M4).
"""


def instrument(app: FastAPI, *, job_store: Callable[[], JobStatistics]) -> None:
    """Count and time every request per route, and answer ``GET /metrics``.

    Args:
        app: the application.
        job_store: gives the job store to read at each scrape (the service's runner's).
    """
    Instrumentator(excluded_handlers=["/metrics"]).instrument(
        app, latency_lowr_buckets=ROUTE_BUCKETS
    )

    @app.get(
        "/metrics",
        operation_id="metrics",
        tags=["health"],
        summary="Prometheus metrics: requests per route, jobs by status, placements",
        response_class=PlainTextResponse,
        responses={
            200: {"content": {"text/plain": {"schema": {"type": "string"}}}},
            500: {**SERVER_ERROR_RESPONSE[500], **JSON_ERROR},
        },
    )
    def metrics() -> PlainTextResponse:
        """The Prometheus text exposition of the service's metrics."""
        return PlainTextResponse(generate_latest(REGISTRY), media_type=CONTENT_TYPE_LATEST)

    if not any(isinstance(c, _JobCollector) for c in getattr(REGISTRY, "_collector_to_names", {})):
        REGISTRY.register(_JobCollector(job_store))
