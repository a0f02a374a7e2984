"""The main window: opening recordings in a worker, errors, cancel, recent files, drag and drop."""
from __future__ import annotations

import threading
from pathlib import Path

from PySide6.QtCore import QMimeData, QPoint, Qt, QUrl
from PySide6.QtGui import QDropEvent

import app.jobs.workers
from analysis.fit.least_squares import FitCancelled
from analysis.recording.format import RecordingError, read_recording
from app.window.main_window import MainWindow
from app.window.settings import MAX_RECENT

from tests.pace import wait_ms

from tests.app.conftest import analysis_wait_ms, open_and_wait


def test_every_page_is_built(window):
    names = [window.pages.tabText(i) for i in range(window.pages.count())]
    assert names == ["Measure", "Results", "Model lab", "Series", "Large signal", "QA", "Production", "Archive"]
    assert window.pages.widget(0) is window.wizard
    assert window.pages.widget(2) is window.model_lab
    assert window.pages.widget(3) is window.series
    assert window.pages.widget(4) is window.large_signal
    assert window.pages.widget(5) is window.qa
    assert window.pages.widget(6) is window.production and window.pages.widget(7) is window.archive


def test_analysis_runs_in_a_worker_thread(qtbot, window, recordings, monkeypatch):
    threads = []
    real = app.jobs.workers.analyze_recording

    def spy(*args, **kwargs):
        threads.append(threading.current_thread())
        return real(*args, **kwargs)
    monkeypatch.setattr(app.jobs.workers, "analyze_recording", spy)
    open_and_wait(qtbot, window, recordings["paper"])
    assert len(threads) == 1
    assert threads[0] is not threading.main_thread()
    assert threading.current_thread() is threading.main_thread()


def test_cancel_stops_the_analysis_and_the_gui_stays_responsive(qtbot, window, recordings, monkeypatch):
    started = threading.Event()

    def blocked(recording, sd_m2=None, effects=None, cancel=None):
        started.set()
        if not cancel.wait(240):         # only the Cancel button ends this "fit"
            raise AssertionError("never cancelled")
        raise FitCancelled("fit cancelled")
    monkeypatch.setattr(app.jobs.workers, "analyze_recording", blocked)
    window.open_path(recordings["paper"])
    qtbot.waitUntil(started.is_set, timeout=wait_ms(10))
    assert window.busy and window.jobs.cancel_button.isVisible() and window.jobs.progress.isVisible()
    window.pages.setCurrentIndex(0)                 # the event loop runs while the worker is busy
    assert window.pages.currentIndex() == 0
    with qtbot.waitSignal(window.analysis_cancelled, timeout=wait_ms(10)):
        qtbot.mouseClick(window.jobs.cancel_button, Qt.LeftButton)
    assert not window.busy and not window.jobs.cancel_button.isVisible()
    assert "cancelled" in window.status_label.text().lower()
    assert window.results.result is None


def test_a_new_file_replaces_a_running_analysis(qtbot, window, recordings, monkeypatch):
    real = app.jobs.workers.analyze_recording
    first_started = threading.Event()

    def first_blocks(recording, sd_m2=None, effects=None, cancel=None):
        if recording.source.name.startswith("no-sd"):
            first_started.set()
            cancel.wait(240)
            raise FitCancelled("fit cancelled")
        return real(recording, sd_m2, effects, cancel)
    monkeypatch.setattr(app.jobs.workers, "analyze_recording", first_blocks)
    window.open_path(recordings["no_sd"])
    qtbot.waitUntil(first_started.is_set, timeout=wait_ms(10))
    with qtbot.assertNotEmitted(window.analysis_cancelled, wait=200):
        outcome, = open_and_wait(qtbot, window, recordings["paper"])
    assert outcome.path == recordings["paper"]
    assert window.results.result.source == recordings["paper"]


def test_bad_recording_shows_the_message_and_the_window_keeps_working(qtbot, window, recordings, dialogs):
    with __import__("pytest").raises(RecordingError) as expected:
        read_recording(recordings["broken"])
    message, = open_and_wait(qtbot, window, recordings["broken"], "analysis_failed")
    assert len(dialogs) == 1
    kind, title, text = dialogs[0]
    assert kind == "warning" and "broken.wav" in title
    assert text == message == str(expected.value)
    assert "Traceback" not in text and "\n" not in text
    assert not window.busy
    assert window.settings.recent_files() == []          # a file that failed is not "recent"
    open_and_wait(qtbot, window, recordings["paper"])     # still usable
    assert window.results.has_result


def test_missing_file_is_an_error_message(qtbot, window, tmp_path, dialogs):
    open_and_wait(qtbot, window, tmp_path / "nothing-here.wav", "analysis_failed")
    assert "missing" in dialogs[0][2]


