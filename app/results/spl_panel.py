"""Predicted SPL from Hx, for a chosen drive voltage, distance and Sd.

Sd does not come out of the measurement: when the recording does not carry
it, the panel asks for it instead of drawing a curve for a made-up area.
"""
from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (QDoubleSpinBox, QFormLayout, QHBoxLayout, QLabel, QStackedWidget, QVBoxLayout,
                               QWidget)

from analysis.spl import predicted_spl
from app.widgets.plots import SplPlot

DEFAULT_VOLTAGE = 2.83      # V RMS: 1 W into 8 ohm, the customary sensitivity drive
DEFAULT_DISTANCE = 1.0      # m
CM2 = 1e-4                  # m^2 per cm^2
DB_PER_NEPER = 20.0 / np.log(10.0)


def _spin(minimum: float, maximum: float, value: float, decimals: int, suffix: str) -> QDoubleSpinBox:
    spin = QDoubleSpinBox()
    spin.setRange(minimum, maximum)
    spin.setDecimals(decimals)
    spin.setValue(value)
    spin.setSuffix(suffix)
    spin.setKeyboardTracking(False)     # recompute when the number is complete, not on each keystroke
    return spin


class SplPanel(QWidget):
    sd_changed = Signal(object)      # float (m^2) or None

    def __init__(self, parent=None):
        super().__init__(parent)
        self._curves = None          # ChannelCurves of the displacement, or None
        self.voltage = _spin(0.01, 200.0, DEFAULT_VOLTAGE, 2, " V")
        self.voltage.setToolTip("RMS drive voltage of the prediction")
        self.distance = _spin(0.01, 100.0, DEFAULT_DISTANCE, 2, " m")
        self.distance.setToolTip("listening distance (far field, half space)")
        self.sd = _spin(0.0, 20000.0, 0.0, 1, " cm²")
        self.sd.setSpecialValueText("not set")
        self.sd.setToolTip("Sd, the effective radiating area of the diaphragm (about π/4 · D² with D the "
                           "diameter measured to the middle of the surround)")

        form = QHBoxLayout()
        for label, spin in (("Voltage", self.voltage), ("Distance", self.distance), ("Sd", self.sd)):
            row = QFormLayout()
            row.addRow(label, spin)
            form.addLayout(row)
        form.addStretch(1)

        self.plot = SplPlot()
        self.message = QLabel()
        self.message.setAlignment(Qt.AlignCenter)
        self.message.setWordWrap(True)
        self.message.setMargin(24)
        self.stack = QStackedWidget()
        self.stack.addWidget(self.plot)
        self.stack.addWidget(self.message)

        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.stack, 1)

        self.voltage.valueChanged.connect(self._redraw)
        self.distance.valueChanged.connect(self._redraw)
        self.sd.valueChanged.connect(self.on_sd_edited)

    @property
    def sd_m2(self) -> float | None:
        value = self.sd.value()
        return value * CM2 if value > 0 else None

    def set_data(self, displacement_curves, sd_m2: float | None) -> None:
        """Show a new result; `sd_m2` from the recording (None when it does not say)."""
        self._curves = displacement_curves
        self.sd.blockSignals(True)      # a new recording's Sd is not a user edit
        self.sd.setValue(sd_m2 / CM2 if sd_m2 else 0.0)
        self.sd.blockSignals(False)
        self._redraw()

    def clear(self) -> None:
        self._curves = None
        self.plot.clear_curves()
        self._show_message("No recording loaded.")

    def on_sd_edited(self, _value: float) -> None:
        self._redraw()
        self.sd_changed.emit(self.sd_m2)

    def _show_message(self, text: str) -> None:
        self.message.setText(text)
        self.stack.setCurrentWidget(self.message)

    def _redraw(self, *_args) -> None:
        curves = self._curves
        if curves is None:
            self.plot.clear_curves()
            self._show_message("The SPL prediction needs the displacement transfer function Hx, and this "
                               "recording has no displacement channel. Measure with the laser to get it.")
            return
        sd = self.sd_m2
        if sd is None:
            self.plot.clear_curves()
            self._show_message("Enter Sd, the effective radiating area in cm², in the field above to predict "
                               "the SPL. The measurement does not give it.")
            return
        volts, metres = self.voltage.value(), self.distance.value()
        spl = predicted_spl(curves.freqs, curves.measured, sd, volts, metres)
        with np.errstate(divide="ignore", invalid="ignore"):
            err = DB_PER_NEPER * np.abs(curves.std) / np.abs(curves.measured)
        model = predicted_spl(curves.dense_freqs, curves.dense_model, sd, volts, metres)
        title = f"Predicted SPL at {volts:.3g} V, {metres:.3g} m, half space, Sd = {sd / CM2:.4g} cm²"
        self.plot.set_spl(curves.freqs, spl, err, curves.dense_freqs, model, title)
        self.stack.setCurrentWidget(self.plot)
