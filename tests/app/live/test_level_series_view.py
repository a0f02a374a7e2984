"""The level-series view: Table II and the fs-against-excursion plot of a simulated series."""
from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtGui import QImage

from analysis.level_series import level_series
from app.live.level_series_view import EMPTY_TEXT, FIXED_COLUMNS, LevelSeriesView, save_screenshot
from instruments.simulation.level_series import simulate_level_series

LEVELS_V = (0.3, 3.0, 14.0)


@pytest.fixture(scope="module")
def series():
    return level_series(simulate_level_series(LEVELS_V))


@pytest.fixture
def view(qtbot, series):
    from app.widgets import style
    style.configure_pyqtgraph()
    w = LevelSeriesView()
    qtbot.addWidget(w)
    w.resize(1400, 800)
    w.show()
    w.set_series(series)
    return w


def _header(table) -> list[str]:
    return [table.horizontalHeaderItem(c).text() for c in range(table.columnCount())]


def test_table_has_a_row_per_level_in_customary_units(view, series):
    table = view.table
    assert table.rowCount() == len(LEVELS_V)
    header = _header(table)
    assert header[:3] == list(FIXED_COLUMNS) and "fs (Hz)" in header and "Cms (mm/N)" in header
    fs_column = header.index("fs (Hz)")
    fs_small = float(table.item(0, fs_column).text().split("(")[0])
    assert fs_small == pytest.approx(series.levels[0].value("fs"), rel=1e-6)
    assert table.item(0, fs_column).textAlignment() & Qt.AlignRight      # numbers line up on the right
    assert table.item(0, 2).text() == "yes" and table.item(2, 2).text() == "no"
    assert "distortion-high" in table.item(2, 2).toolTip()
    cms_column = header.index("Cms (mm/N)")
    assert "% from the smallest level" in table.item(2, cms_column).toolTip()


def test_plot_has_fs_against_peak_excursion(view, series):
    small_x, small_y = view.plot.small.getData()
    large_x, large_y = view.plot.large.getData()
    assert len(small_x) == 1 and len(large_x) == len(LEVELS_V) - 1
    assert small_x[0] == pytest.approx(series.levels[0].peak_displacement_m * 1e3)
    assert np.all(large_y < small_y[0])          # fs falls with level
    assert "against peak excursion" in view.plot.getPlotItem().titleLabel.text
    assert "fs 70.5" in view.summary.text() and "Cms" in view.summary.text()


def test_clear_empties_table_and_plot(view):
    view.clear()
    assert view.table.rowCount() == 0 and view.summary.text() == EMPTY_TEXT
    assert view.plot.small.getData()[0] is None or len(view.plot.small.getData()[0]) == 0


def test_screenshot_is_a_png_of_the_view(qtbot, series, tmp_path):
    path = save_screenshot(series, tmp_path / "level-series.png", size=(1000, 700))
    image = QImage(str(path))
    assert not image.isNull() and (image.width(), image.height()) == (1000, 700)
    # Not a blank grab: the plot's white and the table's cells differ somewhere.
    colours = {image.pixel(x, y) for x in range(0, 1000, 50) for y in range(0, 700, 50)}
    assert len(colours) > 3
