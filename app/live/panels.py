"""Live spectra of voltage, current and displacement while a measurement averages its periods.

As in the paper's validation figures: per channel, on a log frequency axis in
dB, the signal lines (the excited bins), the noise floor (the scatter between
periods, at every bin) and the noise + distortion lines (the bins not
excited); above each plot the channel's traffic light with its finding and
remedy (analysis.live.LiveFrame).

Frames arrive from the measurement thread, one per averaged period, as fast
as the measurement goes. The panels keep only the newest (`set_frame` is
cheap) and a QTimer draws it at most REPAINT_HZ times a second, as pyqtgraph
advises: drawing every frame of a fast simulator would starve the event loop.
"""
from __future__ import annotations

import math
import time
from typing import Callable

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import QSize, Qt, QTimer, Signal
from PySide6.QtGui import QTextDocument
from PySide6.QtWidgets import QHBoxLayout, QLabel, QVBoxLayout, QWidget

from analysis.live import DB_FLOOR, LiveFrame
from analysis.recording.format import UNITS
from app.jobs.next_turn import in_a_later_turn
from app.widgets import style
from app.widgets.grid_axis import show_grid
from app.widgets.plot_placeholder import PlotPlaceholder
from app.widgets.plots import LEFT_AXIS_WIDTH, LogFrequencyAxis
from app.widgets.traffic_light import CHANNELS, ChannelLight

REPAINT_HZ = 30
REPAINT_INTERVAL_MS = 1000 // REPAINT_HZ + 1      # 34 ms: never above 30 repaints a second
# Qt lets a late timer catch up with its schedule (a tick soon after a late one), never more than one tick per
# interval on average: a repaint closer than this to the last one waits. Half an interval: with 0.9 of one,
# every tick more than 3 ms late (common on a busy machine) cost the next tick too, ~22 instead of 29 a second.
MIN_REPAINT_GAP_S = 0.5 / REPAINT_HZ
IDLE_TICKS = 30                                   # stop the timer after ~1 s without a new frame
SIGNAL_COLOUR = style.MEASURED
DISTORTION_COLOUR = "#e08a00"
NOISE_COLOUR = "#606060"
GRID_COLOUR = "#d9d9d9"
RANGE_STEP_DB = 10.0
DOT_HEIGHT = 0.015          # of the y range: ~2 pixels on a panel 150 pixels tall, plus the pen's width
# The noise floor and the noise + distortion come in a few hundred log-spaced buckets, worked out with the
# frame in the measurement thread (analysis.live, analysis.log_buckets): thousands of bins per channel drawn
# here cost ~100 ms a repaint, with the GIL held (the audio thread waits).
LEGEND = (f"<span style='color:{SIGNAL_COLOUR}'>●</span> signal lines &nbsp; "
          f"<span style='color:{DISTORTION_COLOUR}'>●</span> noise + distortion (lines not excited) &nbsp; "
          f"<span style='color:{NOISE_COLOUR}'>—</span> noise floor")
UNIT_WORDS = {"V": "dB re 1 V", "A": "dB re 1 A", "m": "dB re 1 mm"}
# dB added to a channel's levels (dB re 1 of its SI unit) for its panel: displacement is read in mm, not m.
UNIT_OFFSET_DB = {"m": 60.0}


class SparseFrequencyAxis(LogFrequencyAxis):
    """Ticks and grid lines at 1, 2 and 5 only: the minor grid lines cost a third of a repaint."""

    def logTickValues(self, minVal, maxVal, size, stdTicks):
        return super().logTickValues(minVal, maxVal, size, stdTicks)[:2]


class CompactPlotWidget(pg.PlotWidget):
    """A plot that asks for little and takes what it is given.

    pyqtgraph's views ask for 640 x 480; in a scrolled page with word-wrapped
    labels the page's height follows the sum of the hints, so three panels
    would ask for a page two screens tall. The hint is the minimum: a page with word-wrapped labels is
    laid out at its hinted height, and three panels asking for more pushed the Displacement panel
    below a scroll bar on a 720 px screen; they stretch into whatever room the page has.
    """

    def sizeHint(self) -> QSize:
        return QSize(400, 80)


def _visible(db: np.ndarray) -> np.ndarray:
    """NaN where a value is DB_FLOOR (an exact zero) or unknown, so that nothing is drawn there."""
    out = np.array(db, dtype=np.float64)
    out[~np.isfinite(out) | (out <= DB_FLOOR + 1.0)] = np.nan
    return out


