"""Fixtures of the service tests: a client, request bodies, the Panda URDF, the settings."""

from __future__ import annotations

import copy
import importlib.metadata
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from service.config import Settings, get_settings
from service.deps import _settings
from service.main import app
from service.schemas import DtfRequest, EvaluateRequest


def example_body(model: type[DtfRequest] | type[EvaluateRequest]) -> dict[str, Any]:
    """A fresh copy of the first example of a request schema (the one /docs shows)."""
    extra = model.model_config.get("json_schema_extra")
    assert isinstance(extra, dict)
    return copy.deepcopy(extra["examples"][0])


@pytest.fixture(scope="session")
def client() -> Iterator[TestClient]:
    with TestClient(app) as test_client:
        yield test_client


@pytest.fixture
def dtf_body() -> dict[str, Any]:
    """A valid /v1/dtf body: ur5e at a regular configuration, h = 0.5 m."""
    return example_body(DtfRequest)


@pytest.fixture
def evaluate_body() -> dict[str, Any]:
    """A valid, feasible /v1/evaluate body: ur5, two waypoints of examples/, auto branch."""
    return example_body(EvaluateRequest)


@pytest.fixture(scope="session")
def panda_urdf() -> str:
    dist = importlib.metadata.distribution("example-robot-data")
    path = dist.locate_file(
        "cmeel.prefix/share/example-robot-data/robots/panda_description/urdf/panda.urdf"
    )
    return Path(str(path)).read_text()


@pytest.fixture
def body_limit(monkeypatch: pytest.MonkeyPatch) -> Iterator[int]:
    """A 500-byte body limit, set through the environment as a deployment would."""
    monkeypatch.setenv("DTF_MAX_BODY_BYTES", "500")
    get_settings.cache_clear()
    yield 500
    get_settings.cache_clear()


def sent_back(placement: dict[str, Any]) -> dict[str, Any]:
    """An answer's placement as a request takes it: x, y, z, yaw, spin (its frames left out)."""
    return {key: placement[key] for key in ("x", "y", "z", "yaw", "spin")}


@contextmanager
def served_with(settings: Settings) -> Iterator[None]:
    """The app's routes and jobs run with ``settings`` while the block runs."""

    async def given() -> Settings:
        return settings

    app.dependency_overrides[_settings] = given
    try:
        yield
    finally:
        app.dependency_overrides.pop(_settings)


@pytest.fixture
def own_store(tmp_path: Path) -> Iterator[Path]:
    """The app with its jobs in ``tmp_path``: a queue no other test of this process fills.

    The session's store is shared with the in-process fuzz, whose queued jobs may fill the
    queue to its limit (checked in the insert's transaction): a POST would then be a 429.
    """
    with served_with(Settings(data_dir=tmp_path, workers=1)):
        yield tmp_path
