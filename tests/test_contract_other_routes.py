"""The contract (``tests/contract_live.py``) of every operation but evaluate's JSON and the jobs.

Those are in ``tests/test_contract_evaluate_and_jobs.py``; here are the pictures, the
optimisation, the map, the DTF, paths, robots, health and metrics. The two modules, each with
its own live server, run on the suite's two workers at once.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from tests.contract_live import contract_tests, evaluate_or_jobs, live_server


@pytest.fixture(scope="module")
def live_url() -> Iterator[str]:
    """A live server with the contract limits, for this module's operations."""
    yield from live_server("other-routes")


globals().update(contract_tests(lambda name: not evaluate_or_jobs(name)))
