"""The large-signal curves on screen: Bl(x), Kms(x), Le(x) against x with their bands, limits and measured range,
and the distortion the model predicts against the distortion measured.

Shows an analysis.large_signal.LargeSignalResult; computes nothing but the
curves' samples. Customary units: mm, T·m, N/mm, mH, dB.
"""
from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt

from app.widgets import style
from app.widgets.grid_axis import show_grid
from app.widgets.plot_placeholder import PlotPlaceholder
from app.widgets.plots import LogFrequencyAxis, style_plot

BAND = (209, 73, 91, 55)              # the model's red, translucent: the 2-sigma band
RANGE = (31, 95, 191, 22)             # the measured range: a light blue background
EMPTY_HINT = "Choose recordings of one driver at large signal, or measure with the Large signal template."
LIMIT = "#e08a00"
OUTSIDE_STYLE = Qt.DashLine
SAMPLES = 201
MARGIN = 0.15                          # drawn beyond the measured range on each side (dashed: extrapolated)


class CurvePlot(pg.PlotWidget):
    """One curve against x (mm): the model, its 2-sigma band, the range measured, and limits as lines."""

    def __init__(self, name: str, label: str, scale: float, parent=None):
        super().__init__(parent=parent)
        self.name, self.scale = name, scale
        plot = self.getPlotItem()
        show_grid(plot)
        plot.setLabel("left", label)
        plot.setLabel("bottom", "x (mm), positive outwards")
        plot.getAxis("left").enableAutoSIPrefix(False)      # 0.132 mH, not "132 (x0.001)"
        plot.setMenuEnabled(False)
        self.region = pg.LinearRegionItem(movable=False, brush=pg.mkBrush(*RANGE), pen=pg.mkPen(None))
        self.region.setZValue(-10)
        self.upper = pg.PlotDataItem(pen=pg.mkPen(None))
        self.lower = pg.PlotDataItem(pen=pg.mkPen(None))
        self.band = pg.FillBetweenItem(self.upper, self.lower, brush=pg.mkBrush(*BAND))
        self.inside = pg.PlotDataItem(pen=style.model_pen())
        self.outside = [pg.PlotDataItem(pen=pg.mkPen(style.MODEL, width=1, style=OUTSIDE_STYLE)) for _ in range(2)]
        for item in (self.region, self.upper, self.lower, self.band, self.inside, *self.outside):
            plot.addItem(item)
        self.marks: list = []
        self.placeholder = PlotPlaceholder(self, f"{name}(x): no curve yet. {EMPTY_HINT}")

    def clear_curve(self) -> None:
        for item in (self.upper, self.lower, self.inside, *self.outside):
            item.setData([], [])
        self._clear_marks()
        self.placeholder.show_text(f"{self.name}(x): no curve yet. {EMPTY_HINT}")

    def set_curve(self, curve, limits=(), threshold=None, extra_marks=()) -> None:
        """``limits``: (x_m, text) vertical lines; ``threshold``: (value in the curve's unit, text) horizontal."""
        self.placeholder.hide()
        lo, hi = curve.x_range
        width = hi - lo
        x = np.linspace(lo - MARGIN * width, hi + MARGIN * width, SAMPLES)
        y, s = curve(x) * self.scale, curve.sigma(x) * abs(self.scale)
        mm = x * 1e3
        inside = (x >= lo) & (x <= hi)
        self.inside.setData(mm[inside], y[inside])
        self.outside[0].setData(mm[x <= lo], y[x <= lo])
        self.outside[1].setData(mm[x >= hi], y[x >= hi])
        self.upper.setData(mm, y + 2 * s)
        self.lower.setData(mm, y - 2 * s)
        self.region.setRegion((lo * 1e3, hi * 1e3))
        self._clear_marks()
        plot = self.getPlotItem()
        # Limits' labels near the top, other marks (Bl's maximum) near the bottom: they never sit on each other.
        marks = [(x, text, 0.92, LIMIT, Qt.DashLine) for x, text in limits] + \
                [(x, text, 0.1, style.MODEL, Qt.DashDotLine) for x, text in extra_marks]
        for x_m, text, position, colour, dash in marks:
            line = pg.InfiniteLine(pos=x_m * 1e3, angle=90, movable=False, pen=pg.mkPen(colour, width=1, style=dash),
                                   label=text or None, labelOpts={"position": position, "color": colour,
                                                                  "fill": (255, 255, 255, 200)})
            plot.addItem(line)
            self.marks.append(line)
        if threshold is not None:
            value, text = threshold
            line = pg.InfiniteLine(pos=value, angle=0, movable=False, pen=pg.mkPen(style.GUIDE, width=1,
                                                                                  style=Qt.DotLine),
                                   label=text, labelOpts={"position": 0.2, "color": style.GUIDE,
                                                          "fill": (255, 255, 255, 200)})
            plot.addItem(line)
            self.marks.append(line)
        plot.enableAutoRange()

    def _clear_marks(self) -> None:
        for item in self.marks:
            self.getPlotItem().removeItem(item)
        self.marks = []


class DistortionPlot(pg.PlotWidget):
    """Distortion (the lines not excited) re the signal, per third of an octave: measured points, predicted
    lines, and the noise floor, for the current and the displacement."""

    COLOURS = {"current": style.MEASURED, "displacement": style.RESIDUAL_IMAG}

    def __init__(self, parent=None):
        super().__init__(parent=parent, axisItems={"bottom": LogFrequencyAxis("bottom")})
        plot = self.getPlotItem()
        style_plot(plot, "distortion re signal (dB)", bottom="frequency (Hz)")
        plot.addLegend(offset=(10, -10))          # bottom left: the distortion is largest at low frequencies
        self.items = {}
        for name, colour in self.COLOURS.items():
            measured = pg.PlotDataItem(pen=None, symbol="o", symbolSize=6, symbolPen=None,
                                       symbolBrush=pg.mkBrush(colour), name=f"{name}, measured")
            predicted = pg.PlotDataItem(pen=pg.mkPen(colour, width=2), name=f"{name}, predicted")
            noise = pg.PlotDataItem(pen=pg.mkPen(colour, width=1, style=Qt.DotLine))
            for item in (measured, predicted, noise):
                plot.addItem(item)
            self.items[name] = (measured, predicted, noise)
        self.placeholder = PlotPlaceholder(self, f"Distortion: no data yet. {EMPTY_HINT}")

    def set_fit(self, fit) -> None:
        for name, (measured, predicted, noise) in self.items.items():
            channel = fit.channels.get(name) if fit is not None else None
            if channel is None:
                for item in (measured, predicted, noise):
                    item.setData([], [])
                continue
            hz = np.array(channel.bands_hz)
            for item, values in ((measured, channel.bands_measured_db), (predicted, channel.bands_predicted_db),
                                 (noise, channel.bands_noise_db)):
                y = np.array(values, dtype=float)
                ok = np.isfinite(y) & (hz > 0)
                item.setData(hz[ok], y[ok])
        self.getPlotItem().setTitle(None if fit is None else f"{fit.label}, {fit.drive_rms_v:.3g} V RMS")
        self.getPlotItem().enableAutoRange()
        self.placeholder.show_text("" if fit is not None else f"Distortion: no data yet. {EMPTY_HINT}")
