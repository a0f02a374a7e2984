"""Frequency-response plots: measured lines as points, the model as a line, and
a residual strip in units of sigma underneath.

pyqtgraph applies log mode to the data items it knows (PlotDataItem) but not
to ErrorBarItem, which is drawn in view coordinates: error bars are therefore
built here in log10 coordinates by hand.
"""
from __future__ import annotations

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt

from app.widgets import style
from app.widgets.grid_axis import OpaqueGridAxis, show_grid
from app.widgets.plot_placeholder import PlotPlaceholder
from app.widgets.still_scene import StillScene

LEFT_AXIS_WIDTH = 72          # the same on every row, so that the x axes line up
RESIDUAL_MIN_RANGE = 4.0      # sigma: the +-3 guides always stay in view
RESIDUAL_MAX_RANGE = 30.0     # beyond that, outliers are pinned at the edge so the rest stays readable
EDGE = 0.93                   # where a pinned point sits, as a share of the range: inside the strip, visible
NO_CURVES = "Nothing to draw: no fitted measurement (the validity above says why)."


class LogFrequencyAxis(OpaqueGridAxis):
    """Frequency axis labelled at 1, 2 and 5 per decade ("20", "500", "2k").

    pyqtgraph's own log axis labels every minor tick as "5·10¹", which
    overlaps into an unreadable row on a plot a few decades wide.
    """

    LABELLED = (1, 2, 5)
    UNLABELLED = (3, 4, 6, 7, 8, 9)

    def logTickValues(self, minVal, maxVal, size, stdTicks):
        first, last = int(np.floor(minVal)), int(np.ceil(maxVal))

        def ticks(mantissas):
            return [v for d in range(first, last + 1) for m in mantissas
                    if minVal <= (v := d + np.log10(m)) <= maxVal]
        return [(1.0, ticks((1,))), (None, ticks((2, 5))), (None, ticks(self.UNLABELLED))]

    def logTickStrings(self, values, scale, spacing):
        return [self.frequency_text(v) for v in values]

    @classmethod
    def frequency_text(cls, log_value: float) -> str:
        f = 10.0**log_value
        mantissa = round(f / 10.0 ** np.floor(log_value + 1e-9))
        if mantissa not in cls.LABELLED:
            return ""
        return f"{f / 1000:g}k" if f >= 999.5 else f"{f:.3g}"


def style_plot(plot: pg.PlotItem, left: str, log_y: bool = False, bottom: str | None = None) -> None:
    show_grid(plot)
    plot.setLogMode(x=True, y=log_y)
    plot.setLabel("left", left)
    plot.getAxis("left").setWidth(LEFT_AXIS_WIDTH)
    if bottom:
        plot.setLabel("bottom", bottom)
    else:
        plot.getAxis("bottom").setStyle(showValues=False)
    plot.setMenuEnabled(False)


def _measured_item(name: str = "measured") -> pg.PlotDataItem:
    return pg.PlotDataItem(pen=None, symbol="o", symbolSize=style.MEASURED_SYMBOL_SIZE,
                           symbolBrush=style.measured_brush(), symbolPen=None, name=name)


def _model_item(name: str = "model") -> pg.PlotDataItem:
    return pg.PlotDataItem(pen=style.model_pen(), name=name)


def _error_item() -> pg.ErrorBarItem:
    return pg.ErrorBarItem(x=np.zeros(0), y=np.zeros(0), beam=0,
                           pen=pg.mkPen(style.MEASURED, width=1))


def set_error_bars(item: pg.ErrorBarItem, freqs: np.ndarray, y: np.ndarray, err: np.ndarray,
                   log_y: bool = False) -> None:
    """Vertical +-err bars at (freqs, y), in the log10 x (and optionally y) view coordinates."""
    x = np.log10(freqs)
    err = np.nan_to_num(err, nan=0.0, posinf=0.0)
    if log_y:
        with np.errstate(divide="ignore", invalid="ignore"):
            centre = np.log10(y)
            top = np.log10(y + err) - centre
            low = np.where(y - err > 0, y - err, y * 1e-3)   # a bar through zero: draw it three decades long
            bottom = centre - np.log10(low)
        item.setData(x=x, y=centre, top=top, bottom=bottom)
    else:
        item.setData(x=x, y=y, top=err, bottom=err)


def _guides(plot: pg.PlotItem) -> None:
    for pos, dash in ((0.0, Qt.SolidLine), (1.0, Qt.DashLine), (-1.0, Qt.DashLine),
                      (3.0, Qt.DotLine), (-3.0, Qt.DotLine)):
        plot.addItem(pg.InfiniteLine(pos=pos, angle=0, movable=False,
                                     pen=pg.mkPen(style.GUIDE, width=1, style=dash)))


