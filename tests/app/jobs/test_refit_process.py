"""The Model lab's refit process: the fit the window's thread would make, cancellable, and a dead worker replaced."""
from __future__ import annotations

import dataclasses
import os
import signal
import threading
import time

import pytest

import analysis
from analysis.effects import parse_effects
from analysis.effects.creep import CreepLog
from analysis.diagnosis.refit import refit
from analysis.fit.least_squares import FitCancelled, FitData, FitResult, fit_model
from analysis.model import Model
from analysis.parallel import BACKGROUND_NICENESS, worker_count
from analysis.spectra import estimate_spectra
from app.jobs import refit_process
from app.jobs.background_pool import PoolCancelled
from app.jobs.refit_process import RefitProcess

pytestmark = pytest.mark.skipif(worker_count() < 2, reason="one core: the lab refits in its own thread, no process")


@pytest.fixture(scope="module")
def data() -> FitData:
    return FitData.from_spectra(estimate_spectra(analysis.synthesize(noise=analysis.TYPICAL_NOISE)))


@pytest.fixture
def refits():
    process = RefitProcess()
    yield process
    process.shutdown()


MODEL = Model(parse_effects("lr3,creep-log"))


@pytest.fixture(scope="module")
def current(data) -> FitResult:
    """The version a refit changes: MODEL without its creep."""
    return fit_model(data, Model(parse_effects("lr3")))


def test_a_refit_on_the_process_is_the_fit_of_the_callers_thread(data, current, refits):
    here = refit(data, MODEL, current)
    there = refits.fit(refits.ticket(), data, MODEL, current, threading.Event())
    assert there.values == pytest.approx(here.values, rel=1e-12)
    assert there.model.effect_ids == MODEL.effect_ids


def _wait_for(path: str) -> None:
    while not os.path.exists(path):
        time.sleep(0.01)


def test_a_refit_cancelled_while_it_waits_ends_at_once_and_the_next_one_still_fits(data, current, refits, tmp_path):
    go_on = tmp_path / "go on"
    refits._running().submit(_wait_for, str(go_on))         # the worker is busy with an older refit
    cancel = threading.Event()
    timer = threading.Timer(0.05, cancel.set)
    timer.start()
    with pytest.raises(PoolCancelled):
        refits.fit(refits.ticket(), data, MODEL, current, cancel)
    timer.join()
    go_on.touch()
    assert refits.fit(refits.ticket(), data, MODEL, current, threading.Event()).values["Bl"] > 0


def test_a_refit_cancelled_before_it_was_sent_is_not_sent(data, current, refits):
    cancel = threading.Event()
    cancel.set()
    with pytest.raises(PoolCancelled):
        refits.fit(refits.ticket(), data, MODEL, current, cancel)
    assert refits._pool is None


def test_the_worker_stops_a_fit_the_lab_has_cancelled_and_not_a_later_one(data, current, refits):
    """What the worker reads at each of the fit's checks: the shared counter, not the job's Event."""
    refits.fit(refits.ticket(), data, MODEL, current, threading.Event())          # the process is running
    refits._cancel(5)
    pool = refits._running()
    with pytest.raises(FitCancelled):
        pool.submit(refit_process._fit_in_worker, 5, data, MODEL, current).result()
    assert pool.submit(refit_process._fit_in_worker, 6, data, MODEL, current).result().values["Bl"] > 0


def test_a_killed_worker_does_not_lose_the_refit_and_a_new_one_is_started(data, current, refits):
    refits.fit(refits.ticket(), data, MODEL, current, threading.Event())
    first = refits._running()
    for pid in list(first._processes):
        os.kill(pid, signal.SIGKILL)
    assert refits.fit(refits.ticket(), data, MODEL, current, threading.Event()).values["Bl"] > 0      # fitted in this thread
    assert refits._running() is not first
    assert refits.fit(refits.ticket(), data, MODEL, current, threading.Event()).values["Bl"] > 0      # and on the new process


