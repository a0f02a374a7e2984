"""Up to 8 stored measurements side by side: their measured |Z| and |Hx| overlaid, and their parameters.

The curves are the measured lines as the archive stored them (no fit is
redone); one colour per measurement, the same in the legend and in the
heading of its column in the parameter table. The table is
analysis.archive.compare's: rows are parameters in customary units, columns
the measurements (value ± 1σ as stored), then the spread between them; a
cell's tooltip has its deviation from the first measurement.
"""
from __future__ import annotations

import dataclasses
import html

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt
from PySide6.QtGui import QBrush, QColor
from PySide6.QtWidgets import (QAbstractItemView, QHeaderView, QLabel, QSplitter, QTableWidget, QTableWidgetItem,
                               QVBoxLayout, QWidget)

from analysis.report.numbers import format_number, format_std, plain_number, pretty_unit
from app.archive.table import date_text
from app.widgets.plots import LogFrequencyAxis, style_plot

# Eight colours told apart on white paper (Tableau 10 without its grey and olive).
PALETTE = ("#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf")
VALUE_ROLE = Qt.UserRole          # the value in the display unit (float or None)
STD_ROLE = Qt.UserRole + 1
CURVE_WIDTH = 1.6
EMPTY_TEXT = "Select up to 8 measurements on the list and press Compare."
CHANNELS = (("impedance", 1.0), ("displacement", 1e3))      # |Z| in Ω, |Hx| in mm/V
# The parameters a comparison is usually about come first; the rest (electrical analogues...) follow in their order.
FIRST_ROWS = ("RE", "fs", "Qts", "Qes", "Qms", "Bl", "Mms", "Cms", "Rms", "Kms", "Vas", "LE", "SPL_2.83V_1m",
              "SPL_1W_1m", "eta0")


def _row_order(row) -> int:
    return FIRST_ROWS.index(row.name) if row.name in FIRST_ROWS else len(FIRST_ROWS)   # a stable sort


def column_label(number: int, label: str, date: str) -> str:
    """"2. W18-PAPER 0033" over its date to the second (plain text): the number tells two measurements of one
    driver apart, the date which was measured when, even two in one minute; the tooltip has the id."""
    return f"{number}. {label}\n{date_text(date)}"


class OverlayPlot(pg.GraphicsLayoutWidget):
    """|Z| (linear) beside |Hx| (log), x axes linked; one legend, bottom left of Hx where its curves never are."""

    def __init__(self, parent=None):
        super().__init__(parent=parent)
        self.impedance = self.addPlot(row=0, col=0, axisItems={"bottom": LogFrequencyAxis("bottom")})
        self.displacement = self.addPlot(row=0, col=1, axisItems={"bottom": LogFrequencyAxis("bottom")})
        style_plot(self.impedance, "|Z| (Ω)", bottom="frequency (Hz)")
        style_plot(self.displacement, "|Hx| (mm/V)", log_y=True, bottom="frequency (Hz)")
        self.displacement.setXLink(self.impedance)
        self.impedance.setTitle("Impedance |Z| = |U / I|, measured")
        self.displacement.setTitle("Displacement per volt |Hx| = |X / U|, measured")
        self.legend = self.displacement.addLegend(offset=(10, -10))
        self.items: dict[str, list[pg.PlotDataItem]] = {"impedance": [], "displacement": []}

    def plot_of(self, channel: str) -> pg.PlotItem:
        return self.impedance if channel == "impedance" else self.displacement

    def clear_curves(self) -> None:
        for channel, items in self.items.items():
            plot = self.plot_of(channel)
            for item in items:
                plot.removeItem(item)
            items.clear()
        self.legend.clear()

    def set_curves(self, curves, labels) -> None:
        """curves: per measurement, channel -> analysis.archive.results.Curve; labels: the legend's names."""
        self.clear_curves()
        for number, (channel_curves, label) in enumerate(zip(curves, labels)):
            colour = PALETTE[number % len(PALETTE)]
            named = False
            for channel, scale in CHANNELS:
                curve = channel_curves.get(channel)
                if curve is None:
                    continue             # measured without the laser: no Hx for this one
                magnitude = np.abs(curve.measured) * scale
                keep = np.isfinite(magnitude) & np.isfinite(curve.freqs) & (curve.freqs > 0)
                if channel == "displacement":
                    keep &= magnitude > 0
                item = pg.PlotDataItem(curve.freqs[keep], magnitude[keep],
                                       pen=pg.mkPen(colour, width=CURVE_WIDTH), symbol="o", symbolSize=3,
                                       symbolPen=None, symbolBrush=pg.mkBrush(colour))
                self.plot_of(channel).addItem(item)
                self.items[channel].append(item)
                if not named:            # one entry per measurement, with or without its Hx
                    # pyqtgraph draws a legend's names as HTML: a driver named "<b>" is text, not markup.
                    self.legend.addItem(item, html.escape(label))
                    named = True
        for channel, _ in CHANNELS:
            self.plot_of(channel).enableAutoRange()


