"""The service's own log lines: their level said, once, where the operator's logging sends them.

Each case runs in a fresh interpreter (logging's state is the process's): the lines the
service writes by itself (``service.logs.log_to_stderr``, as the start calls it; a job worker's
lines go to the web process, which says them so: tests/service/test_job_runner.py), and the
lines under a logging configuration of the operator's (what ``uvicorn --log-config`` applies
before the start), read back from stdout and stderr with a regex.
"""

from __future__ import annotations

import re
import subprocess
import sys

from tests.cases import ROOT

_SAY = (
    "import logging\n"
    "{configure}"
    "from service.logs import log, log_to_stderr\n"
    "log_to_stderr()\n"
    "log_to_stderr()\n"  # a second call adds nothing
    "log.info('job a1 queued')\n"
    "log.warning('job a1 ran again')\n"
    "log.debug('not said')\n"
)


def _run(configure: str = "") -> subprocess.CompletedProcess[str]:
    code = _SAY.format(configure=configure)
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=60
    )
    assert done.returncode == 0, done.stderr[-800:]
    return done


def test_each_line_says_its_time_level_and_logger_once() -> None:
    done = _run()
    lines = done.stderr.splitlines()
    stamp = r"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d,\d{3}"
    assert len(lines) == 2, lines
    assert re.fullmatch(rf"{stamp} INFO dtf\.jobs job a1 queued", lines[0]), lines[0]
    assert re.fullmatch(rf"{stamp} WARNING dtf\.jobs job a1 ran again", lines[1]), lines[1]
    assert done.stdout == ""


def test_an_operators_configuration_places_and_filters_the_lines() -> None:
    """A root handler configured (as uvicorn --log-config does): the lines go there, once.

    They went there and to the service's own stderr handler as well (twice, one copy without
    its level), and at INFO whatever the configuration said (operator audit, M3).
    """
    configure = (
        "import sys\n"
        "logging.basicConfig(stream=sys.stdout, level=logging.WARNING,"
        " format='OPERATOR %(levelname)s %(name)s: %(message)s')\n"
    )
    done = _run(configure)
    assert done.stdout.splitlines() == ["OPERATOR WARNING dtf.jobs: job a1 ran again"]
    assert done.stderr == ""
