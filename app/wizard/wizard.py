"""The measurement wizard: Driver -> Hardware -> Calibration -> Level -> Measure -> Results.

A stepped page rather than a QWizard: it lives in a tab of the main window
(QWizard is a dialog with a look of its own per platform), and each step must
say in words why Next is not possible yet, which QWizard has no place for.
Each page reports `missing()`; the bar under the pages shows it and keeps
Next disabled until it is None.
"""
from __future__ import annotations

import dataclasses

from PySide6.QtCore import QSettings, Qt, Signal
from PySide6.QtWidgets import (QFrame, QHBoxLayout, QLabel, QListWidget, QListWidgetItem, QPushButton,
                               QScrollArea, QStackedWidget, QVBoxLayout, QWidget)

from app.wizard.measure_session import MeasureSession
from app.wizard.base import ERROR_COLOUR, WizardPage, WizardState
from app.wizard.calibration_page import CalibrationPage
from app.wizard.driver_page import DriverPage
from app.wizard.hardware_page import HardwarePage
from app.wizard.level_page import LevelPage
from app.wizard.measure_page import MeasurePage
from app.wizard.results_page import ResultsPage
from instruments.rig.state import DEFAULT_NAME


class MeasureWizard(QWidget):
    measurement_finished = Signal(object)        # app.wizard.measure_session.MeasureOutcome
    large_signal_finished = Signal(object)       # app.wizard.tasks.LargeSignalMeasured (with a result)
    open_results_requested = Signal(object)      # app.jobs.workers.AnalysisOutcome

    def __init__(self, settings: QSettings, session: MeasureSession | None = None, parent=None, *,
                 rig_name: str = DEFAULT_NAME, rig_runtime_dir: str | None = None):
        super().__init__(parent)
        self.session = session or MeasureSession(self)
        self.state = WizardState(settings)
        self.driver_page = DriverPage(self.state, self.session)
        self.hardware_page = HardwarePage(self.state, self.session, rig_name=rig_name,
                                          rig_runtime_dir=rig_runtime_dir)
        self.calibration_page = CalibrationPage(self.state, self.session)
        self.level_page = LevelPage(self.state, self.session)
        self.measure_page = MeasurePage(self.state, self.session)
        self.results_page = ResultsPage(self.state, self.session)
        self.pages: list[WizardPage] = [self.driver_page, self.hardware_page, self.calibration_page,
                                        self.level_page, self.measure_page, self.results_page]

        self.steps = QListWidget()
        self.steps.setFocusPolicy(Qt.NoFocus)
        self.steps.setSelectionMode(QListWidget.NoSelection)
        self.steps.setFixedWidth(150)
        self.steps.setFrameShape(QFrame.NoFrame)
        for number, page in enumerate(self.pages, start=1):
            self.steps.addItem(QListWidgetItem(f"{number}. {page.title}"))
        self.title = QLabel()
        self.title.setTextFormat(Qt.RichText)
        self.subtitle = QLabel()
        self.subtitle.setWordWrap(True)
        self.stack = QStackedWidget()
        for page in self.pages:
            # Scrolled, so that no page sets the window's minimum size (the live panels are tall).
            scroll = QScrollArea()
            scroll.setWidgetResizable(True)
            scroll.setFrameShape(QFrame.NoFrame)
            scroll.setWidget(page)
            self.stack.addWidget(scroll)
            page.changed.connect(self.update_navigation)
        self.reason = QLabel()
        self.reason.setWordWrap(True)
        self.reason.setStyleSheet(f"QLabel {{ color: {ERROR_COLOUR}; }}")
        self.back_button = QPushButton("< Back")
        self.next_button = QPushButton("Next >")
        self.next_button.setDefault(True)
        self._build_layout()

        self.back_button.clicked.connect(self.on_back)
        self.next_button.clicked.connect(self.on_next)
        self.measure_page.measured.connect(self.measurement_finished)
        self.measure_page.large_signal_measured.connect(self.large_signal_finished)
        self.results_page.open_requested.connect(self.open_results_requested)
        self.results_page.again_requested.connect(self.on_again)
        self.go_to(0)

    def _build_layout(self) -> None:
        bar = QHBoxLayout()
        bar.addWidget(self.reason, 1)
        bar.addWidget(self.back_button)
        bar.addWidget(self.next_button)
        line = QFrame()
        line.setFrameShape(QFrame.HLine)
        line.setFrameShadow(QFrame.Sunken)
        main = QVBoxLayout()
        main.addWidget(self.title)
        main.addWidget(self.subtitle)
        main.addWidget(self.stack, 1)
        main.addWidget(line)
        main.addLayout(bar)
        layout = QHBoxLayout(self)
        layout.addWidget(self.steps)
        layout.addLayout(main, 1)

    @property
    def current(self) -> WizardPage:
        return self.pages[self.stack.currentIndex()]

    @property
    def index(self) -> int:
        return self.stack.currentIndex()

    def go_to(self, index: int) -> None:
        page = self.pages[index]
        self.stack.setCurrentIndex(index)
        self.title.setText(f"<h2>{index + 1}. {page.title}</h2>")
        self.subtitle.setText(page.subtitle)
        page.enter()
        self.update_navigation()

    def update_navigation(self) -> None:
        page, index = self.current, self.index
        last = index == len(self.pages) - 1
        missing = page.missing()
        self.next_button.setVisible(not last)
        self.next_button.setEnabled(not last and missing is None and not page.busy)
        self.back_button.setEnabled(index > 0 and not page.busy)
        self.reason.setText("" if last or missing is None else missing)
        for row in range(self.steps.count()):
            item = self.steps.item(row)
            font = item.font()
            font.setBold(row == index)
            item.setFont(font)
            item.setForeground(Qt.black if row <= index else Qt.gray)

    def on_next(self) -> None:
        page = self.current
        if page.busy or page.missing() is not None or self.index >= len(self.pages) - 1:
            return
        page.commit()
        self.go_to(self.index + 1)

    def on_back(self) -> None:
        if self.index > 0 and not self.current.busy:
            self.go_to(self.index - 1)

    def on_again(self) -> None:
        """The next driver of a batch: same hardware, calibration and class; a new name or serial."""
        self.state.outcome = None
        self.driver_page.serial_edit.clear()
        self.driver_page.serial_edit.setFocus()
        self.go_to(0)

    def model_part_arrived(self, analysis) -> None:
        """The measurement's analysis (app.jobs.workers.AnalysisOutcome) again, its uncertainties with their model part
        (estimated in the background after the statistical result): the Results step shows it too."""
        outcome = self.state.outcome
        if outcome is None or outcome.analysis.result.fit is not analysis.result.fit:
            return          # another measurement since: not this one's
        self.state.outcome = dataclasses.replace(outcome, analysis=analysis)
        if self.current is self.results_page:
            self.results_page.enter()

    def shutdown(self, wait_ms: int) -> bool:
        return self.session.shutdown(wait_ms)