def beyond_range(freqs: np.ndarray, residual: np.ndarray, limit: float) -> tuple[np.ndarray, np.ndarray, str]:
    """The lines whose real or imaginary residual lies beyond +-limit: (their frequencies, the sign of the
    larger part), and the words that count them ("14 points beyond ±30σ, up to 2.8e+04σ at 8.2 Hz"; empty
    when none). A misfit of thousands of sigma must not vanish off the strip's edge: on a recording with
    hidden physics it was the only sign of where the model failed."""
    parts = np.stack([np.asarray(residual.real, float), np.asarray(residual.imag, float)])
    size = np.where(np.isfinite(parts), np.abs(parts), 0.0)
    larger = np.argmax(size, axis=0)
    peak = size[larger, np.arange(size.shape[1])]
    out = peak > limit
    if not out.any():
        return np.zeros(0), np.zeros(0), ""
    sign = np.sign(parts[larger, np.arange(size.shape[1])])[out]
    worst = int(np.argmax(np.where(out, peak, -1.0)))
    count = int(out.sum())
    words = (f"{count} point{'s' if count != 1 else ''} beyond ±{limit:.3g}σ (▲▼), "
             f"up to {peak[worst]:.3g}σ at {freqs[worst]:.3g} Hz")
    return np.asarray(freqs)[out], sign, words


class TransferPlot(StillScene, pg.GraphicsLayoutWidget):
    """Magnitude, phase and normalised residual of one transfer function, x axes linked."""

    def __init__(self, magnitude_label: str, display_scale: float, log_y: bool, parent=None):
        super().__init__(parent=parent)
        self.display_scale = display_scale
        self.log_y = log_y
        self.magnitude = self.addPlot(row=0, col=0, axisItems={"bottom": LogFrequencyAxis("bottom")})
        self.phase = self.addPlot(row=1, col=0, axisItems={"bottom": LogFrequencyAxis("bottom")})
        self.residual = self.addPlot(row=2, col=0, axisItems={"bottom": LogFrequencyAxis("bottom")})
        style_plot(self.magnitude, magnitude_label, log_y)
        style_plot(self.phase, "phase (deg)")
        style_plot(self.residual, "residual (σ)", bottom="frequency (Hz)")
        for plot in (self.phase, self.residual):
            plot.setXLink(self.magnitude)
        layout = self.ci.layout
        for row, stretch in enumerate((5, 3, 2)):
            layout.setRowStretchFactor(row, stretch)

        self.magnitude.addLegend(offset=(-10, 10))
        self.magnitude_error = _error_item()
        self.magnitude_measured = _measured_item()
        self.magnitude_model = _model_item()
        for item in (self.magnitude_error, self.magnitude_measured, self.magnitude_model):
            self.magnitude.addItem(item)
        self.phase_error = _error_item()
        self.phase_measured = _measured_item()
        self.phase_model = _model_item()
        for item in (self.phase_error, self.phase_measured, self.phase_model):
            self.phase.addItem(item)

        _guides(self.residual)
        self.residual_real = pg.PlotDataItem(pen=None, symbol="o", symbolSize=4, symbolPen=None,
                                             symbolBrush=pg.mkBrush(style.RESIDUAL_REAL), name="real")
        self.residual_imag = pg.PlotDataItem(pen=None, symbol="t", symbolSize=5, symbolPen=None,
                                             symbolBrush=pg.mkBrush(style.RESIDUAL_IMAG), name="imag")
        self.residual.addItem(self.residual_real)
        self.residual.addItem(self.residual_imag)
        # Points beyond the strip's range, pinned at its edge: an up triangle above, a down one below.
        self.residual_beyond_up = pg.PlotDataItem(pen=None, symbol="t1", symbolSize=8, symbolPen=None,
                                                  symbolBrush=pg.mkBrush(style.RESIDUAL_BEYOND))
        self.residual_beyond_down = pg.PlotDataItem(pen=None, symbol="t", symbolSize=8, symbolPen=None,
                                                    symbolBrush=pg.mkBrush(style.RESIDUAL_BEYOND))
        self.residual.addItem(self.residual_beyond_up)
        self.residual.addItem(self.residual_beyond_down)
        self.beyond_text = ""
        self.placeholder = PlotPlaceholder(self, NO_CURVES)
        # Imported curves: the exporting tool's fitted curve, in the plot (and its legend) only while it is drawn.
        self.magnitude_reference: pg.PlotDataItem | None = None

    def set_curves(self, curves, title: str) -> None:
        """Draw an app.results.curves.ChannelCurves."""
        k = self.display_scale
        self.placeholder.hide()
        self.magnitude.setTitle(title)
        magnitude = np.abs(curves.measured) * k
        self.magnitude_measured.setData(curves.freqs, magnitude)
        self.magnitude_model.setData(curves.dense_freqs, np.abs(curves.dense_model) * k)
        set_error_bars(self.magnitude_error, curves.freqs, magnitude, np.abs(curves.std) * k, self.log_y)

        self.clear_reference()
        # Magnitude-only curves (an LPM export): no measured phase to draw, one residual per line (the magnitude's).
        has_phase = getattr(curves, "has_phase", True)
        phase = curves.measured_phase_deg()
        shown = slice(None) if has_phase else slice(0, 0)
        self.phase_measured.setData(curves.freqs[shown], phase[shown])
        self.phase_model.setData(curves.dense_freqs, curves.dense_phase_deg())
        self.phase.setTitle(None if has_phase else "the model's phase only: the curves have no phase", size="9pt")
        set_error_bars(self.phase_error, curves.freqs[shown], phase[shown], curves.phase_std_deg()[shown])

        res = curves.residual
        self.residual_real.setData(curves.freqs, res.real)
        self.residual_imag.setData(curves.freqs[shown], np.imag(res)[shown])
        limit = self._residual_range(res)
        freqs, sign, self.beyond_text = beyond_range(curves.freqs, res, limit)
        self.residual_beyond_up.setData(freqs[sign > 0], np.full(int((sign > 0).sum()), EDGE * limit))
        self.residual_beyond_down.setData(freqs[sign < 0], np.full(int((sign < 0).sum()), -EDGE * limit))
        beyond = (f"; <span style='color:{style.RESIDUAL_BEYOND}'>{self.beyond_text}</span>"
                  if self.beyond_text else "")
        # In the title rather than a legend: a legend would cover the points of the thin strip.
        self.residual.setTitle(
            f"residual (model − measured)/σ: " + (
                f"<span style='color:{style.RESIDUAL_REAL}'>● real</span>"
                f" <span style='color:{style.RESIDUAL_IMAG}'>▼ imaginary</span>" if has_phase else
                f"<span style='color:{style.RESIDUAL_REAL}'>● magnitude</span>") + "; reduced χ² = "
            f"{curves.chi2_red:.3g}{beyond}", size="9pt")
        self.magnitude.enableAutoRange()
        self.phase.enableAutoRange(axis="y")

    def set_reference(self, freqs: np.ndarray, magnitude: np.ndarray, name: str) -> None:
        """Another tool's fitted |value| (SI) as a third, dashed line beside the measured points and linpar's model."""
        self.clear_reference()
        self.magnitude_reference = pg.PlotDataItem(freqs, np.asarray(magnitude) * self.display_scale,
                                                   pen=style.reference_pen(), name=name)
        self.magnitude.addItem(self.magnitude_reference)

    def clear_reference(self) -> None:
        if self.magnitude_reference is not None:
            self.magnitude.removeItem(self.magnitude_reference)     # and from the legend
            self.magnitude_reference = None

    def _residual_range(self, res: np.ndarray) -> float:
        parts = np.abs(np.concatenate([res.real, res.imag]))
        parts = parts[np.isfinite(parts)]
        peak = float(np.percentile(parts, 99)) * 1.15 if parts.size else 0.0
        limit = min(max(RESIDUAL_MIN_RANGE, peak), RESIDUAL_MAX_RANGE)
        self.residual.setYRange(-limit, limit, padding=0)
        return limit

    def clear_curves(self) -> None:
        self.clear_reference()
        for item in (self.magnitude_measured, self.magnitude_model, self.phase_measured, self.phase_model,
                     self.residual_real, self.residual_imag, self.residual_beyond_up, self.residual_beyond_down):
            item.setData([], [])
        self.beyond_text = ""
        for item in (self.magnitude_error, self.phase_error):
            item.setData(x=np.zeros(0), y=np.zeros(0), top=np.zeros(0), bottom=np.zeros(0))
        self.placeholder.show_text(NO_CURVES)


