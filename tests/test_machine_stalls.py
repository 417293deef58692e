"""The sleeper that sets the machine's stalls apart (tests/machine_stalls.py) sees a stall.

A stall is made by stopping a CPU's sleeper (SIGSTOP, then SIGCONT after a measured time):
what it reports must cover that interval, and ``within`` must cut the stalls to a probe's
interval and count time two CPUs were stalled once. (The machine's own stalls may add intervals
of their own: nothing here bounds them.)
"""

from __future__ import annotations

import signal
import time

import pytest

from tests import machine_stalls as stalls


def test_a_stopped_sleeper_reports_the_stall_and_within_cuts_it() -> None:
    before = stalls.now()
    with stalls.MachineStalls() as machine:
        time.sleep(0.05)
        sleeper = machine._processes[0]
        stopped = stalls.now()
        sleeper.send_signal(signal.SIGSTOP)
        time.sleep(0.2)
        sleeper.send_signal(signal.SIGCONT)
        resumed = stalls.now()
        time.sleep(0.05)
    assert resumed - stopped >= 0.2
    # One stall covers the stopped time, up to the sleeper's 1 ms wait and its wake-up.
    covering = [(s, e) for s, e in machine.stalls if s <= stopped + 0.003 and e >= resumed - 0.003]
    assert len(covering) == 1, machine.stalls
    start, end = covering[0]
    assert machine.within(stopped, resumed) >= resumed - stopped - 0.003
    # A probe half inside it counts its inside only; one before the sleeper started, nothing.
    middle = (start + end) / 2
    assert abs(machine.within(middle, end) - (end - middle)) < 1e-9
    assert abs(machine.less_stalls(middle, end)) < 1e-9  # all of it a stall
    assert machine.within(before - 1.0, before) == 0.0


def test_stalls_of_two_cpus_at_once_count_once() -> None:
    machine = stalls.MachineStalls()
    machine.stalls = sorted([(1.0, 2.0), (1.5, 2.5), (3.0, 3.5), (1.2, 1.4)])
    assert machine.within(0.0, 10.0) == 2.0  # [1, 2.5] and [3, 3.5]
    assert machine.within(1.8, 3.2) == pytest.approx(0.7 + 0.2, abs=1e-12)
    assert machine.within(2.6, 2.9) == 0.0
    assert machine.total == 2.0