def test_an_internal_error_is_reported_without_traceback(qtbot, window, recordings, monkeypatch, dialogs):
    def broken(*args, **kwargs):
        raise ZeroDivisionError("division by zero")
    monkeypatch.setattr(app.jobs.workers, "analyze_recording", broken)
    open_and_wait(qtbot, window, recordings["paper"], "analysis_failed")
    text = dialogs[0][2]
    assert "internal error" in text and "ZeroDivisionError" in text and "Traceback" not in text
    report = Path(text.rsplit("(details in ", 1)[1].rstrip(")"))     # the GUI says where the crash report is
    assert "ZeroDivisionError" in report.read_text(encoding="utf-8")


def test_recent_files_are_remembered_newest_first(qtbot, window, recordings, settings):
    open_and_wait(qtbot, window, recordings["no_sd"])
    open_and_wait(qtbot, window, recordings["paper"])
    expected = [str(recordings["paper"].resolve()), str(recordings["no_sd"].resolve())]
    assert settings.recent_files() == expected
    window.close()
    again = MainWindow(settings)
    qtbot.addWidget(again)
    actions = [a for a in again.recent_menu.actions() if a.data()]
    assert [a.data() for a in actions] == expected
    assert "paper.wav" in actions[0].text()
    # Opening from the menu analyses that file.
    with qtbot.waitSignal(again.analysis_shown, timeout=analysis_wait_ms()) as blocker:
        actions[1].trigger()
    assert blocker.args[0].path == recordings["no_sd"].resolve()


def test_recent_files_keep_at_most_eight(settings, tmp_path):
    for i in range(MAX_RECENT + 3):
        settings.add_recent_file(tmp_path / f"r{i}.wav")
    files = settings.recent_files()
    assert len(files) == MAX_RECENT
    assert files[0].endswith(f"r{MAX_RECENT + 2}.wav")
    settings.add_recent_file(tmp_path / "r5.wav")        # re-opened: moves to the top, no duplicate
    files = settings.recent_files()
    assert files[0].endswith("r5.wav") and len(files) == len(set(files)) == MAX_RECENT


def test_geometry_is_restored(qtbot, settings):
    first = MainWindow(settings)
    qtbot.addWidget(first)
    first.show()
    # Smaller than the offscreen screen (800x600): restoreGeometry keeps a window on its screen.
    first.resize(700, 500)
    qtbot.waitUntil(lambda: first.size().width() == 700, timeout=wait_ms(5))
    first.close()
    second = MainWindow(settings)
    qtbot.addWidget(second)
    assert (second.size().width(), second.size().height()) == (700, 500)


def test_dropping_a_recording_opens_it(qtbot, window, recordings):
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(recordings["paper"].with_suffix(".json")))])
    event = QDropEvent(QPoint(10, 10), Qt.CopyAction, mime, Qt.LeftButton, Qt.NoModifier)
    with qtbot.waitSignal(window.analysis_shown, timeout=analysis_wait_ms()):
        window.dropEvent(event)
    assert event.isAccepted()


def test_dropping_something_else_is_refused(window, tmp_path):
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(tmp_path / "notes.txt"))])
    event = QDropEvent(QPoint(10, 10), Qt.CopyAction, mime, Qt.LeftButton, Qt.NoModifier)
    window.dropEvent(event)
    assert not window.busy


def test_file_menu_has_open_and_quit_shortcuts(window):
    assert window.open_action.shortcut().toString() == "Ctrl+O"
    assert window.quit_action.shortcut().toString() == "Ctrl+Q"


def test_a_bug_in_a_slot_is_a_message_with_its_crash_report(window, dialogs):
    from app.main import _report_uncaught
    try:
        1 / 0
    except ZeroDivisionError as exc:
        _report_uncaught(window)(type(exc), exc, exc.__traceback__)
    (kind, title, text), = dialogs
    assert title == "Internal error" and "internal error while working in the window: ZeroDivisionError" in text
    assert "ZeroDivisionError" in Path(text.rsplit("(details in ", 1)[1].rstrip(")")).read_text(encoding="utf-8")


def test_the_model_part_of_the_uncertainties_runs_in_the_worker_after_the_result(qtbot, window):
    from analysis.pipeline import analyze_recording
    from app.jobs.workers import AnalysisOutcome
    from tests.realistic_drivers import realistic_recording
    result = analyze_recording(realistic_recording("midrange", 0))
    shown = AnalysisOutcome(0, Path("midrange"), result, None)
    with qtbot.waitSignal(window.worker.finished, timeout=analysis_wait_ms(4)) as done:
        window.worker.start_model_part(shown)
    outcome = done.args[1]
    mms = outcome.result.parameters["Mms"]
    assert mms.value == result.parameters["Mms"].value and mms.std_noise == result.parameters["Mms"].std
    assert mms.std_model > 0 and mms.std > mms.std_noise
