"""The machine's own stalls, seen by a process that only sleeps, to set apart from a server's.

A latency test bounds how long a live server takes to answer while its job workers fill the CPUs.
Some machines stop every process at once for a while when their CPUs are all busy (a CPU quota
of the virtual machine: the development machine, 2026-12-07, stopped everything for about 100 ms
at a time once both CPUs were used, and never with one). Such a stall is neither caused nor
avoidable by the server; what the test bounds is the rest. ``MachineStalls`` runs a separate
Python process that waits 1 ms at a time and reports each wait that overran by more than
``THRESHOLD``; ``within(start, end)`` is how much of a probe's interval those stalls covered.
Shorter overruns are not taken out (the bound then stays as strict as it was), and a server's own
blocking (its event loop held by work) does not stop the sleeper: it stays in the probe's time.
"""

from __future__ import annotations

import subprocess
import sys
import time
from types import TracebackType

THRESHOLD = 0.005
"""A wait that overran by more than this is a stall; the clock is time.monotonic, the same
CLOCK_MONOTONIC in every process."""

_SLEEPER = f"""
import select, sys, time
print("ready", flush=True)
last = time.monotonic()
while not select.select([sys.stdin], [], [], 0.001)[0]:
    now = time.monotonic()
    if now - last > 0.001 + {THRESHOLD}:
        print(last + 0.001, now, flush=True)
    last = now
"""


class MachineStalls:
    """A sleeper process for the ``with`` block; its stalls are read at the block's end."""

    def __init__(self) -> None:
        self.stalls: list[tuple[float, float]] = []
        self._process: subprocess.Popen[str] | None = None

    def __enter__(self) -> MachineStalls:
        self._process = subprocess.Popen(
            [sys.executable, "-c", _SLEEPER],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert self._process.stdout is not None
        assert self._process.stdout.readline().strip() == "ready"
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        assert self._process is not None
        output, _ = self._process.communicate(input="", timeout=10)
        self.stalls = [
            (float(start), float(end))
            for start, end in (line.split() for line in output.splitlines())
        ]

    def within(self, start: float, end: float) -> float:
        """The seconds of [start, end] (time.monotonic) the machine was stalled."""
        return sum(
            max(0.0, min(end, s_end) - max(start, s_start)) for s_start, s_end in self.stalls
        )

    @property
    def total(self) -> float:
        return sum(end - start for start, end in self.stalls)


def now() -> float:
    """The clock ``within`` takes."""
    return time.monotonic()
