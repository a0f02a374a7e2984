"""Step 6: the parameters and the validity of the measurement just made; open them in the Results page."""
from __future__ import annotations

import html

from PySide6.QtCore import Signal
from PySide6.QtWidgets import QHBoxLayout, QPushButton, QVBoxLayout

from app.results.fit_quality import FitQualityBox
from app.results.parameter_table import titled_parameter_table
from app.widgets.traffic_light import ValiditySummary
from app.wizard.base import WizardPage, rich_label


class ResultsPage(WizardPage):
    title = "Results"
    subtitle = "The parameters of this measurement and whether it can be trusted, channel by channel."
    open_requested = Signal(object)          # app.jobs.workers.AnalysisOutcome
    again_requested = Signal()

    def __init__(self, state, session, parent=None):
        super().__init__(state, session, parent)
        self.source = rich_label(selectable=True)
        self.validity = ValiditySummary()
        self.fit_quality = FitQualityBox()
        table_box, self.table = titled_parameter_table("<b>Parameters</b> (bold: fitted; the rest derived "
                                                       "from them)")
        self.open_button = QPushButton("Open in the Results page")
        self.open_button.setToolTip("Z, Hx and SPL with their residuals; the Model lab starts from it too")
        self.again_button = QPushButton("Measure the next driver")
        self.again_button.setToolTip("Back to the Driver step, with the same hardware, calibration and class")
        buttons = QHBoxLayout()
        buttons.addWidget(self.open_button)
        buttons.addWidget(self.again_button)
        buttons.addStretch(1)
        left = QVBoxLayout()
        left.addWidget(self.source)
        left.addWidget(self.validity)
        left.addWidget(self.fit_quality)
        left.addLayout(buttons)
        left.addStretch(1)
        layout = QHBoxLayout(self)
        layout.addLayout(left, 1)
        layout.addWidget(table_box, 1)
        self.open_button.clicked.connect(self.on_open)
        self.again_button.clicked.connect(self.again_requested)

    def enter(self) -> None:
        outcome = self.state.outcome
        if outcome is None:
            return
        result = outcome.analysis.result
        self.source.setText(f"<b>{html.escape(outcome.path.name)}</b> in {html.escape(str(outcome.path.parent))}")
        self.validity.set_validity(result.validity)
        self.fit_quality.set_result(result)
        descriptions = {spec.name: spec.description for spec in result.fit.model.param_specs} if result.fit else {}
        self.table.set_parameters(result.parameters, descriptions, result.sd_m2)

    def missing(self) -> str | None:
        return "This is the last step." if self.state.outcome is not None else "No measurement yet."

    def on_open(self) -> None:
        if self.state.outcome is not None:
            self.open_requested.emit(self.state.outcome.analysis)
