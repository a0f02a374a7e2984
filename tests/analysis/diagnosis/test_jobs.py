"""analysis.diagnosis.jobs: the costliest call is handed to the pool first, each outcome comes back in the
calls' order, and a failed fit is an outcome, not an exception (unless the diagnosis was cancelled)."""
from __future__ import annotations

import threading
from concurrent.futures import Future

import pytest

from analysis.diagnosis import jobs
from analysis.fit.least_squares import FitError


class _RecordingExecutor:
    """Runs each call when submitted and notes the order it was handed over in."""

    def __init__(self):
        self.order: list[str] = []

    def submit(self, fn, *args):
        self.order.append(args[0])
        future = Future()
        try:
            future.set_result(fn(*args))
        except Exception as exc:        # noqa: BLE001 - a future carries whatever the call raised
            future.set_exception(exc)
        return future


def _named(name: str) -> str:
    if name == "fails":
        raise FitError("no convergence")
    return name.upper()


def test_the_costliest_call_is_handed_over_first_and_outcomes_come_back_in_order():
    pool = _RecordingExecutor()
    calls = [(_named, ("short",), 10.0), (_named, ("long",), 900.0), (_named, ("fails",), 50.0),
             (_named, ("unknown",), 0.0), (_named, ("also-unknown",), 0.0)]
    handles = jobs.submit(calls, pool, None)
    assert pool.order == ["long", "fails", "short", "unknown", "also-unknown"]
    assert [h.outcome() for h in handles] == [("SHORT", None), ("LONG", None), (None, "no convergence"),
                                              ("UNKNOWN", None), ("ALSO-UNKNOWN", None)]


def test_without_a_pool_each_call_runs_once_when_its_outcome_is_asked_for():
    ran = []

    def note(name):
        ran.append(name)
        return name

    handles = jobs.submit([(note, ("a",), 1.0), (note, ("b",), 5.0)], None, None)
    assert ran == []
    assert handles[1].outcome() == ("b", None) and handles[1].outcome() == ("b", None)
    assert handles[0].outcome() == ("a", None)
    assert ran == ["b", "a"]


def test_a_failure_after_cancel_goes_on_up_instead_of_becoming_a_failed_candidate():
    cancel = threading.Event()
    cancel.set()
    (handle,) = jobs.submit([(_named, ("fails",), 0.0)], None, cancel)
    with pytest.raises(FitError):
        handle.outcome()


def test_run_gives_the_outcomes_in_order():
    assert jobs.run([(_named, ("x",)), (_named, ("fails",))], _RecordingExecutor(), None) == \
        [("X", None), (None, "no convergence")]
