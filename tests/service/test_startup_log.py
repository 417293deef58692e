"""The start says what it is doing while the kernels load or compile (issue 26)."""

from __future__ import annotations

import logging
import os
import subprocess
import sys
from pathlib import Path

import pytest
from fastapi.testclient import TestClient
from pydantic import ValidationError

from service.config import Settings
from service.main import app
from tests.cases import ROOT


def test_the_warm_up_is_logged_before_and_after(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.INFO, logger="dtf.startup"), TestClient(app):
        pass
    lines = [r.getMessage() for r in caplog.records if r.name == "dtf.startup"]
    assert len(lines) == 3, lines
    assert "compiles them, about 30 s" in lines[0]
    assert lines[1].startswith("ready after ")
    # where jobs are kept, as an absolute path, and the settings they run with (operator
    # audit M6: a relative DTF_DATA_DIR is the working directory's, and nothing said which)
    settings = Settings()
    store = (Path(settings.data_dir) / "jobs.sqlite3").resolve()
    assert lines[2].startswith(f"jobs: kept in {store}, finished ones for "), lines[2]
    assert f"(DTF_JOB_TTL = {settings.job_ttl:g} s)" in lines[2]
    assert f"{settings.workers} worker process(es) (DTF_WORKERS)" in lines[2]
    assert f"maps on {settings.threads} thread(s) (DTF_THREADS)" in lines[2]


def test_a_dtf_name_that_is_no_setting_is_warned_of() -> None:
    """DTF_WORKER=2 (for DTF_WORKERS) was ignored without a word (operator audit, M6)."""
    env = {**os.environ, "DTF_WORKER": "2"}
    code = "from service.config import settings_or_exit; settings_or_exit()"
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env, timeout=60
    )
    assert done.returncode == 0, done.stderr[-800:]
    assert done.stderr.startswith("warning: DTF_WORKER is not a setting (misspelt?): ignored")
    assert "DTF_WORKERS" not in done.stderr and "DTF_DATA_DIR" not in done.stderr


def test_an_empty_data_directory_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    """DTF_DATA_DIR= meant the working directory (operator audit, M6)."""
    monkeypatch.setenv("DTF_DATA_DIR", "")
    with pytest.raises(ValidationError, match="an empty path; name a directory"):
        Settings()
    monkeypatch.setenv("DTF_DATA_DIR", " ")
    with pytest.raises(ValidationError, match="an empty path"):
        Settings()


@pytest.mark.parametrize(
    ("variable", "value", "said"),
    [
        ("DTF_WORKERS", "abc", "Input should be a valid integer"),
        ("DTF_MAX_BODY_BYTES", "-5", "Input should be greater than 0"),
        ("DTF_DASK_SCHEDULER", "garbage", "'garbage' is not a scheduler address"),
        ("DTF_CORS_ORIGINS", "http://cam:3000/", "'http://cam:3000/' is not a web origin"),
    ],
)
def test_a_bad_setting_stops_the_start_naming_its_variable(
    variable: str, value: str, said: str, tmp_path: Path
) -> None:
    """They were refused after the warm-up (30 s on a first start) by a traceback through the
    lifespan naming the field (workers); a malformed scheduler address was taken, and every
    map job then failed as internal. Now: exit 3 before the warm-up, one line naming each."""
    env = {**os.environ, variable: value, "DTF_DATA_DIR": str(tmp_path)}
    done = subprocess.run(
        [sys.executable, "-m", "uvicorn", "service.main:app", "--port", "0"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
        timeout=120,
    )
    assert done.returncode == 3, done.stderr[-800:]
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {variable}={value!r}: {said}"), lines
    assert "Traceback" not in done.stderr and "warming up" not in done.stderr


def test_a_scheduler_address_of_host_and_port_is_taken() -> None:
    for address in ("tcp://127.0.0.1:8786", "host1:8786", "tls://[::1]:8786"):
        assert Settings(dask_scheduler=address).dask_scheduler == address
