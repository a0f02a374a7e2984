"""What a broken measurement still measured: each valid channel's spectrum at the excited lines, and Hx where
voltage and displacement both are valid.

A broken current lead leaves nothing to fit (no impedance), yet the voltage and the laser's displacement were
read: the Results page draws them here instead of an empty plot, so that the user sees the drive arrived and the
cone moved, and that only the lead named red is missing.
"""
from __future__ import annotations

import numpy as np
import pyqtgraph as pg

from app.widgets import style
from app.widgets.plots import LogFrequencyAxis, style_plot
from app.widgets.still_scene import StillScene

# channel -> (what is plotted, display scale from SI): displacement in mm, as everywhere in the GUI.
CHANNEL_AXES = {"voltage": ("voltage (V)", 1.0), "current": ("current (A)", 1.0),
                "displacement": ("displacement (mm)", 1e3)}
NOISE = "#9e9e9e"


def valid_channels(result) -> list[str]:
    """The recording's channels the validity did not mark red, in CHANNEL_AXES's order."""
    judged = result.validity.channels
    return [name for name in CHANNEL_AXES if name in result.spectra.channels
            and (name not in judged or judged[name].status != "red")]


def broken_channels(result) -> list[str]:
    return [name for name, channel in result.validity.channels.items() if channel.status == "red"]


class MeasuredSpectraView(StillScene, pg.GraphicsLayoutWidget):
    """One plot per valid channel (amplitude and noise floor at the excited lines), then |Hx| if it was
    measured; frequency axes linked."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setBackground("w")
        self.shown: list[str] = []          # the plots drawn, by name ("voltage", ..., "Hx")

    def show_result(self, result) -> None:
        self.clear()
        self.shown = []
        s = result.spectra
        bins = s.excited_bins
        freqs = s.freqs[bins]
        channels = valid_channels(result)
        rows = [(name, *CHANNEL_AXES[name], s.channels[name].amplitude[bins], s.channels[name].noise_floor[bins])
                for name in channels]
        if s.displacement is not None and {"voltage", "displacement"} <= set(channels):
            hx = s.displacement
            rows.append(("Hx", "|Hx| (mm/V)", 1e3, np.abs(hx.value), np.nan_to_num(hx.std, nan=0.0)))
            hx_freqs = hx.freqs
        else:
            hx_freqs = freqs
        first = None
        for row, (name, label, scale, amplitude, noise) in enumerate(rows):
            plot = self.addPlot(row=row, col=0, axisItems={"bottom": LogFrequencyAxis("bottom")})
            style_plot(plot, label, log_y=True, bottom="frequency (Hz)" if row == len(rows) - 1 else None)
            plot.getAxis("left").enableAutoSIPrefix(False)      # "voltage (V) (x0.001)" over 10¹ read as 10 V
            x = hx_freqs if name == "Hx" else freqs
            positive = amplitude > 0
            plot.plot(x[positive], amplitude[positive] * scale, pen=None, symbol="o",
                      symbolSize=style.MEASURED_SYMBOL_SIZE, symbolBrush=style.measured_brush(), symbolPen=None)
            floor = noise > 0
            if floor.any():
                plot.plot(x[floor], noise[floor] * scale, pen=pg.mkPen(NOISE, width=1))
            if first is None:
                first = plot
                broken = ", ".join(broken_channels(result)) or "a channel"
                plot.setTitle(f"Measured (nothing fitted: {broken} red): each valid channel at the excited lines, "
                              "its noise floor in grey")
            else:
                plot.setXLink(first)
            self.shown.append(name)
