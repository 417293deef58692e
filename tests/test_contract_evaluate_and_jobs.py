"""The contract (``tests/contract_live.py``) of ``POST /v1/evaluate`` and the ``/v1/jobs`` routes.

The other operations are in ``tests/test_contract_other_routes.py``: the two modules, each with
its own live server, run on the suite's two workers at once.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from tests.contract_live import contract_tests, evaluate_or_jobs, live_server


@pytest.fixture(scope="module")
def live_url() -> Iterator[str]:
    """A live server with the contract limits, for this module's operations."""
    yield from live_server("evaluate-and-jobs")


globals().update(contract_tests(evaluate_or_jobs))
