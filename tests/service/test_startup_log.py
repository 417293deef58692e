"""The start says what it is doing while the kernels load or compile (issue 26)."""

from __future__ import annotations

import logging

import pytest
from fastapi.testclient import TestClient

from service.main import app


def test_the_warm_up_is_logged_before_and_after(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.INFO, logger="dtf.startup"), TestClient(app):
        pass
    lines = [r.getMessage() for r in caplog.records if r.name == "dtf.startup"]
    assert len(lines) == 2, lines
    assert "compiles them, about 30 s" in lines[0]
    assert lines[1].startswith("ready after ")
