"""Opaque grid lines: the colour a translucent line shows on the background, drawn behind the data."""
from __future__ import annotations

import pyqtgraph as pg
import pytest
from PySide6.QtGui import QColor, QPainter, QPen, QPicture

from app.widgets import style
from app.widgets.grid_axis import BEHIND_THE_DATA, OpaqueGridAxis, opaque_pen, show_grid
from app.widgets.plots import LogFrequencyAxis


def test_a_translucent_pen_becomes_the_colour_it_shows_over_the_background():
    pen = QPen(QColor(0, 0, 0, 64))
    out = opaque_pen(pen, QColor("white"))
    assert out.color().alpha() == 255
    expected = round(255 * (1 - 64 / 255))
    assert abs(out.color().red() - expected) <= 1 and out.color().red() == out.color().blue()
    assert opaque_pen(QPen(QColor(10, 20, 30)), QColor("white")).color() == QColor(10, 20, 30)


@pytest.mark.parametrize("log_y", [False, True])
def test_show_grid_keeps_log_mode_draws_opaque_lines_and_puts_the_axes_behind(qtbot, log_y):
    style.configure_pyqtgraph()
    widget = pg.PlotWidget(axisItems={"bottom": LogFrequencyAxis("bottom")})
    qtbot.addWidget(widget)
    plot = widget.getPlotItem()
    plot.setLogMode(x=True, y=log_y)
    show_grid(plot)
    plot.plot([10.0, 100.0, 1000.0], [1.0, 10.0, 100.0])
    widget.resize(400, 300)
    widget.show()
    qtbot.waitExposed(widget)
    for name in ("left", "bottom"):
        axis = plot.getAxis(name)
        assert isinstance(axis, OpaqueGridAxis) and axis.zValue() == BEHIND_THE_DATA
        assert axis.grid is not False
    assert plot.getAxis("bottom").logMode is True and plot.getAxis("left").logMode is log_y
    picture = QPicture()                # kept: a painter on a device already collected crashes
    painter = QPainter(picture)
    try:
        _axis, ticks, _text = plot.getAxis("bottom").generateDrawSpecs(painter)
    finally:
        painter.end()
    assert ticks and all(pen.color().alpha() == 255 for pen, _a, _b in ticks)
    assert any(pen.color().red() > 150 for pen, _a, _b in ticks)      # grid lines stay light, not black
