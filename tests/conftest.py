"""Settings for every test process: their own, jobs kept in a temporary directory, small and few.

The run's first process (pytest-xdist's controller, or the only one) settles the environment
when this module is imported, before any other (:func:`settle_environment`); its workers, and
every process a test starts, inherit it. The app reads its settings on first use, after that:
the in-process tests that reach ``/v1/jobs`` (the schemathesis fuzz) then queue small jobs in
one worker process, under a directory removed when the run ends, never under the repository.
"""

from __future__ import annotations

import atexit
import os
import shutil
import tempfile
from collections.abc import Iterator

import pytest

SETTINGS = {
    "DTF_WORKERS": "1",
    "DTF_MAX_JOB_CELLS": "2000",
    "DTF_MAX_JOB_POSES": "200000",
    # In-process requests queue jobs that no worker may ever take (a TestClient without
    # lifespan): the fuzz alone leaves dozens, so one worker process's later modules met the
    # default limit of 100 depending on which modules it ran. The tests of the limit set their
    # own.
    "DTF_MAX_QUEUED_JOBS": "100000",
}
"""The settings every test process starts with, besides DTF_DATA_DIR; the others default."""
SETTLED_BY = "PYTEST_DTF_SETTLED_BY"
"""The variable naming the process that settled the environment (its pid): a pytest-xdist
worker whose parent it is inherits its settings. Not a DTF_ name (the app warns of those)."""


def settle_environment() -> None:
    """In a run's first process: the DTF_ settings of the environment out, the tests' own in.

    A shell that serves the app has its settings in the environment (README: settings are
    DTF_ variables), and the tests took them: with DTF_DATA_DIR set the in-process tests
    queued their jobs in that service's own store, and a lowered limit (DTF_MAX_MAP_CELLS=100)
    failed 50 of the service tests (stop 76). They are left out, and named at the run's end
    (:func:`pytest_terminal_summary`). A worker of this run keeps what it inherits; a pytest
    run started by a test settles its own. The jobs directory is made here, by the first
    process, and removed when it exits, after its workers: a directory made in every process
    and removed by the workers' session end left the controller's, the one the workers used,
    in the temporary directory after every run.
    """
    worker = "PYTEST_XDIST_WORKER" in os.environ  # set by pytest-xdist before conftests load
    if worker and os.environ.get(SETTLED_BY) == str(os.getppid()):
        return
    inherited = sorted(name for name in os.environ if name.startswith("DTF_"))
    for name in inherited:
        del os.environ[name]
    LEFT_OUT.extend(inherited)
    data = tempfile.mkdtemp(prefix="dtf-test-jobs-")
    atexit.register(shutil.rmtree, data, ignore_errors=True)
    os.environ.update({"DTF_DATA_DIR": data, SETTLED_BY: str(os.getpid()), **SETTINGS})


LEFT_OUT: list[str] = []
"""The DTF_ variables :func:`settle_environment` took out of this process's environment."""
settle_environment()


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> None:
    """Name the DTF_ settings of the environment the run left out, whatever its verbosity."""
    if LEFT_OUT:
        terminalreporter.write_line(
            "the DTF_ settings of the environment were left out (the tests set their own): "
            + ", ".join(LEFT_OUT)
        )


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
