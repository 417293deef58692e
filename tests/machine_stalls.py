"""The machine's own stalls, seen by processes that only sleep, to set apart from a server's.

A latency test bounds how long a live server takes to answer while its work fills the CPUs.
Some machines stop a CPU for a while when they are all busy: the development machine's
hypervisor (2026-12-07) took about 100 ms at a time from one virtual CPU or the other once both
were used (vmstat's steal 4 to 26 %; never with one busy), which stops whatever runs there, the
server's event loop or the test's client. Neither is caused nor avoidable by the server; what
the test bounds is the rest. ``MachineStalls`` runs one Python process per CPU, pinned to it,
that waits 1 ms at a time and reports each wait that overran by more than ``THRESHOLD``;
``within(start, end)`` is how much of a probe's interval some CPU was stalled (the union of
the stalls: which CPU the probe's threads were on is not known, so a stall of either counts).
Shorter overruns are not taken out (the bound then stays as strict as it was), and a server's
own blocking (its event loop held by work) does not stop the sleepers: it stays in the probe's
time.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import time
from types import TracebackType

THRESHOLD = 0.005
"""A wait that overran by more than this is a stall; the clock is time.monotonic, the same
CLOCK_MONOTONIC in every process."""

_SLEEPER = f"""
import os, select, sys, time
os.sched_setaffinity(0, {{int(sys.argv[1])}})
print("ready", flush=True)
last = time.monotonic()
while not select.select([sys.stdin], [], [], 0.001)[0]:
    now = time.monotonic()
    if now - last > 0.001 + {THRESHOLD}:
        print(last + 0.001, now, flush=True)
    last = now
"""


class MachineStalls:
    """A sleeper process a CPU for the ``with`` block; their stalls are read at its end."""

    def __init__(self) -> None:
        self.stalls: list[tuple[float, float]] = []
        self._processes: list[subprocess.Popen[str]] = []

    def __enter__(self) -> MachineStalls:
        self._processes = [
            subprocess.Popen(
                [sys.executable, "-c", _SLEEPER, str(cpu)],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                text=True,
            )
            for cpu in sorted(os.sched_getaffinity(0))
        ]
        for process in self._processes:
            assert process.stdout is not None
            assert process.stdout.readline().strip() == "ready"
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        for process in self._processes:
            output, _ = process.communicate(input="", timeout=10)
            self.stalls += [
                (float(start), float(end))
                for start, end in (line.split() for line in output.splitlines())
            ]
        self.stalls.sort()

    def within(self, start: float, end: float) -> float:
        """The seconds of [start, end] (time.monotonic) some CPU was stalled (their union)."""
        total, reached = 0.0, start
        for s_start, s_end in self.stalls:  # sorted by start
            low, high = max(s_start, reached), min(s_end, end)
            if high > low:
                total += high - low
                reached = high
        return total

    def less_stalls(self, start: float, end: float) -> float:
        """A probe's time from ``start`` to ``end`` less the time some CPU was stalled in it."""
        return end - start - self.within(start, end)

    @property
    def total(self) -> float:
        """The seconds some CPU was stalled while the block ran."""
        return self.within(-math.inf, math.inf)


def now() -> float:
    """The clock ``within`` takes."""
    return time.monotonic()
