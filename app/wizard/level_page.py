"""Step 4: the level check (analysis.level_check) with the live panels; the chosen level and why."""
from __future__ import annotations

import html

from PySide6.QtWidgets import (QAbstractItemView, QCheckBox, QDoubleSpinBox, QFormLayout, QHBoxLayout,
                               QHeaderView, QPushButton, QTableWidget, QTableWidgetItem, QVBoxLayout)

from app.live.panels import LivePanels
from app.jobs.controls import JobControls
from app.wizard.base import ERROR_COLOUR, OK_COLOUR, WizardPage, coloured, rich_label
from app.wizard.plans import TEMPLATES

PROBE_COLUMNS = ("Level\n(V rms)", "Weakest SNR\n(dB)", "Noise + distortion\nover the floor (dB)",
                 "Peak excursion\n(mm)")
REASON_WORDS = {"snr-reached": "enough signal", "distortion": "distortion limit", "excursion": "excursion limit",
                "max-voltage": "maximum voltage", "too-loud-at-min": "too loud even at the minimum",
                "max-probes": "undecided"}


def _spin(maximum: float, suffix: str, decimals: int = 3) -> QDoubleSpinBox:
    spin = QDoubleSpinBox()
    spin.setDecimals(decimals)
    spin.setRange(10.0 ** -decimals, maximum)
    spin.setSuffix(suffix)
    return spin


class LevelPage(WizardPage):
    title = "Level"
    subtitle = ("The level is raised from a safe minimum until every channel has enough signal, and stops "
                "before the driver leaves its linear range or the excursion passes its limit.")

    def __init__(self, state, session, parent=None):
        super().__init__(state, session, parent)
        self.decision = None
        self._template_key = None
        self.v_min = _spin(10.0, " V rms")
        self.v_max = _spin(50.0, " V rms")
        self.x_limit = _spin(10.0, " mm")
        self.run_button = QPushButton("Run the level check")
        self.jobs = JobControls(session)
        self.probes = QTableWidget(0, len(PROBE_COLUMNS))
        self.probes.setHorizontalHeaderLabels(PROBE_COLUMNS)
        self.probes.verticalHeader().setVisible(False)
        self.probes.setEditTriggers(QAbstractItemView.NoEditTriggers)
        self.probes.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeToContents)
        self.probes.horizontalHeader().setStretchLastSection(True)
        self.probes.setMinimumHeight(70)
        self.decision_label = rich_label(selectable=True)
        self.manual = QCheckBox("Measure at a level of my own instead:")
        self.manual_level = _spin(50.0, " V rms")
        self.manual_level.setValue(0.5)
        self.panels = LivePanels("No data yet: start the level check.")

        form = QFormLayout()
        form.addRow("Start at", self.v_min)
        form.addRow("Never above", self.v_max)
        form.addRow("Peak excursion limit", self.x_limit)
        run = QHBoxLayout()
        run.addWidget(self.run_button)
        run.addWidget(self.jobs, 1)
        manual = QHBoxLayout()
        manual.addWidget(self.manual)
        manual.addWidget(self.manual_level)
        manual.addStretch(1)
        left = QVBoxLayout()
        left.addLayout(form)
        left.addLayout(run)
        left.addWidget(self.probes, 1)
        left.addWidget(self.decision_label)
        left.addLayout(manual)
        layout = QHBoxLayout(self)
        layout.addLayout(left, 2)
        layout.addWidget(self.panels, 3)

        self.run_button.clicked.connect(self.on_run)
        self.manual.toggled.connect(self.changed)
        self.manual_level.valueChanged.connect(self.changed)
        self.jobs.busy_changed.connect(self.on_busy_changed)

    def enter(self) -> None:
        key = self.state.driver.template if self.state.driver else "woofer"
        if key != self._template_key:          # a new class: its limits, and any decision is void
            self._template_key = key
            t = TEMPLATES[key]
            self.v_min.setValue(t.v_min)
            self.v_max.setValue(t.v_max)
            self.x_limit.setValue(t.x_limit_m * 1e3)
            self.decision = None
            self.decision_label.setText("")
            self.probes.setRowCount(0)
        self.changed.emit()

    def level(self) -> tuple[float, str, str] | None:
        """(V rms, why, why in a few words), or None while there is no level."""
        if self.manual.isChecked():
            return self.manual_level.value(), "chosen by hand on the Level page", "chosen by hand"
        if self.decision is not None and self.decision.level is not None:
            d = self.decision
            return d.level, d.reason, REASON_WORDS.get(d.reason_code, d.reason_code)
        return None

    def missing(self) -> str | None:
        if self.jobs.busy:
            return "Wait for the level check to finish, or cancel it."
        if self.level() is None:
            if self.decision is not None:
                return "The level check found no usable level: lower the start level, or set one by hand."
            return "Run the level check (or tick 'a level of my own')."
        return None

    @property
    def busy(self) -> bool:
        return self.jobs.busy

    def commit(self) -> None:
        self.state.level_v, self.state.level_reason, self.state.level_words = self.level()

    def on_run(self) -> None:
        if self.v_min.value() > self.v_max.value():
            self.decision_label.setText(coloured("The start level must not exceed the maximum.", ERROR_COLOUR))
            return
        self.decision = None
        self.probes.setRowCount(0)
        self.decision_label.setText("")
        template = TEMPLATES[self._template_key or "woofer"]
        self.panels.clear(band_hz=template.band_hz)
        job = self.session.check_level(self.state.hardware, template, self.state.corrections,
                                       self.v_min.value(), self.v_max.value(), self.x_limit.value() * 1e-3)
        self.jobs.run(job, "Level check…", self.on_decided,
                      lambda message: self.decision_label.setText(coloured("Failed: " + message, ERROR_COLOUR)),
                      lambda: self.decision_label.setText("Level check cancelled."),
                      frame=self.panels.set_frame)
        self.changed.emit()

    def on_decided(self, decision) -> None:
        self.decision = decision
        self.probes.setRowCount(len(decision.probes))
        for row, p in enumerate(decision.probes):
            peak = "–" if p.peak_displacement_m is None else f"{p.peak_displacement_m * 1e3:.3f}"
            cells = (f"{p.level:.4g}", f"{p.snr_db:.1f} ({p.snr_channel})",
                     f"{p.distortion_db:.1f} ({p.distortion_channel})", peak)
            for col, text in enumerate(cells):
                self.probes.setItem(row, col, QTableWidgetItem(text))
        words = REASON_WORDS.get(decision.reason_code, decision.reason_code)
        if decision.level is None:
            self.decision_label.setText(coloured(f"No usable level ({words}): ", ERROR_COLOUR)
                                        + html.escape(decision.reason))
        else:
            self.decision_label.setText(coloured(f"Chosen: {decision.level:.4g} V rms ({words}). ", OK_COLOUR)
                                        + "Why: " + html.escape(decision.reason))
        self.changed.emit()

    def on_busy_changed(self, busy: bool) -> None:
        self.run_button.setEnabled(not busy)
        for spin in (self.v_min, self.v_max, self.x_limit):
            spin.setEnabled(not busy)
        self.changed.emit()
