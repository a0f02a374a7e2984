"""A level series on screen: fs against peak excursion (the paper's Fig. 14) over Table II.

Shows an analysis.level_series.LevelSeries; it computes nothing. The plot
marks which levels the validity calls small-signal: the drift of the others
is the driver's nonlinearity, not a measuring error. Not wired into the main
window here (see the module's report to the lead: a page or a dialog fed by a
worker that runs level_series off the GUI thread).
"""
from __future__ import annotations

import html
from pathlib import Path

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt
from PySide6.QtGui import QBrush, QColor
from PySide6.QtWidgets import (QAbstractItemView, QApplication, QHeaderView, QLabel, QSplitter, QTableWidget,
                               QTableWidgetItem, QVBoxLayout, QWidget)

from analysis.level_series import TABLE_PARAMETERS, Level, LevelSeries, concise
from app.widgets import style
from app.widgets.grid_axis import show_grid
from app.results.parameter_table import format_value
from app.widgets.plot_placeholder import PlotPlaceholder

FIXED_COLUMNS = ("Level (V RMS)", "Peak (mm)", "Small signal")
LARGE = "#e08a00"               # levels beyond small signal: orange, beside the blue small-signal points
SYMBOL_SIZE = 9
EMPTY_TEXT = "No level series: analyse recordings made at rising drive levels (linpar levels FILE...)."


EMPTY_PLOT = "No data yet: choose recordings at rising levels."


class LevelSeriesPlot(pg.PlotWidget):
    """fs (Hz) against peak excursion (mm), +-1 sigma bars; small-signal points apart from the others."""

    def __init__(self, parent=None):
        super().__init__(parent=parent)
        plot = self.getPlotItem()
        show_grid(plot)
        plot.setLabel("left", "fs (Hz)")
        plot.setLabel("bottom", "peak excursion (mm)")
        plot.setMenuEnabled(False)
        plot.addLegend(offset=(-10, 10))
        self.line = pg.PlotDataItem(pen=pg.mkPen(style.GUIDE, width=1))
        self.error = pg.ErrorBarItem(x=np.zeros(0), y=np.zeros(0), beam=0, pen=pg.mkPen(style.GUIDE, width=1))
        self.small = pg.PlotDataItem(pen=None, symbol="o", symbolSize=SYMBOL_SIZE, symbolPen=None,
                                     symbolBrush=style.measured_brush(), name="small signal")
        self.large = pg.PlotDataItem(pen=None, symbol="s", symbolSize=SYMBOL_SIZE, symbolPen=None,
                                     symbolBrush=pg.mkBrush(LARGE), name="large signal (distortion)")
        for item in (self.line, self.error, self.small, self.large):
            plot.addItem(item)
        self.placeholder = PlotPlaceholder(self, EMPTY_PLOT)

    def set_series(self, series: LevelSeries) -> None:
        curve = series.fs_curve()
        x = np.array(curve["peak_displacement_m"]) * 1e3
        fs = np.array(curve["fs_hz"], dtype=float)
        err = np.nan_to_num(np.array(curve["fs_std_hz"], dtype=float), nan=0.0)
        small = np.array(curve["small_signal"], dtype=bool)
        self.line.setData(x, fs)
        self.error.setData(x=x, y=fs, top=err, bottom=err)
        self.small.setData(x[small], fs[small])
        self.large.setData(x[~small], fs[~small])
        self.getPlotItem().setTitle("resonance frequency against peak excursion")
        self.getPlotItem().enableAutoRange()
        self.placeholder.hide()

    def clear_series(self) -> None:
        for item in (self.line, self.small, self.large):
            item.setData([], [])
        self.error.setData(x=np.zeros(0), y=np.zeros(0), top=np.zeros(0), bottom=np.zeros(0))
        self.placeholder.show_text(EMPTY_PLOT)


