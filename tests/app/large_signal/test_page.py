"""The Large-signal page: the curves with their bands, limits and measured range, the distortion predicted against
the distortion measured, the identification off the GUI thread, and the way in from the Series page."""
from __future__ import annotations

import numpy as np
import pytest

from analysis.large_signal import large_signal
from app.large_signal.page import LargeSignalPage, summary_html
from tests.large_signal_truth import write_steps
from tests.pace import wait_ms


@pytest.fixture(scope="module")
def steps(tmp_path_factory):
    """Two levels of the issue's known driver, written as recordings (8,192-sample periods: ~1 s to identify)."""
    return write_steps(tmp_path_factory.mktemp("large-signal-page"))


@pytest.fixture(scope="module")
def result(steps):
    return large_signal(steps)


@pytest.fixture
def page(qtbot):
    widget = LargeSignalPage()
    qtbot.addWidget(widget)
    return widget


def test_the_curves_come_with_bands_limits_and_the_measured_range(page, result):
    page.show_result(result)
    lo, hi = result.model.x_range
    bl = page.plots["Bl"]
    x, y = bl.inside.getData()
    assert x[0] == pytest.approx(lo * 1e3, abs=0.05) and x[-1] == pytest.approx(hi * 1e3, abs=0.05)
    assert np.all(bl.upper.getData()[1] >= bl.lower.getData()[1])
    assert len(bl.outside[0].getData()[0]) > 0                   # extrapolated beyond the range, dashed
    assert bl.region.getRegion() == pytest.approx((lo * 1e3, hi * 1e3))
    labels = [m.label.toPlainText() for m in bl.marks if getattr(m, "label", None) is not None]
    assert any(text.startswith("X_Bl") for text in labels) and any("Bl max -1.50 mm" in t for t in labels)
    assert any(t.startswith("X_C") for t in (m.label.toPlainText() for m in page.plots["Kms"].marks
                                             if getattr(m, "label", None) is not None))
    assert page.level_choice.count() == 2 and page.level_choice.currentIndex() == 1


def test_the_distortion_predicted_is_shown_against_the_measured_for_each_level(page, result):
    page.show_result(result)
    measured, predicted, _ = page.distortion.items["current"]
    loud = predicted.getData()[1].copy()
    page.level_choice.setCurrentIndex(0)
    quiet = page.distortion.items["current"][1].getData()[1]
    assert len(measured.getData()[0]) > 3 and np.nanmax(quiet) < np.nanmax(loud)
    assert "step-5V" in page.distortion.getPlotItem().titleLabel.text


def test_the_summary_says_where_to_move_the_coil_and_what_to_read_with_care(result):
    text = summary_html(result)
    assert "move the coil 1.50 mm in" in text and "X_Bl (Bl &gt;= 82 %)" in text
    assert "Bl(0)" in text and "T·m" in text
    assert "beyond the measured range" in text            # X_L lies beyond +-3 mm: said, not hidden


def test_recordings_are_identified_off_the_gui_thread(qtbot, page, steps):
    with qtbot.waitSignal(page.result_shown, timeout=wait_ms(180)):
        page.analyse(steps)
    assert "2 recording(s) identified" in page.status.text() and page.choose_button.isEnabled()


def test_a_recording_without_the_laser_is_said_not_shown(qtbot, page, recordings):
    with qtbot.waitSignal(page.worker.failed, timeout=wait_ms(60)):
        page.analyse([recordings["no_laser"]])
    assert "no displacement" in page.status.text() and page.result is None


def test_the_series_pages_level_series_opens_here(qtbot, settings, steps, monkeypatch):
    from app.window.main_window import MainWindow
    window = MainWindow(settings)
    qtbot.addWidget(window)
    asked = []
    monkeypatch.setattr(window.large_signal, "analyse", asked.append)
    window.series.level_paths = list(steps)
    window.series.large_signal_button.setEnabled(True)
    window.series.large_signal_button.click()
    assert window.pages.currentWidget() is window.large_signal and asked == [list(steps)]


def test_the_report_and_the_curves_are_saved_by_their_suffix(page, result, tmp_path):
    import json
    page.show_result(result)
    for name in ("r.pdf", "r.html", "r.csv", "r.json"):
        page.save(tmp_path / name)
        assert (tmp_path / name).stat().st_size > 1000 and "Saved" in page.status.text()
    assert json.loads((tmp_path / "r.json").read_text())["x_unit"] == "m"
    assert (tmp_path / "r.pdf").read_bytes().startswith(b"%PDF")
    assert "x_m,Bl_Tm" in (tmp_path / "r.csv").read_text()
    from analysis.importers.table import read_table      # the project's own reader takes it back, comments and all
    table = read_table(tmp_path / "r.csv")
    assert table.header[:2] == ("x_m", "Bl_Tm") and table.values.shape[0] == 101
    assert "# exported by linpar" in (tmp_path / "r.csv").read_text()
    page.save(tmp_path / "r.txt")
    assert "Not saved" in page.status.text() and not (tmp_path / "r.txt").exists()
    page.save(tmp_path)
    assert "Not saved" in page.status.text()