class LiveChannelPanel(QWidget):
    """One channel: the light with its finding, and the plot of its lines, noise floor and noise + distortion."""

    def __init__(self, channel: str, parent=None, frequency_label: bool = True):
        super().__init__(parent)
        self.channel = channel
        self.light = ChannelLight(channel, 14, compact=True)
        self.plot_widget = CompactPlotWidget(axisItems={"bottom": SparseFrequencyAxis("bottom")})
        self.plot_widget.setMinimumHeight(80)      # three of them fit a 720 px screen
        plot = self.plot = self.plot_widget.getPlotItem()
        plot.setLogMode(x=True, y=False)
        # The axis' own horizontal grid costs ~10 ms a panel per repaint (the GIL held all along): the
        # horizontal lines are one item of our own instead, redrawn only when the range changes.
        show_grid(plot, x=True, y=False)
        plot.setMenuEnabled(False)
        plot.setMouseEnabled(x=False, y=False)
        plot.hideButtons()
        plot.getAxis("left").setWidth(LEFT_AXIS_WIDTH)
        # Labelled now: a label set with the first frame re-lays the axis out, a 40 ms first repaint.
        self._unit = UNITS.get(channel, "")
        plot.setLabel("left", UNIT_WORDS.get(self._unit, "dB"))
        if frequency_label:        # once, under the lowest panel: the axes are the same
            plot.setLabel("bottom", "frequency (Hz)")
        # No legend: it would cover lines; the colours are named once above the three panels.
        # Drawn in this order: the dense noise + distortion dots, the noise floor over them, the lines on top.
        # The points are short thick segments of one path, not pyqtgraph symbols: a scatter item keeps Python
        # objects per point and costs ~2 ms a panel per repaint; a path of segments a tenth of that.
        # Curves, not PlotDataItems: a PlotDataItem maps the log axis, finds its bounds and updates its own curve
        # at each setData, three times a channel per repaint; the curves are given log10(f) already.
        self.distortion = pg.PlotCurveItem(pen=pg.mkPen(DISTORTION_COLOUR, width=3), connect="pairs",
                                           antialias=False, skipFiniteCheck=True)
        # Width 1: an antialiased line any wider costs twice as much to draw, with the GIL held throughout.
        self.noise = pg.PlotCurveItem(pen=pg.mkPen(NOISE_COLOUR, width=1), connect="finite")
        self.lines = pg.PlotCurveItem(pen=pg.mkPen(SIGNAL_COLOUR, width=4), connect="pairs", antialias=False,
                                      skipFiniteCheck=True)
        self.y_grid = pg.PlotCurveItem(pen=pg.mkPen(GRID_COLOUR, width=1), connect="pairs", antialias=False,
                                       skipFiniteCheck=True)
        self.y_grid.setZValue(-10)
        for item in (self.y_grid, self.distortion, self.noise, self.lines):
            plot.addItem(item)
        self._freqs_key: tuple | None = None
        self._x_span = (0.0, 1.0)          # log10(f) of the grid lines' ends
        self._y_range: tuple[float, float] | None = None
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(2)
        layout.addWidget(self.light)
        layout.addWidget(self.plot_widget, 1)
        self.empty_text = "No data yet."
        self.placeholder = PlotPlaceholder(self.plot_widget, self.empty_text)

    def show_frame(self, frame: LiveFrame) -> None:
        ch = frame.channels.get(self.channel)
        if ch is None:
            self.clear("absent")
            self.placeholder.show_text(f"No {self.channel} channel in this measurement.")
            return
        self.placeholder.hide()
        self.light.set_state(ch.status, ch.findings)
        if ch.unit != self._unit:          # a new label re-lays the axis out: only when it changes
            self._unit = ch.unit
            self.plot.setLabel("left", UNIT_WORDS.get(ch.unit, f"dB re 1 {ch.unit}"))
        self._set_frequencies(frame)
        line_db, other_db, noise = _visible(ch.line_db), ch.other_db, ch.noise_db      # buckets: NaN for none
        offset = UNIT_OFFSET_DB.get(ch.unit, 0.0)
        if offset:
            line_db, other_db, noise = line_db + offset, other_db + offset, noise + offset
        self._set_y_range(line_db, other_db, noise)
        self._dots(self.lines, frame.line_freqs, line_db, DOT_HEIGHT)
        self._dots(self.distortion, frame.other_freqs, other_db, DOT_HEIGHT * 0.5)
        self.noise.setData(np.log10(frame.noise_freqs), noise)

    def _dots(self, item: pg.PlotCurveItem, freqs: np.ndarray, db: np.ndarray, height: float) -> None:
        """Each point a vertical segment `height` of the y range tall (with the pen's width: a dot)."""
        shown = np.isfinite(db)
        half = 0.5 * height * (self._y_range[1] - self._y_range[0]) if self._y_range else 0.5
        y = db[shown]
        item.setData(np.repeat(np.log10(freqs[shown]), 2), np.column_stack([y - half, y + half]).ravel())

    def _set_frequencies(self, frame: LiveFrame) -> None:
        """The frequency axis spans the band, first to last excited line; set when the lines change."""
        key = (frame.line_freqs.size, float(frame.line_freqs[0]), float(frame.line_freqs[-1]),
               frame.noise_freqs.size)
        if key == self._freqs_key:
            return
        self._freqs_key = key
        lo, hi = np.log10(frame.line_freqs[0]), np.log10(frame.line_freqs[-1])
        self.plot.setXRange(lo, hi, padding=0.02)
        self._x_span = (lo - 0.05, hi + 0.05)
        self._y_range = None               # new lines: the grid is redrawn with the next range

    def _set_y_range(self, *arrays: np.ndarray) -> None:
        """A range in whole RANGE_STEP_DB steps, changed only when the data leave it: no jitter per frame."""
        values = np.concatenate([a[np.isfinite(a)] for a in arrays])
        if values.size == 0:
            return
        # The 0.5th percentile (the nearest value below it): np.partition takes 4 us on a channel's ~900 values,
        # np.percentile 60 us.
        k = int(0.005 * (values.size - 1))
        low = np.floor(np.partition(values, k)[k] / RANGE_STEP_DB) * RANGE_STEP_DB - RANGE_STEP_DB
        high = np.ceil(values.max() / RANGE_STEP_DB) * RANGE_STEP_DB + RANGE_STEP_DB
        if self._y_range is None or low < self._y_range[0] or high > self._y_range[1] \
                or low > self._y_range[0] + 3 * RANGE_STEP_DB or high < self._y_range[1] - 3 * RANGE_STEP_DB:
            self._y_range = (low, high)
            self.plot.setYRange(low, high, padding=0)
            step = RANGE_STEP_DB if high - low <= 120 else 2 * RANGE_STEP_DB
            levels = np.arange(np.ceil(low / step) * step, high + 1e-9, step)
            self.y_grid.setData(np.tile(self._x_span, levels.size), np.repeat(levels, 2))

    def clear(self, status: str = "unknown", band_hz: tuple[float, float] | None = None) -> None:
        for item in (self.lines, self.distortion, self.noise, self.y_grid):
            item.setData([], [])
        self.light.set_state(status, ())
        self.placeholder.show_text(self.empty_text)
        self._y_range = None
        self._freqs_key = None             # the next frame sets the frequency axis to its own lines
        if band_hz is not None:            # the axis laid out before the first frame, not with it
            lo, hi = np.log10(band_hz[0]), np.log10(band_hz[1])
            self.plot.setXRange(lo, hi, padding=0.02)


