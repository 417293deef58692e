"""Run the test suite: most of it on two worker processes, the latency tests alone after it.

The suite took 10 to 11 minutes on one process of the 2-core development machine, over the
10-minute goal. On two workers (pytest-xdist, each module on one worker) it takes about half,
but the tests that bound a live server's latency (``/healthz`` under load, a cancel within a
second, SIGTERM within seconds: marked ``latency``) fail beside a second worker's CPU-bound
tests, which take the server's time slices. So they run after, alone, with the coverage of the
first run appended. Modules are handed out in collection order, the longest first (FIRST in
tests/conftest.py), not by their number of tests. Arguments are passed to both runs; either
failing fails the whole.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(arguments: list[str]) -> int:
    """Both runs; the first failing status, else 0."""
    pytest = [sys.executable, "-m", "pytest"]
    runs = [
        [
            *pytest,
            "-n",
            "2",
            "--dist",
            "loadscope",
            "--no-loadscope-reorder",
            "-m",
            "not latency",
            *arguments,
        ],
        [*pytest, "-m", "latency", "--cov-append", *arguments],
    ]
    status = 0
    for command in runs:
        print("$", " ".join(command[1:]), flush=True)
        code = subprocess.call(command, cwd=ROOT)
        status = status or code
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
