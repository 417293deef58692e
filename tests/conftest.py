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


FIRST = (
    "tests/web/test_page_answers.py",
    "tests/test_contract_other_routes.py",
    "tests/test_contract_evaluate_and_jobs.py",
    "tests/test_jobs.py",
    "tests/web/test_page_cell.py",
    "tests/web/test_page.py",
    "tests/service/test_cli.py",
    "tests/web/test_page_findings.py",
    "tests/solver/test_active_set.py",
    "tests/web/test_page_jobs.py",
    "tests/solver/test_optimize.py",
    "tests/test_jobs_dask.py",
)
"""The longest modules, longest first, before all others (scripts/run_tests.py keeps
collection order): 104, 97, 95, 69, 67, 59, 49, 48, 44, 41, 39 and 36 s of the suite's 1,222 s
of test time on two workers (2026-12-06), the next under 24 s.

Each of the two workers takes the next module when it is free (``--dist loadscope``), so the
longest first leaves short ones to even out the end. xdist's default order (scopes by their
number of tests) gave the contract tests out near the end, so one worker ran them alone for
minutes after the other had finished; with only the contract modules first, the web modules,
in collection order, came last."""


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The modules of FIRST before the others, in FIRST's order, each keeping its own order."""
    rank = {module: index for index, module in enumerate(FIRST)}
    items.sort(key=lambda item: rank.get(item.nodeid.split("::")[0], len(FIRST)))


@pytest.fixture(scope="session", autouse=True)
def _jobs_stop_at_the_end() -> Iterator[None]:
    yield
    from service.jobs.runner import close_runners

    close_runners()
