"""Run the tests: the kernels compiled first, most tests on two workers, the latency tests alone.

1. The numba kernels are compiled into their disk cache (``scripts/compile_kernels.py``, its
   groups in two processes, the cores): on a fresh clone about 180 s of CPU, which the two
   workers and the live servers they start would otherwise each spend on the kernels they meet
   together (the map kernels in a server's warm-up and in the other worker's tests at once).
   The project's sources are compiled to bytecode too (``compileall``, about 1 s): where
   ``PYTHONDONTWRITEBYTECODE`` is set (the development machine sets it) nothing is cached at
   import, and each of the hundred-odd processes the tests start (live servers, job workers,
   the command's runs) compiled the modules of ``solver`` and ``service`` again (261 in a job
   worker): 0.35 s of CPU each (2.32 s against 2.65 to import the service and a job worker,
   best of 8, 2026-12-07).
2. The tests on two worker processes (pytest-xdist, each module on one worker, handed out in
   collection order, the longest first: FIRST in tests/conftest.py). One process took 10 to 11
   minutes on the 2-core development machine, over the 10-minute goal.
3. The tests that bound a live server's latency (``/healthz`` under load, a cancel within a
   second, SIGTERM within seconds: marked ``latency``), alone: beside a second worker's
   CPU-bound tests they fail, since those take the server's time slices. Only their modules
   (``LATENCY_MODULES``) are collected, unless arguments are given.

``--coverage`` adds a coverage report of ``solver`` and ``service`` (both runs, combined): it
makes the suite about half as long again, so it is asked for, not the default. Other arguments
are passed to both pytest runs. Any step failing fails the whole.
"""

from __future__ import annotations

import compileall
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
COMPILE_GROUPS = (("numeric6", "numeric7"), ("analytic", "cell"))
"""scripts/compile_kernels.py's groups in two processes: about 99 and 81 s on a fresh clone
(2026-12-06). The numeric groups share a process, where the seven-joint group reuses the
six-joint group's seeding and following (one signature each) and takes 26 s, not the 45 s it took
beside the analytic and cell groups; these share the UR kernels. The earlier split, numeric6
alone against the other three, took 126 s: 85 against 122."""
COVERAGE = ["--cov=solver", "--cov=service", "--cov-report=term:skip-covered"]
LATENCY_MODULES = (
    "tests/test_live_server.py",
    "tests/test_jobs.py",
    "tests/test_jobs_dask.py",
    "tests/service/test_job_runner.py",
)
"""The modules with tests marked ``latency``, the only ones the latency run collects: collecting
every module (the contract tests build their cases then) took 27 of its 82 s, 2026-12-03.
tests/test_run_tests.py holds the list to the modules that use the mark."""


def compile_kernels() -> int:
    """Every group of scripts/compile_kernels.py at once; the first failing status, else 0."""
    start = time.perf_counter()
    script = str(ROOT / "scripts" / "compile_kernels.py")
    processes = [
        subprocess.Popen([sys.executable, script, *groups], cwd=ROOT) for groups in COMPILE_GROUPS
    ]
    codes = [process.wait() for process in processes]
    print(f"kernels ready in {time.perf_counter() - start:.1f} s", flush=True)
    return next((code for code in codes if code), 0)


SOURCES = ("solver", "service")
"""The packages whose bytecode :func:`compile_sources` writes (the tests' own are pytest's)."""


def compile_sources() -> bool:
    """Write the bytecode of :data:`SOURCES` into their ``__pycache__``; False if any failed."""
    return all(compileall.compile_dir(ROOT / name, quiet=1) for name in SOURCES)


def main(arguments: list[str]) -> int:
    """Compile, then both runs; the first failing status, else 0."""
    coverage = "--coverage" in arguments
    arguments = [a for a in arguments if a != "--coverage"]
    pytest = [sys.executable, "-m", "pytest"]
    workers = ["-n", "2", "--dist", "loadscope", "--no-loadscope-reorder", "-m", "not latency"]
    runs = [
        [*pytest, *workers, *(COVERAGE if coverage else []), *arguments],
        [
            *pytest,
            "-m",
            "latency",
            *([*COVERAGE, "--cov-append"] if coverage else []),
            *(arguments or LATENCY_MODULES),  # the modules, where no argument chooses tests
        ],
    ]
    status = 0 if compile_sources() else 1  # first: the kernels' processes import them too
    print("$ scripts/compile_kernels.py", flush=True)
    status = status or compile_kernels()
    for command in runs:
        print("$", " ".join(command[1:]), flush=True)
        code = subprocess.call(command, cwd=ROOT)
        status = status or code
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
