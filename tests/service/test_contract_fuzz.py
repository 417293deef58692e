"""Schemathesis against the committed spec, in process: no input of any shape is a server error.

Seeded and bounded (issue 9). Here the generated requests go in as generated, the rules the
spec states in words (unit vectors, one q per joint...) not met, so only the server-error check
runs; ``tests/contract_live.py`` runs every check on a live server.
"""

from __future__ import annotations

import json
from collections.abc import Callable

import hypothesis
import schemathesis
from schemathesis.checks import not_a_server_error

from service.main import app
from tests.cases import ROOT
from tests.contract_hooks import operations

schema = schemathesis.openapi.from_dict(json.loads((ROOT / "openapi" / "openapi.json").read_text()))
schema.app = app  # the committed spec, served by the app in process


def _fuzz_test(method: str, path: str) -> Callable[..., None]:
    """The test of one operation (one function each: contract_hooks.operations)."""

    @schema.include(method=method, path=path).parametrize()
    @hypothesis.settings(
        max_examples=40,
        phases=[hypothesis.Phase.generate],  # the spec's examples run in tests/contract_live.py
        deadline=None,
        derandomize=True,
        suppress_health_check=list(hypothesis.HealthCheck),
    )
    def test(case: schemathesis.Case) -> None:
        case.call_and_validate(checks=[not_a_server_error], timeout=120)

    return test


for _method, _path, _name in operations(schema):
    globals()["test_no_input_is_a_server_error_" + _name] = _fuzz_test(_method, _path)