class ComparisonTable(QTableWidget):
    """Rows: parameters, with their unit. Columns: one per measurement, then the spread."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setEditTriggers(QAbstractItemView.NoEditTriggers)
        self.setSelectionBehavior(QAbstractItemView.SelectRows)
        self.setAlternatingRowColors(True)
        self.setWordWrap(False)
        self.verticalHeader().setDefaultSectionSize(self.fontMetrics().height() + 8)
        self.n_measurements = 0
        self.names: list[str] = []

    def set_comparison(self, comparison, dates) -> None:
        comparison = dataclasses.replace(comparison, rows=tuple(sorted(comparison.rows, key=_row_order)))
        n = len(comparison.ids)
        self.n_measurements = n
        self.names = [row.name for row in comparison.rows]
        self.clear()
        self.setRowCount(len(comparison.rows))
        self.setColumnCount(n + 1)
        headers = [column_label(i + 1, label, date) for i, (label, date)
                   in enumerate(zip(comparison.labels, dates))] + ["Spread\n(σ between)"]
        for col, text in enumerate(headers):
            item = QTableWidgetItem(text)
            if col < n:
                item.setForeground(QBrush(QColor(PALETTE[col % len(PALETTE)])))
                item.setToolTip(f"{comparison.ids[col]}: {comparison.labels[col]}, measured {date_text(dates[col])}")
            else:
                item.setToolTip("The standard deviation of the values between the measurements, to set against "
                                "each one's own ±1σ: larger means the drivers differ, not only the measurements")
            self.setHorizontalHeaderItem(col, item)
        self.setVerticalHeaderLabels([row.name + (f" ({pretty_unit(row.display_unit)})"
                                                  if pretty_unit(row.display_unit) else "")
                                      for row in comparison.rows])
        for r, row in enumerate(comparison.rows):
            for i, (value, std, dev) in enumerate(zip(row.values, row.stds, row.deviation_percent)):
                text = "n/a" if value is None else format_number(value, std) + \
                    ("" if std is None else f" ± {format_std(std)}")
                item = QTableWidgetItem(text)
                item.setData(VALUE_ROLE, value)
                item.setData(STD_ROLE, std)
                item.setTextAlignment(Qt.AlignRight | Qt.AlignVCenter)
                if i and dev is not None:
                    item.setToolTip(f"{dev:+.2f} % from measurement 1")
                self.setItem(r, i, item)
            spread = QTableWidgetItem("" if row.spread is None else plain_number(row.spread))    # no "1.6e-05"
            spread.setTextAlignment(Qt.AlignRight | Qt.AlignVCenter)
            if row.mean is not None:
                spread.setToolTip(f"mean {row.mean:.6g} {pretty_unit(row.display_unit)}")
            self.setItem(r, n, spread)
        header = self.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeToContents)

    def values(self, number: int) -> dict[str, float | None]:
        """Parameter -> the value shown for measurement `number` (0-based), in the display unit."""
        return {name: self.item(r, number).data(VALUE_ROLE) for r, name in enumerate(self.names)}


class CompareView(QWidget):
    def __init__(self, parent=None):
        super().__init__(parent)
        self.heading = QLabel(EMPTY_TEXT)
        self.heading.setWordWrap(True)
        self.heading.setTextFormat(Qt.RichText)
        self.plot = OverlayPlot()
        self.table = ComparisonTable()
        # The plots above the table: the table gets the whole width, room for eight columns.
        splitter = QSplitter(Qt.Vertical)
        splitter.addWidget(self.plot)
        splitter.addWidget(self.table)
        splitter.setStretchFactor(0, 4)
        splitter.setStretchFactor(1, 5)
        splitter.setSizes([340, 425])
        self.splitter = splitter
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.heading)
        layout.addWidget(splitter, 1)
        self.data = None

    def clear(self) -> None:
        self.data = None
        self.plot.clear_curves()
        self.table.clear()
        self.table.setRowCount(0)
        self.table.setColumnCount(0)
        self.table.n_measurements, self.table.names = 0, []
        self.heading.setText(EMPTY_TEXT)

    def set_data(self, data) -> None:
        """An app.archive.worker.ComparisonData."""
        self.data = data
        c = data.comparison
        labels = [f"{i + 1}. {label}" for i, label in enumerate(c.labels)]
        self.plot.set_curves(data.curves, labels)
        self.table.set_comparison(c, data.dates)
        missing = [labels[i] for i, curves in enumerate(data.curves) if "displacement" not in curves]
        text = (f"<b>{len(c.ids)} measurements</b>: curves as measured; parameters as stored (±1σ); the "
                "tooltip of a value says how far it is from measurement 1.")
        if missing:
            text += " No displacement channel (no Hx) in: " + html.escape(", ".join(missing)) + "."
        self.heading.setText(text)
