"""The Series page: repeatability and level series analysed off the GUI thread."""
import pytest

from analysis.recording.format import write_recording
from app.live.series_page import SeriesPage
from instruments.simulation.level_series import write_level_series
from tests.builders import TYPICAL_NOISE, recording
from tests.pace import wait_ms


@pytest.fixture
def page(qtbot):
    widget = SeriesPage()
    qtbot.addWidget(widget)
    return widget


def test_repeatability_of_three_recordings_shows_mean_and_spread(qtbot, page, tmp_path):
    paths = []
    for seed in range(3):
        paths += list(write_recording(tmp_path / f"rep{seed}", recording(noise=TYPICAL_NOISE, n_periods=4, seed=seed)))
    with qtbot.waitSignal(page.worker.finished, timeout=wait_ms(60)):
        page.analyse("repeatability", paths)
    table = page.repeat_table
    rows = {table.item(r, 0).text(): r for r in range(table.rowCount())}
    assert float(table.item(rows["Re"], 1).text()) == pytest.approx(3.02, rel=1e-3)      # the customary name
    assert table.item(rows["Re"], 5).text() == "Ω" and table.item(rows["Re"], 6).text() == "3"
    assert float(table.item(rows["Bl"], 2).text()) > 0          # a spread over seeds, not zero
    assert "3 recordings" in page.panels["repeatability"].status.text()


def test_level_series_shows_fs_falling_with_excursion(qtbot, page, tmp_path):
    paths = write_level_series(tmp_path, levels_v=(0.3, 10.0))
    with qtbot.waitSignal(page.worker.finished, timeout=wait_ms(120)):
        page.analyse("levels", paths)
    x, fs = page.levels_view.plot.line.getData()
    assert len(fs) == 2 and x[1] > x[0] and fs[1] < fs[0]
    # The drift's reason is one click away: the same recordings, for the Large-signal page.
    assert page.large_signal_button.isEnabled()
    with qtbot.waitSignal(page.large_signal_requested) as requested:
        page.large_signal_button.click()
    assert requested.args[0] == sorted(p.with_suffix("") for p in paths)


def test_one_recording_is_not_a_series(qtbot, page, tmp_path):
    wav, _ = write_recording(tmp_path / "one", recording(n_periods=2))
    page.analyse("repeatability", [wav])
    assert "at least two" in page.panels["repeatability"].status.text()
