"""Step 3: a reference resistor in place of the driver; the current channel's gain and delay corrections."""
from __future__ import annotations

import html
import json

import numpy as np
import pyqtgraph as pg
from PySide6.QtWidgets import (QCheckBox, QDoubleSpinBox, QFormLayout, QGroupBox, QHBoxLayout, QPushButton,
                               QVBoxLayout)

from app.widgets import style
from app.widgets.grid_axis import show_grid
from app.widgets.plots import LEFT_AXIS_WIDTH, LogFrequencyAxis
from app.jobs.controls import JobControls
from app.wizard.base import ERROR_COLOUR, OK_COLOUR, WizardPage, coloured, rich_label
from app.wizard.calibration import Corrections, CorrectionsError
from app.wizard.hardware import RIG, SIMULATOR

SETTINGS_PREFIX = "measure/calibration/"
# The smallest half-range of the plots: a good resistor shows flat, not its last digits blown up to fill the plot.
MAGNITUDE_SPAN_PERCENT = 1.0
PHASE_SPAN_DEG = 2.0


class ResistorPlot(pg.GraphicsLayoutWidget):
    def sizeHint(self):
        from PySide6.QtCore import QSize
        return QSize(500, 300)        # pyqtgraph asks for 640 x 480, which would set the page's height


def settings_key(hardware_key: str) -> str:
    return SETTINGS_PREFIX + hardware_key.replace("/", "_").replace("\\", "_")