def test_the_worker_runs_below_its_caller(refits):
    pool = refits._running()
    assert pool.submit(os.nice, 0).result() == min(os.nice(0) + BACKGROUND_NICENESS, 19)     # 19: the lowest


def test_a_model_whose_effect_cannot_be_sent_to_the_worker_is_fitted_here(data, current, refits):
    """A package's entry point may name a factory whose effects are of a class made inside it: pickle cannot send
    them. Before the fix the refit failed as an internal error ("Can't pickle local object")."""
    creep = parse_effects("creep-log")[0]

    class PackagesCreep(type(creep)):       # a class pickle cannot find by its name
        pass

    made = PackagesCreep(**{f.name: getattr(creep, f.name) for f in dataclasses.fields(creep) if f.init})
    model = Model((*parse_effects("lr3"), made))
    here = refit(data, model, current)
    there = refits.fit(refits.ticket(), data, model, current, threading.Event())
    assert there.values == pytest.approx(here.values, rel=1e-12)


def test_no_process_is_started_after_the_lab_shut_down(data, current, refits):
    """A refit job still on its way when the window closed (its wait ran out) reaches fit() after shutdown(): it
    started a new worker no one would shut down, or, shut down between _running() and submit, failed as an
    internal error ("cannot schedule new futures after shutdown") with a crash report."""
    pool = refits._running()
    refits.shutdown()
    refits.start()
    assert refits.fit(refits.ticket(), data, MODEL, current, threading.Event()).values["Bl"] > 0
    assert refits._pool is None
    refits._running = lambda: pool                    # the pool it took just before the shutdown
    assert refits.fit(refits.ticket(), data, MODEL, current, threading.Event()).values["Bl"] > 0


def test_start_does_not_wait_for_the_process_in_the_callers_thread(refits, monkeypatch):
    """start() is called by the Model lab's showEvent, in the GUI thread: the fork (and, the first time, the fork
    server's own start, 0.57 s) happens in a thread of its own."""
    forked_in = []
    real = RefitProcess._running

    def running(self):
        forked_in.append(threading.current_thread())
        return real(self)
    monkeypatch.setattr(RefitProcess, "_running", running)
    refits.start()
    deadline = time.monotonic() + 60
    while refits._pool is None and time.monotonic() < deadline:
        time.sleep(0.01)
    assert refits._pool is not None and forked_in and threading.current_thread() not in forked_in


class NeedsTwo(Exception):
    """An exception pickle cannot rebuild: its args hold the one message, its __init__ wants two arguments."""

    def __init__(self, part: str, why: str):
        super().__init__(f"{part}: {why}")


class FailingCreep(CreepLog):
    """A package's effect whose code raises an exception of its own."""

    def response(self, s, p):
        raise NeedsTwo("the spider", "torn")


def test_an_effects_exception_the_window_cannot_rebuild_is_one_line_and_the_worker_goes_on(data, current, refits):
    """Before: the worker's exception could not be unpickled in the window's process; concurrent.futures marked
    the pool broken, the refit was redone in the window's process (the window stalled) and a new worker started."""
    creep = parse_effects("creep-log")[0]
    failing = FailingCreep(**{f.name: getattr(creep, f.name) for f in dataclasses.fields(creep) if f.init})
    refits.fit(refits.ticket(), data, MODEL, current, threading.Event())
    pool = refits._running()
    worker = pool.submit(os.getpid).result()
    with pytest.raises(Exception) as raised:
        refits.fit(refits.ticket(), data, Model((*parse_effects("lr3"), failing)), current, threading.Event())
    assert "the effect creep-log raised NeedsTwo: the spider: torn" in str(raised.value)
    assert refits._running() is pool and pool.submit(os.getpid).result() == worker
    assert refits.fit(refits.ticket(), data, MODEL, current, threading.Event()).values["Bl"] > 0
