"""Step 5: the measurement: what will be done, progress, the live panels, cancel."""
from __future__ import annotations

import html
import threading
from pathlib import Path

from PySide6.QtCore import QStandardPaths, Signal
from PySide6.QtWidgets import QDoubleSpinBox, QFileDialog, QHBoxLayout, QLabel, QPushButton, QVBoxLayout, QWidget

from app.live.panels import LivePanels
from app.jobs.controls import JobControls
from app.wizard.base import ERROR_COLOUR, OK_COLOUR, WizardPage, coloured, rich_label
from app.wizard.plans import LARGE_SIGNAL, TEMPLATES
from app.wizard.tasks import MeasurementRequest

OUT_DIR_KEY = "measure/out_dir"


def default_out_dir() -> Path:
    documents = QStandardPaths.writableLocation(QStandardPaths.DocumentsLocation) or str(Path.home())
    return Path(documents) / "linpar"


def _table(left: list[tuple[str, str]], right: list[tuple[str, str]]) -> str:
    """Two columns of name: value rows, so the summary leaves the height to the live panels."""
    def cells(rows, i):
        if i >= len(rows):
            return "<td></td><td></td>"
        name, value = rows[i]
        return f"<td><b>{html.escape(name)}</b>&nbsp;</td><td>{html.escape(value)}&nbsp;&nbsp;&nbsp;</td>"
    body = "".join(f"<tr>{cells(left, i)}{cells(right, i)}</tr>" for i in range(max(len(left), len(right))))
    return f"<table>{body}</table>"