class CalibrationPage(WizardPage):
    title = "Calibration"
    subtitle = ("A reference resistor in place of the driver: |Z| must equal R and the phase be zero. What the "
                "chain makes of it instead becomes a gain and a delay correction of the current channel.")

    def __init__(self, state, session, parent=None):
        super().__init__(state, session, parent)
        self.check = None                         # the last ResistorCheck
        self.stored: Corrections | None = None
        self.intro = rich_label()
        self.resistor = QDoubleSpinBox()
        self.resistor.setRange(0.1, 1000.0)
        self.resistor.setDecimals(3)
        self.resistor.setValue(10.0)
        self.resistor.setSuffix(" Ω")
        self.resistor.setToolTip("The resistor's measured value (a four-wire ohmmeter), not its printed one")
        self.level = QDoubleSpinBox()
        self.level.setRange(0.01, 10.0)
        self.level.setValue(1.0)
        self.level.setSuffix(" V rms")
        self.measure_button = QPushButton("Measure the resistor")
        self.jobs = JobControls(session)
        self.result = rich_label(selectable=True)
        self.stored_label = rich_label(selectable=True)
        self.without = QCheckBox("Continue without corrections (the constants of the Hardware page as they are)")

        self.plot = ResistorPlot()
        self.plot.setMinimumHeight(260)
        self.magnitude = self.plot.addPlot(row=0, col=0, axisItems={"bottom": LogFrequencyAxis("bottom")})
        self.phase = self.plot.addPlot(row=1, col=0, axisItems={"bottom": LogFrequencyAxis("bottom")})
        for plot, label in ((self.magnitude, "|Z| / R − 1 (%)"), (self.phase, "phase (deg)")):
            plot.setLogMode(x=True, y=False)
            show_grid(plot)
            plot.setLabel("left", label)
            plot.getAxis("left").setWidth(LEFT_AXIS_WIDTH)
            plot.getAxis("left").enableAutoSIPrefix(False)     # "(%) (x0.001)" reads as nonsense
            plot.setMenuEnabled(False)
        self.phase.setLabel("bottom", "frequency (Hz)")
        self.phase.setXLink(self.magnitude)
        self.magnitude.setTitle("The reference resistor as measured (before the corrections)", size="9pt")
        self.magnitude_item = pg.PlotDataItem(pen=None, symbol="o", symbolSize=4, symbolPen=None,
                                              symbolBrush=style.measured_brush())
        self.phase_item = pg.PlotDataItem(pen=None, symbol="o", symbolSize=4, symbolPen=None,
                                          symbolBrush=style.measured_brush())
        self.delay_item = pg.PlotDataItem(pen=style.model_pen())
        self.magnitude.addItem(self.magnitude_item)
        self.phase.addItem(self.phase_item)
        self.phase.addItem(self.delay_item)

        form = QFormLayout()
        form.addRow("Reference resistor", self.resistor)
        form.addRow("Level", self.level)
        run = QHBoxLayout()
        run.addWidget(self.measure_button)
        run.addWidget(self.jobs, 1)
        box = QGroupBox("Corrections")
        box_layout = QVBoxLayout(box)
        box_layout.addWidget(self.stored_label)
        box_layout.addWidget(self.without)
        left = QVBoxLayout()
        left.addWidget(self.intro)
        left.addLayout(form)
        left.addLayout(run)
        left.addWidget(self.result)
        left.addWidget(box)
        left.addStretch(1)
        layout = QHBoxLayout(self)
        layout.addLayout(left, 2)
        layout.addWidget(self.plot, 3)

        self.measure_button.clicked.connect(self.on_measure)
        self.without.toggled.connect(self.changed)
        self.jobs.busy_changed.connect(self.on_busy_changed)

    # -- page ---------------------------------------------------------------------
    def enter(self) -> None:
        hw = self.state.hardware
        driver = self.state.driver
        if driver is not None and driver.nominal_impedance_ohm and self.check is None:
            self.resistor.setValue(driver.nominal_impedance_ohm)
        if hw.kind == RIG:
            self.intro.setText("The JACK virtual rig simulates the driver, not a resistor, and its chain follows "
                               "its calibration exactly: no correction is needed, and none can be measured on it.")
        elif hw.kind == SIMULATOR:
            self.intro.setText("On the in-process simulator a simulated resistor takes the driver's place "
                               "(a driver model that is a pure resistance R).")
        else:
            self.intro.setText("Put the reference resistor in place of the driver (non-inductive, its value "
                               "known to 0.1 %), then measure it. Put the driver back before the next step.")
        self.measure_button.setEnabled(hw.kind != RIG and not self.busy)
        self.resistor.setEnabled(hw.kind != RIG)
        self.level.setEnabled(hw.kind != RIG)
        self.without.setVisible(hw.kind != RIG)
        self._load_stored()
        self.changed.emit()

    def corrections(self) -> Corrections | None:
        if self.state.hardware.kind == RIG:
            return Corrections(source="exact", hardware=self.state.hardware.key())
        if self.stored is not None:
            return self.stored
        if self.without.isChecked():
            return Corrections(hardware=self.state.hardware.key())
        return None

    def missing(self) -> str | None:
        if self.jobs.busy:
            return "Wait for the resistor's measurement to finish, or cancel it."
        if self.corrections() is None:
            return ("Measure the reference resistor (no corrections are stored for this hardware), or tick "
                    "'Continue without corrections'.")
        return None

    @property
    def busy(self) -> bool:
        return self.jobs.busy

    def commit(self) -> None:
        self.state.corrections = self.corrections()

    # -- stored corrections -------------------------------------------------------------
    def _load_stored(self) -> None:
        key = settings_key(self.state.hardware.key())
        self.stored = None
        try:
            text = self.state.settings.value(key, "")
            if text:
                self.stored = Corrections.from_dict(json.loads(text))
        except (TypeError, json.JSONDecodeError, CorrectionsError):      # settings another version wrote
            self.stored = None
        self._show_stored()

    def _show_stored(self) -> None:
        corrections = self.corrections()
        if self.state.hardware.kind == RIG:
            text = "Corrections: " + corrections.describe()
        elif self.stored is not None:
            text = f"In use, stored for {html.escape(self.state.hardware.describe())}: " \
                   f"<b>{html.escape(self.stored.describe())}</b>"
        else:
            text = "No corrections stored for this hardware yet."
        self.stored_label.setText(text)

    # -- measuring --------------------------------------------------------------------
    def on_measure(self) -> None:
        self.result.setText("")
        job = self.session.calibrate(self.state.hardware, self.resistor.value(), self.level.value())
        self.jobs.run(job, "Measuring the reference resistor…", self.on_checked,
                      lambda message: self.result.setText(coloured("Failed: " + message, ERROR_COLOUR)),
                      lambda: self.result.setText("Calibration cancelled: nothing stored."))

    def on_checked(self, check) -> None:
        self.check = check
        z = check.impedance
        self.magnitude_item.setData(check.freqs, (np.abs(z) / check.resistor_ohm - 1.0) * 100.0)
        self.phase_item.setData(check.freqs, np.degrees(np.unwrap(np.angle(z))))
        delay = check.corrections.current_delay_s
        self.delay_item.setData(check.freqs, np.degrees(2 * np.pi * check.freqs * delay))
        for plot, values, span in ((self.magnitude, (np.abs(z) / check.resistor_ohm - 1.0) * 100.0,
                                    MAGNITUDE_SPAN_PERCENT),
                                   (self.phase, np.degrees(np.unwrap(np.angle(z))), PHASE_SPAN_DEG)):
            centre = float(np.median(values))
            half = max(span, float(np.max(np.abs(values - centre))) * 1.1)
            plot.setYRange(centre - half, centre + half, padding=0)
        self.magnitude.enableAutoRange(axis="x")
        summary = html.escape(check.summary())
        if check.ok:
            self.state.settings.setValue(settings_key(self.state.hardware.key()),
                                         json.dumps(check.corrections.to_dict()))
            self.result.setText(coloured("Resistor OK. ", OK_COLOUR) + summary + "<br>Computed and stored: <b>"
                                + html.escape(check.corrections.describe()) + "</b>")
            self._load_stored()
        else:
            problems = "<br>".join(coloured(p, ERROR_COLOUR) for p in check.problems)
            self.result.setText(f"{summary}<br>{problems}<br>Nothing stored.")
        self.changed.emit()

    def on_busy_changed(self, busy: bool) -> None:
        self.measure_button.setEnabled(not busy and self.state.hardware.kind != RIG)
        self.changed.emit()
