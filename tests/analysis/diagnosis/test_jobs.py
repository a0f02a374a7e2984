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


def _noting(ran: list):
    """A call that notes its argument in `ran` when it runs, and returns it."""
    def note(name):
        ran.append(name)
        return name
    return note


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
    note = _noting(ran)
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


class _HeldFuture:
    """A future the test finishes by hand (done() says whether it has)."""

    def __init__(self, name: str):
        self.name, self.finished = name, False

    def done(self) -> bool:
        return self.finished

    def result(self):
        self.finished = True        # waiting for it: the test's pool ends it then
        return self.name


class _HeldExecutor:
    def __init__(self):
        self.futures: list[_HeldFuture] = []

    def submit(self, fn, *args):
        self.futures.append(_HeldFuture(args[0]))
        return self.futures[-1]


def test_as_ready_takes_what_is_done_first_then_waits_in_the_order_handed_over():
    pool = _HeldExecutor()
    handles = jobs.submit([(_named, ("a",), 1.0), (_named, ("b",), 3.0), (_named, ("c",), 2.0),
                           (_named, ("d",), 0.0)], pool, None)
    by_name = {f.name: f for f in pool.futures}
    by_name["d"].finished = True
    order = jobs.as_ready(handles)
    assert next(order) == 3                  # d: done before anything was asked
    assert next(order) == 1                  # then b, handed over first, waited for
    by_name["a"].finished = True
    assert next(order) == 0                  # a finished meanwhile: before c, handed over earlier
    assert list(order) == [2]
    assert [h.outcome() for h in handles] == [("a", None), ("b", None), ("c", None), ("d", None)]


def test_as_ready_without_a_pool_runs_each_call_in_turn_in_order():
    ran = []
    note = _noting(ran)
    handles = jobs.submit([(note, ("a",), 1.0), (note, ("b",), 5.0)], None, None)
    for index in jobs.as_ready(handles):
        assert ran == ["a", "b"][:index]
        handles[index].outcome()
    assert ran == ["a", "b"]