class SplPlot(StillScene, pg.GraphicsLayoutWidget):
    """Predicted SPL: from the measured Hx lines (points) and from the model (line)."""

    def __init__(self, parent=None):
        super().__init__(parent=parent)
        self.plot = self.addPlot(row=0, col=0, axisItems={"bottom": LogFrequencyAxis("bottom")})
        style_plot(self.plot, "SPL (dB SPL)", bottom="frequency (Hz)")
        self.plot.addLegend(offset=(-10, -10))      # bottom right: the SPL curve runs along the top
        self.error = _error_item()
        self.measured = _measured_item("from measured Hx")
        self.model = _model_item("from the model")
        for item in (self.error, self.measured, self.model):
            self.plot.addItem(item)

    def set_spl(self, freqs, spl_measured, spl_err, dense_freqs, spl_model, title: str) -> None:
        self.plot.setTitle(title)
        self.measured.setData(freqs, spl_measured)
        self.model.setData(dense_freqs, spl_model)
        set_error_bars(self.error, freqs, spl_measured, spl_err)
        self.plot.enableAutoRange()

    def clear_curves(self) -> None:
        self.measured.setData([], [])
        self.model.setData([], [])
        self.error.setData(x=np.zeros(0), y=np.zeros(0), top=np.zeros(0), bottom=np.zeros(0))
