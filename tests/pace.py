"""The machine's pace: how much longer than its own CPU time the wall clock takes right now.

A test that bounds a time ("the measurement ends within 2 s of the fault")
states the bound for a machine that gives the test a core when it asks. On a
busy machine the same work waits for a CPU, and the wall clock runs longer by
that wait: two `yes` on two cores roughly double it. ``paced(2.0)`` is the
bound at the pace of the moment, so a slow or busy machine stretches it and an
idle one keeps it as written. The pace is measured where the bound is checked,
right after the work: the load that stretched the work is still there.
"""
from __future__ import annotations

import os
import statistics
import time

SPIN_S = 0.03        # CPU time of one probe: long enough to span several scheduler slices
PROBES = 5


def machine_pace(probes: int = PROBES) -> float:
    """Median over a few probes of wall time / this thread's CPU time while it spins; at least 1."""
    ratios = []
    for _ in range(probes):
        wall, cpu = time.perf_counter(), time.thread_time()
        while time.thread_time() - cpu < SPIN_S:
            pass
        ratios.append((time.perf_counter() - wall) / (time.thread_time() - cpu))
    return max(1.0, statistics.median(ratios))


def paced(seconds: float) -> float:
    """A time bound written for an idle machine, at the machine's pace now."""
    return seconds * machine_pace()


WAIT_PROBES = 2      # a wait's timeout needs the pace roughly, and is asked for often


def wait_ms(seconds: float) -> int:
    """The timeout of a wait on work (qtbot.waitSignal, waitUntil), in ms: `seconds` written for an idle
    machine, at the pace when the wait begins. A timeout bounds a hang, never a speed: give the work several
    times what it takes on an idle machine, and the load that slows the work stretches the wait too."""
    return int(1000 * seconds * machine_pace(WAIT_PROBES))


def load_pace() -> float:
    """Runnable processes per core over the last minute (the load average), at least 1: the pace a long test
    meets, read for free. pytest-timeout's limits use it (tests/conftest.py): a probe per test would cost
    the suite minutes of CPU, and a test that runs for minutes sees the minute's load, not the moment's."""
    return max(1.0, os.getloadavg()[0] / (os.cpu_count() or 1))
