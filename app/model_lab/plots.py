"""The model lab's plots: the normalised residual of Z and Hx, and reduced chi^2 against model version."""
from __future__ import annotations

import html
from collections.abc import Iterator
import math
from dataclasses import dataclass

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QLabel, QVBoxLayout, QWidget

from app.widgets import style
from app.widgets.grid_axis import OpaqueGridAxis, show_grid
from app.widgets.layout_room import LinesLabel
from app.widgets.plots import LEFT_AXIS_WIDTH, RESIDUAL_MIN_RANGE, LogFrequencyAxis
from app.widgets.still_scene import StillPlotWidget, StillScene
from app.results.curves import ChannelCurves, ResultCurves

CHANNEL_SHORT = {"impedance": "Z", "displacement": "Hx"}
CHANNEL_COLOURS = {"impedance": style.MEASURED, "displacement": style.RESIDUAL_IMAG}
NOISE_FLOOR_COLOUR = "#2e7d32"
PIXELS_PER_VERSION_LABEL = 36
LISTED_VERSIONS = 8
LEGEND_LINES = 3            # the chart's list of versions: cut beyond, whole in its tooltip
RESIDUAL_WORDS_LINES = 3    # where the residual sits, in words, over the residual plots
PIXELS_PER_DECADE_LABEL = 22


def chi2_text(chi2_red: dict[str, float]) -> str:
    return ", ".join(f"{CHANNEL_SHORT.get(k, k)} {v:.3g}" for k, v in chi2_red.items())


def _guides(plot: pg.PlotItem) -> None:
    for pos, dash in ((0.0, Qt.SolidLine), (1.0, Qt.DashLine), (-1.0, Qt.DashLine),
                      (3.0, Qt.DotLine), (-3.0, Qt.DotLine)):
        plot.addItem(pg.InfiniteLine(pos=pos, angle=0, movable=False,
                                     pen=pg.mkPen(style.GUIDE, width=1, style=dash)))


class ResidualPlot(StillScene, pg.PlotWidget):
    """The normalised residual of one channel per line: real and imaginary parts, in sigma."""

    def __init__(self, channel: str, bottom_label: bool, parent=None):
        super().__init__(parent=parent, axisItems={"bottom": LogFrequencyAxis("bottom")})
        self.channel = channel
        plot = self.getPlotItem()
        plot.setLogMode(x=True, y=False)
        show_grid(plot)
        plot.setLabel("left", f"{CHANNEL_SHORT[channel]} residual (σ)")
        plot.getAxis("left").setWidth(LEFT_AXIS_WIDTH)
        if bottom_label:
            plot.setLabel("bottom", "frequency (Hz)")
        plot.setMenuEnabled(False)
        _guides(plot)
        # No dynamic range limit (pyqtgraph clips points beyond 1e6 view heights): the y range always holds every
        # point (set_curves), so it never clipped, but with it every new range built the point clouds again
        # (each setYRange ran the items' update a second time: 1-2 ms of the GUI thread per refit and plot).
        self.real = pg.PlotDataItem(pen=None, symbol="o", symbolSize=4, symbolPen=None,
                                    symbolBrush=pg.mkBrush(style.RESIDUAL_REAL), dynamicRangeLimit=None)
        self.imag = pg.PlotDataItem(pen=None, symbol="t", symbolSize=5, symbolPen=None,
                                    symbolBrush=pg.mkBrush(style.RESIDUAL_IMAG), dynamicRangeLimit=None)
        plot.addItem(self.real)
        plot.addItem(self.imag)

    def set_curves(self, curves: ChannelCurves) -> None:
        res = curves.residual
        self.real.setData(curves.freqs, res.real)
        self.imag.setData(curves.freqs, np.imag(res))
        # In the title rather than a legend: a legend would cover the points. Short: a title wider than the
        # plot would set its minimum width, and the lab's middle column is ~500 px on a 1280 px screen.
        self.getPlotItem().setTitle(
            f"{CHANNEL_SHORT[self.channel]}: (model − measured)/σ, "
            f"<span style='color:{style.RESIDUAL_REAL}'>● real</span> "
            f"<span style='color:{style.RESIDUAL_IMAG}'>▼ imag.</span>, χ²ᵣ {curves.chi2_red:.3g}",
            size="9pt")
        # Every point in view, unlike the Results page's clipped strip: here the size of a misfit
        # (thousands of sigma before an effect is added, one after) is the point.
        parts = np.abs(np.concatenate([res.real, np.imag(res)]))
        parts = parts[np.isfinite(parts)]
        peak = float(parts.max()) * 1.1 if parts.size else 0.0
        limit = max(RESIDUAL_MIN_RANGE, peak)
        self.getPlotItem().setYRange(-limit, limit, padding=0)
        self.getPlotItem().enableAutoRange(axis="x")

    def clear_curves(self) -> None:
        self.real.setData([], [])
        self.imag.setData([], [])
        self.getPlotItem().setTitle(None)


