"""Every click that starts work shows it at once: a busy indicator, what is being done, and Cancel.

"At once" is checked as "before the event loop runs again": the click handler itself puts the feedback
up, so it is on screen with the next repaint, whatever the job's thread does. (How long the event loop
may stall under a running job is a benchmark's business, bench/gui_bench.py, not a timed test's.)
"""
from __future__ import annotations

from PySide6.QtCore import Qt

from .conftest import analysis_wait_ms
from tests.app.wizard.test_wizard_helpers import choose_simulator, job_wait_ms, skip_to_measure, to_hardware


def _shows_work(progress, cancel, text: str) -> None:
    assert progress.isVisible() and cancel.isVisible() and cancel.isEnabled()
    assert text.strip(), "the feedback names what is being done"


def _wait_idle(qtbot, jobs) -> None:
    if jobs.busy:
        with qtbot.waitSignal(jobs.busy_changed, timeout=job_wait_ms(), check_params_cb=lambda busy: not busy):
            pass


def test_the_sound_card_test_shows_its_work_on_the_click(qtbot, window):
    wizard = window.wizard
    window.pages.setCurrentWidget(wizard)
    to_hardware(wizard)
    choose_simulator(wizard, realtime=True)
    page = wizard.hardware_page
    qtbot.mouseClick(page.test_audio_button, Qt.LeftButton)
    jobs = page.audio_jobs
    _shows_work(jobs.progress, jobs.cancel_button, jobs.text.text())
    assert "sound card" in jobs.text.text().lower()
    assert not page.test_audio_button.isEnabled()            # a second click cannot start a second test
    qtbot.mouseClick(jobs.cancel_button, Qt.LeftButton)
    assert jobs.text.text() == "Cancelling…"
    _wait_idle(qtbot, jobs)


def test_the_measurement_shows_its_work_on_the_click(qtbot, window, settings, tmp_path):
    settings.qsettings.setValue("measure/out_dir", str(tmp_path / "measurements"))
    wizard = window.wizard
    window.pages.setCurrentWidget(wizard)
    skip_to_measure(qtbot, wizard, realtime=True)
    page = wizard.measure_page
    qtbot.mouseClick(page.start_button, Qt.LeftButton)
    _shows_work(page.jobs.progress, page.jobs.cancel_button, page.jobs.text.text())
    qtbot.mouseClick(page.jobs.cancel_button, Qt.LeftButton)
    _wait_idle(qtbot, page.jobs)


def test_opening_a_recording_and_diagnosing_show_their_work_on_the_click(qtbot, window, recordings):
    with qtbot.waitSignal(window.analysis_shown, timeout=analysis_wait_ms()):
        window.open_path(recordings["paper"])
        _shows_work(window.jobs.progress, window.jobs.cancel_button, window.jobs.text.text())
    lab = window.model_lab
    window.pages.setCurrentWidget(lab)
    qtbot.mouseClick(lab.candidates.diagnose_button, Qt.LeftButton)
    _shows_work(lab.jobs.progress, lab.jobs.cancel_button, lab.jobs.text.text())
    assert not lab.candidates.diagnose_button.isEnabled()
    with qtbot.waitSignal(lab.job_cancelled, timeout=analysis_wait_ms()):
        qtbot.mouseClick(lab.jobs.cancel_button, Qt.LeftButton)


def test_series_and_large_signal_analyses_show_their_work_at_once(qtbot, window, recordings):
    paths = [recordings["paper"], recordings["no_sd"]]
    series = window.series
    series.analyse("repeatability", paths)
    panel = series.panels["repeatability"]
    window.pages.setCurrentWidget(series)
    _shows_work(panel.jobs.progress, panel.jobs.cancel_button, panel.jobs.text.text())
    qtbot.mouseClick(panel.jobs.cancel_button, Qt.LeftButton)
    large = window.large_signal
    window.pages.setCurrentWidget(large)
    large.analyse(paths)
    _shows_work(large.jobs.progress, large.jobs.cancel_button, large.jobs.text.text())
    qtbot.mouseClick(large.jobs.cancel_button, Qt.LeftButton)
    # The workers' threads end before the window goes: a thread emitting into a deleted page raises.
    assert series.worker.pool.waitForDone(analysis_wait_ms())
    assert large.worker.pool.waitForDone(analysis_wait_ms())
    qtbot.waitUntil(lambda: large.choose_button.isEnabled() and panel.choose_button.isEnabled(),
                    timeout=analysis_wait_ms())