class LargeSignalLimits(QWidget):
    """The large-signal plan's limits the user sets here (the others keep their defaults: -20 dB of current
    distortion, 20 K of coil heating)."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.excursion = _spin(0.1, 20.0, 4.0, " mm", "The plan stops once the peak excursion reaches this")
        self.voltage = _spin(0.1, 100.0, 10.0, " V rms", "The plan never drives above this level")
        row = QHBoxLayout(self)
        row.setContentsMargins(0, 0, 0, 0)
        for text, box in (("Large-signal plan: stop at", self.excursion), ("or", self.voltage)):
            row.addWidget(QLabel(text))
            row.addWidget(box)
        row.addStretch(1)

    def limits(self):
        from analysis.large_signal.stepping import StepLimits
        return StepLimits(max_excursion_m=self.excursion.value() * 1e-3, max_voltage_v=self.voltage.value())


def _spin(low: float, high: float, value: float, suffix: str, tip: str) -> QDoubleSpinBox:
    box = QDoubleSpinBox()
    box.setRange(low, high)
    box.setDecimals(1)
    box.setValue(value)
    box.setSuffix(suffix)
    box.setToolTip(tip)
    return box


class MeasurePage(WizardPage):
    title = "Measure"
    subtitle = "The recording is written first, then analysed; the spectra show each period as it is averaged."
    measured = Signal(object)           # MeasureOutcome
    large_signal_measured = Signal(object)      # app.wizard.tasks.LargeSignalMeasured

    def __init__(self, state, session, parent=None):
        super().__init__(state, session, parent)
        self.summary = rich_label(selectable=True)
        self.folder_button = QPushButton("Folder…")
        self.folder_button.setToolTip("Where the recording (NAME.wav and NAME.json) is written")
        self.start_button = QPushButton("Start the measurement")
        self.jobs = JobControls(session)
        self.result = rich_label(selectable=True)
        self.large_signal = LargeSignalLimits()
        self.large_signal.setVisible(False)
        self.large_signal_done = None           # the last large-signal plan's LargeSignalMeasured
        self.panels = LivePanels("No data yet: start the measurement.")
        top = QHBoxLayout()
        top.addWidget(self.summary, 1)
        top.addWidget(self.folder_button)
        run = QHBoxLayout()
        run.addWidget(self.start_button)
        run.addWidget(self.jobs, 1)
        layout = QVBoxLayout(self)
        layout.addLayout(top)
        layout.addLayout(run)
        layout.addWidget(self.large_signal)
        layout.addWidget(self.result)
        layout.addWidget(self.panels, 1)
        self.start_button.clicked.connect(self.on_start)
        self.folder_button.clicked.connect(self.on_folder)
        self.jobs.busy_changed.connect(self.on_busy_changed)

    def out_dir(self) -> Path:
        saved = self.state.settings.value(OUT_DIR_KEY, "")
        return Path(saved) if saved else default_out_dir()

    def request(self) -> MeasurementRequest:
        s = self.state
        limits = self.large_signal.limits() if self.is_large_signal() else None
        return MeasurementRequest(s.driver, s.hardware, TEMPLATES[s.driver.template], s.corrections, s.level_v,
                                  s.level_reason, self.out_dir(), limits)

    def is_large_signal(self) -> bool:
        return self.state.driver is not None and self.state.driver.template == LARGE_SIGNAL

    def enter(self) -> None:
        s = self.state
        if s.driver is None or s.level_v is None or s.corrections is None:
            self.summary.setText("")
            return
        if s.outcome is not None and s.outcome.request != self.request():
            s.outcome = None            # the steps before changed: that measurement is not this one
            self.result.setText("")
        t = TEMPLATES[s.driver.template]
        serial = f", serial {s.driver.serial}" if s.driver.serial else ""
        left = [("Driver", f"{s.driver.name}{serial} ({t.key})"), ("Hardware", s.hardware.describe()),
                ("Corrections", s.corrections.describe())]
        right = [("Level", f"{s.level_v:.4g} V rms ({s.level_words})"), ("Excitation", t.describe().split(";")[0]),
                 ("Recording to", str(self.out_dir()))]
        self.summary.setText(_table(left, right))
        self.large_signal.setVisible(self.is_large_signal())
        self.start_button.setText("Start the large-signal plan" if self.is_large_signal() else
                                  "Start the measurement")
        self.summary.setToolTip(f"Level: {s.level_reason}")
        self.changed.emit()

    def missing(self) -> str | None:
        if self.jobs.busy:
            return "Wait for the measurement to finish, or cancel it."
        if self.is_large_signal():
            done = self.large_signal_done
            if done is None:
                return "Start the large-signal plan."
            # Not "the curves are on the Large-signal page" when none were identified: the words above say why.
            return ("The curves are on the Large-signal page." if done.result is not None
                    else "No curves were identified (the reason is above): start the large-signal plan again.")
        if self.state.outcome is None:
            return "Start the measurement."
        return None

    @property
    def busy(self) -> bool:
        return self.jobs.busy

    def on_folder(self) -> None:
        folder = QFileDialog.getExistingDirectory(self, "Folder for the recordings", str(self.out_dir()))
        if folder:
            self.state.settings.setValue(OUT_DIR_KEY, folder)
            self.enter()

    def on_start(self) -> None:
        if self.is_large_signal():
            self.start_large_signal()
            return
        self.state.outcome = None
        self._run(self.session.measure, self.on_measured, "Measurement cancelled: nothing analysed.")

    def on_measured(self, outcome) -> None:
        self.state.outcome = outcome
        overall = outcome.analysis.result.validity.overall
        self.result.setText(coloured(f"Written {outcome.path} and analysed (validity {overall}). ", OK_COLOUR)
                            + "Next shows the parameters.")
        self.measured.emit(outcome)
        self.changed.emit()

    def start_large_signal(self) -> None:
        self.large_signal_done = None
        self._run(self.session.measure_large_signal, self.on_large_signal,
                  "Large-signal plan cancelled: its steps so far are kept.")

    def _run(self, start_job, on_done, cancelled_text: str) -> None:
        """A measurement job of the session (start_job(request)), its frames on the live panels."""
        self.result.setText("")
        request = self.request()
        panels_drawn = threading.Event()            # the job begins once the emptied panels are drawn
        self.panels.clear(band_hz=request.template.band_hz, then=panels_drawn.set)
        self.jobs.run(start_job(request, panels_drawn), "Starting…", on_done,
                      lambda message: self.result.setText(coloured("Failed: " + message, ERROR_COLOUR)),
                      lambda: self.result.setText(cancelled_text), frame=self.panels.set_frame)
        self.changed.emit()

    def on_large_signal(self, done) -> None:
        self.large_signal_done = done
        plan = done.plan
        # Plain text: coloured() escapes it (escaped here too, a folder or a message with "&" read "&amp;").
        steps = f"{len(plan.steps)} step(s) recorded in {self.out_dir()}; stopped: {plan.message}. "
        # A complete step with words of its own was measured again at its level (its laser stream misplaced in
        # time): said here, as the CLI says it, or the user would count one step more than the levels shown.
        steps += "".join(f"Step {step.index} ({step.level_v:.3g} V): {step.message}. "
                         for step in plan.steps if step.message and not step.partial)
        if done.result is None:
            self.result.setText(coloured(steps + "Not identified: " + done.error, ERROR_COLOUR))
        else:
            self.result.setText(coloured(steps, OK_COLOUR) + "The curves are on the Large-signal page.")
            self.large_signal_measured.emit(done)
        self.changed.emit()

    def on_busy_changed(self, busy: bool) -> None:
        self.start_button.setEnabled(not busy)
        self.folder_button.setEnabled(not busy)
        self.changed.emit()