class LevelSeriesTable(QTableWidget):
    """Table II: one row per level, value(1 sigma) in customary units, as the CLI prints it.

    Each cell's tooltip has the value +- sigma written out and the drift from the smallest level.
    """

    def __init__(self, parent=None):
        super().__init__(0, len(FIXED_COLUMNS), parent)
        self.setHorizontalHeaderLabels(FIXED_COLUMNS)
        self.setEditTriggers(QAbstractItemView.NoEditTriggers)
        self.setSelectionBehavior(QAbstractItemView.SelectRows)
        self.verticalHeader().setVisible(False)
        self.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeToContents)
        self._reference: Level | None = None

    def set_series(self, series: LevelSeries) -> None:
        names = [n for n in TABLE_PARAMETERS if any(n in level.parameters for level in series.levels)]
        headers = list(FIXED_COLUMNS)
        for n in names:
            unit = next(level.parameters[n].display_unit for level in series.levels if n in level.parameters)
            headers.append(n if unit in ("-", "1") else f"{n} ({unit})")
        self.clear()
        self.setColumnCount(len(headers))
        self.setHorizontalHeaderLabels(headers)
        self.setRowCount(len(series.levels))
        self._reference = series.reference
        for row, level in enumerate(series.levels):
            self._fill_row(row, level, names)

    def _fill_row(self, row: int, level: Level, names: list[str]) -> None:
        background, text = style.validity_colours("green" if level.small_signal else "yellow")
        flag = _item("yes" if level.small_signal else "no",
                     "small signal: validity green, no distortion" if level.small_signal
                     else "not small-signal: " + "; ".join(level.reasons))
        flag.setBackground(QBrush(QColor(background)))
        flag.setForeground(QBrush(QColor(text)))
        cells = [_item(f"{level.drive_rms_v:.3g}", level.source or ""),
                 _item(f"{level.peak_displacement_m * 1e3:.3f}", ""), flag]
        for n in names:
            p = level.parameters.get(n)
            if p is None or p.value is None:
                cells.append(_item("n/a", "" if p is None else (p.reason or "")))
                continue
            value, std = format_value(p, all_digits=True)
            drift = level.drift.get(n)
            tip = f"{n} = {value} ± {std} {p.display_unit}"
            if drift is not None and level is not self._reference:
                tip += f"\n{drift.percent:+.3g} % from the smallest level"
            scale = p.display_scale
            cells.append(_item(concise(p.value * scale, None if p.std is None else p.std * abs(scale)), tip))
        for column, item in enumerate(cells):
            self.setItem(row, column, item)


def _item(text: str, tooltip: str) -> QTableWidgetItem:
    item = QTableWidgetItem(text)
    item.setTextAlignment(Qt.AlignRight | Qt.AlignVCenter)
    if tooltip:
        item.setToolTip(tooltip)
    return item


def summary_text(series: LevelSeries) -> str:
    """One line: how far fs and Cms moved over the series (the paper's own summary of its Table II)."""
    first, last = series.levels[0], series.levels[-1]
    n_small = sum(level.small_signal for level in series.levels)
    parts = [f"<b>{len(series.levels)} levels</b>, {first.peak_displacement_m * 1e3:.2f}–"
             f"{last.peak_displacement_m * 1e3:.2f} mm peak; {n_small} small-signal"]
    if len(series.levels) > 1:
        for name, unit, scale in (("fs", "Hz", 1.0), ("Cms", "mm/N", 1e3)):
            a, b, d = first.value(name), last.value(name), last.drift.get(name)
            if a is not None and b is not None and d is not None:
                parts.append(f"{name} {a * scale:.4g} → {b * scale:.4g} {unit} ({d.percent:+.1f} %)")
    return html.escape(" · ").join(parts)


class LevelSeriesView(QWidget):
    """The plot over the table, with a one-line summary on top."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.series: LevelSeries | None = None
        self.summary = QLabel(EMPTY_TEXT)
        self.summary.setTextFormat(Qt.RichText)
        self.summary.setWordWrap(True)
        self.plot = LevelSeriesPlot()
        self.table = LevelSeriesTable()
        splitter = QSplitter(Qt.Vertical)
        splitter.addWidget(self.plot)
        splitter.addWidget(self.table)
        splitter.setStretchFactor(0, 1)
        splitter.setStretchFactor(1, 1)
        splitter.setSizes([500, 300])       # the table shows ~8 levels without scrolling
        layout = QVBoxLayout(self)
        layout.addWidget(self.summary)
        layout.addWidget(splitter, 1)

    def set_series(self, series: LevelSeries) -> None:
        self.series = series
        self.summary.setText(summary_text(series))
        self.plot.set_series(series)
        self.table.set_series(series)

    def clear(self) -> None:
        self.series = None
        self.summary.setText(EMPTY_TEXT)
        self.plot.clear_series()
        self.table.setRowCount(0)


def save_screenshot(series: LevelSeries, path: str | Path, size: tuple[int, int] = (1400, 800)) -> Path:
    """The view showing `series`, grabbed to a PNG (for tools/screenshots.py). Needs a QApplication."""
    app = QApplication.instance()
    if app is None:
        raise RuntimeError("save_screenshot needs a QApplication (QT_QPA_PLATFORM=offscreen without a display)")
    style.configure_pyqtgraph()
    view = LevelSeriesView()
    view.resize(*size)
    view.set_series(series)
    view.show()
    for _ in range(3):          # layout, then the plot's auto range, then the paint
        app.processEvents()
    out = Path(path)
    if not view.grab().save(str(out)):
        raise OSError(f"{out}: the screenshot could not be written")
    view.close()
    view.deleteLater()
    return out