class LivePanels(QWidget):
    """The three channel panels, fed LiveFrames from any rate and drawn at most REPAINT_HZ a second."""

    repainted = Signal(int)         # the frame's n_periods, after it was drawn

    def __init__(self, empty_text: str = "No data yet.", parent=None):
        super().__init__(parent)
        self.panels = {name: LiveChannelPanel(name, frequency_label=name == CHANNELS[-1]) for name in CHANNELS}
        self.empty_text = empty_text
        for panel in self.panels.values():
            panel.empty_text = empty_text
            panel.placeholder.show_text(empty_text)
        # What changes with each frame (periods averaged, peak excursion) in a label of a fixed size, grown
        # when a text needs more: a label that may change size re-lays the page out at every text, 5-7 ms
        # of the GUI thread a repaint. The colours' legend beside it does not change.
        self.status = QLabel()
        self.status.setTextFormat(Qt.RichText)
        self.legend = QLabel(LEGEND)
        self.legend.setWordWrap(True)
        self.legend.setTextFormat(Qt.RichText)
        self.legend.setVisible(False)
        top = QHBoxLayout()
        top.setContentsMargins(0, 0, 0, 0)
        top.addWidget(self.status, 0, Qt.AlignLeft)          # at the left also while the legend is hidden
        top.addWidget(self.legend, 1)
        self._set_status("No measurement running: the spectra appear here period by period.", fit=True)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addLayout(top)
        for panel in self.panels.values():
            layout.addWidget(panel, 1)
        self.timer = QTimer(self)
        self.timer.setTimerType(Qt.PreciseTimer)     # a coarse timer may fire 5 % early, or late
        self.timer.setInterval(REPAINT_INTERVAL_MS)
        self.timer.timeout.connect(self.on_repaint_timer)
        self._pending: LiveFrame | None = None
        self._idle = 0
        self._drawing = 0               # counts draws begun: a channel left over from an older one is skipped
        self.frame: LiveFrame | None = None        # the frame on screen
        self.frames_received = 0
        self.paint_times: list[float] = []          # time.monotonic() when each repaint began (bench, tests)

    def set_frame(self, frame: LiveFrame) -> None:
        """Keep the newest frame; the timer draws it. Cheap: called for every period."""
        self._pending = frame
        self.frames_received += 1
        self._idle = 0
        if not self.timer.isActive():
            self.timer.start()

    def on_repaint_timer(self) -> None:
        # paint_times holds when each draw began, so the time a draw takes does not shorten the gap.
        if self.paint_times and time.monotonic() - self.paint_times[-1] < MIN_REPAINT_GAP_S:
            return
        frame, self._pending = self._pending, None
        if frame is None:
            self._idle += 1
            if self._idle > IDLE_TICKS:
                self.timer.stop()
            return
        self.draw(frame)

    def draw(self, frame: LiveFrame) -> None:
        """Draw `frame`: one channel now and each of the others in a later turn of the event loop.

        All three at once (their new data, then their repaint) held the GUI thread for 40 ms and more
        on a busy machine; a channel at a time gives the loop room in between, and the three still
        change within a few milliseconds of each other. `repainted` follows the last channel.
        """
        self.paint_times.append(time.monotonic())
        self.frame = frame
        self._drawing += 1
        self._draw_channel(self._drawing, frame, list(self.panels.values()))

    def _draw_channel(self, drawing: int, frame: LiveFrame, panels: list) -> None:
        if drawing != self._drawing:        # a newer frame, or clear(), took over
            return
        panels[0].show_frame(frame)
        if len(panels) > 1:
            in_a_later_turn(self, lambda: self._draw_channel(drawing, frame, panels[1:]))
            return
        peak = frame.peak_displacement_m
        peak_text = f", peak excursion {peak * 1e3:.3f} mm" if peak is not None else ""
        self._set_status(f"<b>{frame.n_periods} period{'s' if frame.n_periods != 1 else ''} averaged</b>"
                         f"{peak_text}.")
        self.repainted.emit(frame.n_periods)

    def _set_status(self, text: str, fit: bool = False) -> None:
        """The status text; its label's size follows it when `fit`, else it only grows (see __init__)."""
        self.status.setText(text)
        # The text's own size: a fixed-size rich-text label's sizeHint answers its current width.
        document = QTextDocument()
        document.setDocumentMargin(0)
        document.setDefaultFont(self.status.font())
        document.setHtml(text)
        width, height = math.ceil(document.idealWidth()) + 2, math.ceil(document.size().height())
        if fit or width > self.status.width() or height > self.status.height():
            self.status.setFixedSize(width, height)

    def clear(self, text: str = "Waiting for the first period…", band_hz: tuple[float, float] | None = None,
              then: Callable[[], None] | None = None) -> None:
        """Empty panels; `band_hz`, when known, sets the frequency axis already. `then` is called in the turn after
        the last channel's (its paint is done by then), unless a newer clear or frame took over."""
        self._pending = None
        self.frame = None
        self._drawing += 1
        self.timer.stop()
        self._set_status(text, fit=True)
        self.legend.setVisible(True)
        for panel in self.panels.values():       # until the first period, say so where the lines will be
            panel.empty_text = text
        self._clear_channel(self._drawing, list(self.panels.values()), band_hz, then)

    def _clear_channel(self, drawing: int, panels: list, band_hz: tuple[float, float] | None,
                       then: Callable[[], None] | None) -> None:
        """As _draw_channel: a channel per turn of the event loop (a measurement starts with this)."""
        if drawing != self._drawing:
            return
        if not panels:
            then()
            return
        panels[0].clear(band_hz=band_hz)
        if len(panels) > 1 or then is not None:
            in_a_later_turn(self, lambda: self._clear_channel(drawing, panels[1:], band_hz, then))
