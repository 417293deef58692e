"""The README's example scripts without a service: one clear line, not a traceback (issue 26)."""

from __future__ import annotations

import socket
import subprocess
import sys

import pytest

from tests.cases import ROOT

SCRIPTS = ["five_axis", "accelerations", "cam_program"]


def _closed_port() -> int:
    """A port nothing listens on (bound, then released)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@pytest.mark.parametrize("script", SCRIPTS)
def test_no_service_is_one_line_naming_the_url(script: str) -> None:
    url = f"http://127.0.0.1:{_closed_port()}"
    done = subprocess.run(
        [sys.executable, str(ROOT / "examples" / f"{script}.py"), url],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 1 and done.stdout == ""
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert f"no service at {url}" in done.stderr and "Traceback" not in done.stderr
    assert "give its URL as the argument" in done.stderr


def test_the_readme_says_the_scripts_take_the_url() -> None:
    readme = (ROOT / "README.md").read_text()
    assert "at the URL given as their one argument" in readme