class ResidualPanel(QWidget):
    """Where the residual sits, in words (analysis.diagnosis.residuals.describe), over the residual of Z and Hx."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.text = LinesLabel(RESIDUAL_WORDS_LINES)      # as many lines for every version: the plots stay put
        self.text.setTextFormat(Qt.RichText)
        self.text.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.impedance = ResidualPlot("impedance", bottom_label=False)
        self.displacement = ResidualPlot("displacement", bottom_label=True)
        self.displacement.getPlotItem().setXLink(self.impedance.getPlotItem())
        self.no_displacement = QLabel("No displacement channel in this recording: only Z is fitted.")
        self.no_displacement.setAlignment(Qt.AlignCenter)
        self.no_displacement.hide()
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.text)
        layout.addWidget(self.impedance, 1)
        layout.addWidget(self.displacement, 1)
        layout.addWidget(self.no_displacement)
        self._has_x: bool | None = None         # the Hx plot shown (None: not decided yet)

    def set_fit(self, curves: ResultCurves, residual: str) -> None:
        for _ in self.setting_fit(curves, residual):
            pass

    def setting_fit(self, curves: ResultCurves, residual: str) -> Iterator[None]:
        """set_fit in two steps (each plot ~10 ms of CPU), for a caller that runs them in turns of their own."""
        self.text.setText(f"<b>Where the residual sits</b>: {html.escape(residual)}")
        self.impedance.set_curves(curves.impedance)
        yield
        has_x = curves.displacement is not None
        if has_x:
            self.displacement.set_curves(curves.displacement)
        else:
            self.displacement.clear_curves()
        self.displacement.setVisible(has_x)
        self.no_displacement.setVisible(not has_x)
        # The frequency axis is labelled on the lowest plot shown; set when that changes (setting it again
        # re-laid the |Z| plot out and redrew it after every refit: 2 ms of the GUI thread).
        if has_x != self._has_x:
            self._has_x = has_x
            self.impedance.getPlotItem().setLabel("bottom", None if has_x else "frequency (Hz)")

    def clear(self) -> None:
        self.text.setText("")
        self.impedance.clear_curves()
        self.displacement.clear_curves()


class VersionAxis(OpaqueGridAxis):
    """Whole version numbers only, thinned out so that the labels never overlap."""

    def tickValues(self, minVal, maxVal, size):
        first, last = math.ceil(minVal), math.floor(maxVal)
        if last < first:
            return []
        room = max(1, int(size // PIXELS_PER_VERSION_LABEL))
        step = max(1, math.ceil((last - first + 1) / room))
        start = math.ceil(first / step) * step
        return [(float(step), [float(v) for v in range(start, last + 1, step)])]

    def tickStrings(self, values, scale, spacing):
        return [str(int(round(v))) for v in values]


class DecadeAxis(OpaqueGridAxis):
    """A log axis labelled at whole decades only ("0.1", "1", "10", "10⁴").

    pyqtgraph's own labels every minor tick on a range of a decade or two,
    piling "0.4 0.5 0.6 ..." up under the noise floor.
    """

    SUPERSCRIPTS = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")

    def logTickValues(self, minVal, maxVal, size, stdTicks):
        first, last = math.ceil(minVal), math.floor(maxVal)
        decades = list(range(first, last + 1))
        step = max(1, math.ceil(len(decades) / max(1, size // PIXELS_PER_DECADE_LABEL)))
        labelled = [float(d) for d in decades if d % step == 0]
        minor = [d + math.log10(m) for d in range(first - 1, last + 1) for m in range(2, 10)
                 if minVal <= d + math.log10(m) <= maxVal] if step == 1 else []
        return [(float(step), labelled), (None, minor)]

    def logTickStrings(self, values, scale, spacing):
        return [self.decade_text(v) for v in values]

    @classmethod
    def decade_text(cls, log_value: float) -> str:
        if abs(log_value - round(log_value)) > 1e-6:
            return ""
        k = int(round(log_value))
        return f"{10.0**k:g}" if -2 <= k <= 3 else "10" + str(k).translate(cls.SUPERSCRIPTS)


@dataclass(frozen=True, slots=True)
class ChartPoint:
    version: int
    effects: str                  # the model's effect list
    how: str                      # how this version came about
    chi2_red: dict[str, float]

    def tip(self) -> str:
        return f"version {self.version}: {self.effects}\n{self.how}\nreduced χ²: {chi2_text(self.chi2_red)}"


class ChiSquareChart(QWidget):
    """Reduced chi^2 of each channel against model version, log y, with the noise floor at 1."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.points: list[ChartPoint] = []
        self.plot_widget = StillPlotWidget(axisItems={"bottom": VersionAxis("bottom"), "left": DecadeAxis("left")})
        plot = self.plot = self.plot_widget.getPlotItem()
        plot.setLogMode(x=False, y=True)
        show_grid(plot, x=False, y=True)
        plot.setLabel("left", "reduced χ²")
        plot.setLabel("bottom", "model version")
        plot.setMenuEnabled(False)
        # The channels' colours in the title, not in a legend over the plot: wherever a legend sat, the noise
        # floor's label met it for some range of chi^2 (at 1280x720 "Hx" lay over "noise floor" when the last
        # versions neared 1). Short, as the residual plots' titles: a wider title would set the chart's minimum width.
        swatches = " ".join(f"<span style='color:{CHANNEL_COLOURS[c]}'>●</span> {CHANNEL_SHORT[c]}"
                            for c in CHANNEL_COLOURS)
        plot.setTitle(f"Reduced χ²: {swatches}; 1 is the noise floor", size="9pt")
        # In log mode an InfiniteLine sits in view coordinates: log10(1) = 0.
        self.floor = pg.InfiniteLine(pos=0.0, angle=0, movable=False,
                                     pen=pg.mkPen(NOISE_FLOOR_COLOUR, width=2, style=Qt.DashLine),
                                     label="noise floor (χ²ᵣ = 1)",
                                     # At the right end, over the line: the first versions sit on the left.
                                     labelOpts={"position": 0.98, "color": NOISE_FLOOR_COLOUR,
                                                "anchors": [(1, 1), (1, 1)]})
        plot.addItem(self.floor)
        self.series: dict[str, pg.PlotDataItem] = {}
        for channel, colour in CHANNEL_COLOURS.items():
            item = pg.PlotDataItem(pen=pg.mkPen(colour, width=2), symbol="o", symbolSize=8, symbolPen=None,
                                   symbolBrush=pg.mkBrush(colour), name=CHANNEL_SHORT[channel],
                                   dynamicRangeLimit=None)      # the range holds every point, as ResidualPlot's
            # Hovering a point names its model: the x axis has room for version numbers only.
            item.scatter.opts["hoverable"] = True
            item.scatter.opts["tip"] = self._tip
            item.scatter.setAcceptHoverEvents(True)
            plot.addItem(item)
            self.series[channel] = item
        self.legend_label = LinesLabel(LEGEND_LINES)       # a line more per version moved the plot above it
        self.legend_label.setTextFormat(Qt.RichText)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.plot_widget, 1)
        layout.addWidget(self.legend_label)

    @staticmethod
    def _tip(x, y, data) -> str:
        return data.tip() if isinstance(data, ChartPoint) else ""

    def set_points(self, points: list[ChartPoint]) -> None:
        self.points = list(points)
        values = []
        for channel, item in self.series.items():
            mine = [p for p in self.points if channel in p.chi2_red]
            x = np.array([p.version for p in mine], dtype=float)
            y = np.array([max(p.chi2_red[channel], 1e-12) for p in mine])  # log axis: never 0
            item.setData(x, y, data=mine)
            values.extend(y)
        last = self.points[-1].version if self.points else 1
        self.plot.setXRange(0.5, max(last, 5) + 0.5, padding=0)
        lo = min(min(values, default=1.0), 1.0)
        hi = max(max(values, default=1.0), 1.0)
        # At least a decade either side of 1: a narrower log axis labels its minor ticks into a pile.
        self.plot.setYRange(min(math.log10(lo) - 0.3, -1.2), max(math.log10(hi) + 0.4, 1.2), padding=0)
        # The latest versions only: a long history would push the chart off the page.
        shown = [f"<b>{p.version}</b> {html.escape(p.effects)}" for p in self.points[-LISTED_VERSIONS:]]
        more = "… · " if len(self.points) > LISTED_VERSIONS else ""
        self.legend_label.setText(f"Versions: {more}{' · '.join(shown)}" if shown else "")

    def data(self, channel: str) -> tuple[np.ndarray, np.ndarray]:
        """(versions, reduced chi^2) drawn for `channel`, as given (not log10)."""
        item = self.series[channel]
        if item.xData is None:
            return np.zeros(0), np.zeros(0)
        return np.asarray(item.xData), np.asarray(item.yData)
