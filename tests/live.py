"""A live uvicorn server, for the tests that need real connections (contract, SIGTERM)."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

from tests.cases import ROOT


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def start_server(env: dict[str, str], *options: str) -> tuple[subprocess.Popen[bytes], str]:
    """A uvicorn process serving the app on a free port, once it answers /healthz."""
    port = _free_port()
    url = f"http://127.0.0.1:{port}"
    process = subprocess.Popen(
        [sys.executable, "-m", "uvicorn", "service.main:app", "--port", str(port), *options],
        cwd=ROOT,
        env={**os.environ, **env},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(url + "/healthz", timeout=1):
                return process, url
        except OSError:
            time.sleep(0.2)
    process.kill()
    raise RuntimeError("the server did not start within 60 s")


def stat_fields(stat: Path) -> list[str]:
    """A /proc stat file's fields after the command's name: the state first, then the parent.

    The name (field 2) is in parentheses and may hold spaces and parentheses itself: the fields
    are read after its last ``)``. Raises OSError where the process (or thread) has ended.
    """
    return stat.read_text().rsplit(")", 1)[1].split()


def descendants(pid: int) -> set[int]:
    """The processes started by ``pid``, by their children and so on (read from /proc)."""
    children: dict[int, list[int]] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            parent = int(stat_fields(stat)[1])
        except OSError:  # it ended while we read
            continue
        children.setdefault(parent, []).append(int(stat.parent.name))
    found: set[int] = set()
    todo = [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            if child not in found:
                found.add(child)
                todo.append(child)
    return found


def running(pids: set[int]) -> set[int]:
    """Those of ``pids`` that still run (a zombie, ended but not reaped, does not)."""
    alive = set()
    for pid in pids:
        try:
            state = stat_fields(Path("/proc") / str(pid) / "stat")[0]
        except OSError:
            continue
        if state not in ("Z", "X"):
            alive.add(pid)
    return alive
