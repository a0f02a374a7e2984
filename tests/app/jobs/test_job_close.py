"""Closing the main window while a job runs: every job is cancelled or detached, nothing raises in its thread.

Issue 16's leftover: closing the window during a Series or Large-signal analysis raised "Signal source has been
deleted" in the worker thread, which went on emitting into the deleted page. The jobs here are held until the
page's runner is being destroyed (its `destroyed` signal), so they report exactly when the bug bit.
"""
from __future__ import annotations

import sys
import threading

from PySide6.QtCore import QCoreApplication, QEvent

import app.large_signal.page
import app.window.main_window
import app.live.series_page
from tests.pace import wait_ms


def test_closing_the_window_mid_job_raises_nothing(qtbot, settings, recordings, monkeypatch):
    monkeypatch.setattr(app.window.main_window, "CLOSE_WAIT_MS", 50)      # the jobs outlast the wait: detached, not done
    entered, release = threading.Semaphore(0), threading.Event()
    real_analyze_path = app.live.series_page.analyze_path

    def held(result):
        def work(*args, **kwargs):
            entered.release()
            release.wait(240)
            return result(*args, **kwargs)
        return work
    monkeypatch.setattr(app.live.series_page, "analyze_path", held(real_analyze_path))
    monkeypatch.setattr(app.large_signal.page, "large_signal", held(lambda paths: object()))
    raised = []
    monkeypatch.setattr(sys, "excepthook", lambda kind, exc, tb: raised.append(exc))
    monkeypatch.setattr(threading, "excepthook", lambda args: raised.append(args.exc_value))

    window = app.window.main_window.MainWindow(settings)
    window.show()
    window.series.analyse("repeatability", [recordings["paper"], recordings["no_sd"]])
    window.large_signal.analyse([recordings["paper"]])
    for _ in range(2):
        assert entered.acquire(timeout=wait_ms(30) / 1000), "both jobs started"
    # The jobs go on the moment their page's runner is being destroyed, as a slow one would.
    for runner in (window.series.worker, window.large_signal.worker):
        runner.destroyed.connect(lambda *_: release.set())
    with qtbot.capture_exceptions() as in_slots:
        window.close()
        window.deleteLater()
        QCoreApplication.sendPostedEvents(None, QEvent.DeferredDelete)    # waits for the pools' threads
        qtbot.wait(50)
    assert release.is_set(), "the window and its runners were deleted"
    assert raised == [] and in_slots == []


def test_cancel_lets_the_large_signal_page_go_at_once_and_drops_the_late_result(qtbot, monkeypatch, tmp_path):
    """The identification cannot stop midway: Cancel frees the page now, the result that comes later is dropped."""
    entered, release = threading.Event(), threading.Event()
    late = object()

    def slow(stems):
        entered.set()
        release.wait(240)
        return late
    monkeypatch.setattr(app.large_signal.page, "large_signal", slow)
    page = app.large_signal.page.LargeSignalPage()
    qtbot.addWidget(page)
    finished = []
    monkeypatch.setattr(page, "on_finished", finished.append)
    page.analyse([tmp_path / "x.wav"])
    # Cancel once the job runs: a job cancelled while it still waits for its thread says so at once (not late).
    assert entered.wait(wait_ms(60) / 1000), "the identification started"
    assert not page.choose_button.isEnabled()
    page.jobs.cancel_button.click()
    assert page.choose_button.isEnabled() and not page.jobs.busy
    assert "Cancelled" in page.status.text()
    with qtbot.waitSignal(page.worker.cancelled, timeout=wait_ms(10)):
        release.set()          # inside: the late job may say it was cancelled before a waiter outside would listen
    assert finished == []
