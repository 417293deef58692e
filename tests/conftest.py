"""Settings for every test process: jobs kept in a temporary directory, small and few.

The app reads its settings on first use, after this module has set the environment; the
in-process tests that reach ``/v1/jobs`` (the schemathesis fuzz) then queue small jobs in one
worker process, under a directory removed when the run ends, never under the repository.
"""

from __future__ import annotations

import atexit
import os
import shutil
import tempfile
from collections.abc import Iterator

import pytest

if "DTF_DATA_DIR" not in os.environ:
    # Made by the first process (pytest-xdist's controller), whose workers inherit it, and
    # removed when that process exits, after its workers: a directory made in every process
    # and removed by the workers' session end left the controller's, the one the workers
    # used, in the temporary directory after every run.
    _DATA = tempfile.mkdtemp(prefix="dtf-test-jobs-")
    os.environ["DTF_DATA_DIR"] = _DATA
    atexit.register(shutil.rmtree, _DATA, ignore_errors=True)
os.environ.setdefault("DTF_WORKERS", "1")
os.environ.setdefault("DTF_MAX_JOB_CELLS", "2000")
os.environ.setdefault("DTF_MAX_JOB_POSES", "200000")
# In-process requests queue jobs that no worker may ever take (a TestClient without lifespan):
# the fuzz alone leaves dozens, so one worker process's later modules met the default limit of
# 100 depending on which modules it ran. The tests of the limit set their own.
os.environ.setdefault("DTF_MAX_QUEUED_JOBS", "100000")


FIRST = ("tests/test_contract_evaluate_and_jobs.py", "tests/test_contract_other_routes.py")
"""Modules that start first on the two workers (scripts/run_tests.py keeps collection order).

The contract tests are more than half of the suite's time in a handful of tests; xdist's
default order (scopes by their number of tests) gave them out near the end, so one worker ran
them alone for minutes after the other had finished. In one module they still kept one worker
busy for minutes after the other had finished (about 2,150 s of test time against 1,470 s for
everything else, under load); in two, each worker starts with one."""


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The modules of FIRST before the others, each keeping its own order."""
    items.sort(key=lambda item: item.nodeid.split("::")[0] not in FIRST)


@pytest.fixture(scope="session", autouse=True)
def _jobs_stop_at_the_end() -> Iterator[None]:
    yield
    from service.jobs.runner import close_runners

    close_runners()
