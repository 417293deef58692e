"""Schemathesis against the committed spec, in process: no input of any shape is a server error.

Seeded and bounded (issue 9). Here the generated requests go in as generated, the rules the
spec states in words (unit vectors, one q per joint...) not met, so only the server-error check
runs; ``tests/test_contract.py`` runs every check on a live server.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable

import hypothesis
import schemathesis
from schemathesis.checks import not_a_server_error

from service.main import app
from tests.cases import ROOT

schema = schemathesis.openapi.from_dict(json.loads((ROOT / "openapi" / "openapi.json").read_text()))
schema.app = app  # the committed spec, served by the app in process


def _fuzz_test(label: str) -> Callable[..., None]:
    """The test of one operation, under its own test id (pytest-xdist schedules by id)."""
    method, path = label.split(" ", 1)

    @schema.include(method=method, path=path).parametrize()
    @hypothesis.settings(
        max_examples=40,
        phases=[hypothesis.Phase.generate],  # the spec's examples run in tests/test_contract.py
        deadline=None,
        derandomize=True,
        suppress_health_check=list(hypothesis.HealthCheck),
    )
    def test(case: schemathesis.Case) -> None:
        case.call_and_validate(checks=[not_a_server_error], timeout=120)

    return test


for _label in [operation.ok().label for operation in schema.get_all_operations()]:
    _name = "test_no_input_is_a_server_error_" + re.sub(r"\W+", "_", _label).strip("_").lower()
    globals()[_name] = _fuzz_test(_label)
