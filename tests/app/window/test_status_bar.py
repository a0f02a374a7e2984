"""The status bar at 1280x720: what is being done and what was loaded, each on one line cut with "…" (the whole
text in the tooltip). The job's words wrapped a long file name onto a third line the bar had no room for."""
from __future__ import annotations

from PySide6.QtWidgets import QApplication

from app.jobs.book import Job

LONG_NAME = "meas_data_UIV_spectra_1Hz-10kHz_of_a_woofer_measured_with_a_laser_on_its_cone.csv"


def _painted(label) -> str:
    return label.shown_text() if hasattr(label, "shown_text") else label.text()


def _fits_one_line(label) -> bool:
    metrics = label.fontMetrics()
    return (metrics.horizontalAdvance(_painted(label)) <= label.contentsRect().width()
            and label.height() < 2 * metrics.lineSpacing())


def test_the_status_bar_says_a_long_job_and_path_on_one_line_each(window):
    window.resize(1280, 720)
    doing = f"The model part of the uncertainties of {LONG_NAME}…"
    # Shown as the window shows the model part's job (never started: only its words matter here).
    job = Job(10**6, "model part", lambda job: None, window.worker, "the model part")
    window.jobs.run(job, doing, lambda outcome: None, lambda message: None)
    loaded = f"Loaded /home/technician/measurements/2024/line-3/{LONG_NAME} — fitted, analysed in 0.4 s"
    window.status_label.setText(loaded)
    QApplication.processEvents()
    for label, whole in ((window.jobs.text, doing), (window.status_label, loaded)):
        assert _fits_one_line(label), _painted(label)
        assert label.text() == whole and label.toolTip() == whole        # cut on screen, whole when asked
        assert _painted(label).endswith("…") and _painted(label)[:-1] in whole
    assert window.minimumSizeHint().width() <= 1280           # a long path never widens the window
    window.jobs.drop()


def test_a_short_status_is_shown_whole(window):
    window.resize(1280, 720)
    window.status_label.setText("Analysis cancelled")
    QApplication.processEvents()
    assert _painted(window.status_label) == "Analysis cancelled"
