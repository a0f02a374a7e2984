"""The Results page: validity, fit quality, Z / Hx / SPL plots and the parameter table."""
from __future__ import annotations

import html
from collections.abc import Callable, Iterator

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (QFrame, QHBoxLayout, QLabel, QSplitter, QStackedWidget, QTabWidget, QVBoxLayout,
                               QWidget)

from analysis.derived import parameter_table
from analysis.pipeline import AnalysisResult
from app.widgets import style
from app.results.fit_quality import FitQualityBox
from app.results.imported import draw_references, is_imported, source_html
from app.results.measured_spectra import MeasuredSpectraView
from app.results.parameter_table import titled_parameter_table
from app.widgets.plots import TransferPlot
from app.results.spl_panel import SplPanel
from app.jobs.workers import AnalysisOutcome
from app.jobs.next_turn import in_turns

EMPTY_TEXT = ("No recording loaded.\n\nOpen one with File ▸ Open recording… (Ctrl+O), "
              "or drop a recording's .wav or .json file on this window.")


class ValidityBox(QLabel):
    """result.validity.overall in its colour, with what the state means."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setWordWrap(True)
        self.setMargin(8)
        self.setTextFormat(Qt.RichText)
        self.state = "unknown"
        self.set_state("unknown")

    def set_state(self, state: str, meaning: str | None = None) -> None:
        """`meaning`: what the state means here, when not the usual (imported curves: nothing was checked)."""
        self.state = state
        background, text = style.validity_colours(state)
        self.setStyleSheet(f"QLabel {{ background: {background}; color: {text}; border: 1px solid {text}; "
                           f"border-radius: 4px; }}")
        meaning = meaning or style.VALIDITY_TEXT.get(state, "a state this version does not know")
        self.setText(f"<b>Validity: {html.escape(state)}</b> — {html.escape(meaning)}")


def imported_meaning(validity) -> str | None:
    """What the validity of imported curves means: what was found in them (their numbers no driver's, a curve the
    model misses), each with its remedy, else that nothing was checked; None for a recording."""
    if validity.imported is None:
        return None
    found = validity.findings
    return "; ".join(f"{f.message}: {f.remedy}" for f in found) if found else validity.imported.note


def source_text(result: AnalysisResult) -> str:
    s = result.spectra
    name = result.source.name if result.source else "recording"
    channels = "Z and Hx" if s.displacement is not None else "Z only (no displacement channel)"
    return (f"<b>{html.escape(name)}</b> &nbsp;·&nbsp; {s.sample_rate / 1000:g} kHz, {s.n_periods} periods of "
            f"{s.period_samples} samples, {len(s.excited_bins)} lines "
            f"{s.impedance.freqs.min():.3g}–{s.impedance.freqs.max():.4g} Hz &nbsp;·&nbsp; {channels}")


class ResultsView(QWidget):
    # The parameter set shown changed (a new result, or Sd edited): the new AnalysisResult.
    result_changed = Signal(object)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.result: AnalysisResult | None = None
        self.curves = None
        self._nominal_ohm: float | None = None
        self._unshown = False               # the result's widgets wait for the page to be shown (_showing)
        self._filling = 0                   # counts the results begun: a fill in turns stops once a newer begins

        self.empty = QLabel(EMPTY_TEXT)
        self.empty.setAlignment(Qt.AlignCenter)
        self.empty.setWordWrap(True)

        # Word wrap on every long label: an unwrapped one sets the window's minimum width.
        self.source_label = QLabel()
        self.source_label.setTextFormat(Qt.RichText)
        self.source_label.setWordWrap(True)
        self.validity_box = ValidityBox()
        self.fit_quality = FitQualityBox()

        self.impedance_plot = TransferPlot("|Z| (Ω)", 1.0, log_y=False)
        self.measured_spectra = MeasuredSpectraView()       # a broken measurement: what it still measured
        self.impedance_stack = QStackedWidget()
        self.impedance_stack.addWidget(self.impedance_plot)
        self.impedance_stack.addWidget(self.measured_spectra)
        self.displacement_plot = TransferPlot("|Hx| (mm/V)", 1e3, log_y=True)
        self.no_displacement = QLabel("This recording has no displacement channel: Hx, and with it Bl, Mms, "
                                      "Cms and the SPL prediction, need the laser.")
        self.no_displacement.setAlignment(Qt.AlignCenter)
        self.no_displacement.setWordWrap(True)
        self.displacement_stack = QStackedWidget()
        self.displacement_stack.addWidget(self.displacement_plot)
        self.displacement_stack.addWidget(self.no_displacement)
        self.spl_panel = SplPanel()

        self.plot_tabs = QTabWidget()
        self.plot_tabs.addTab(self.impedance_stack, "Impedance Z")
        self.plot_tabs.addTab(self.displacement_stack, "Displacement Hx")
        self.plot_tabs.addTab(self.spl_panel, "Predicted SPL")

        table_box, self.parameter_table = titled_parameter_table("<b>Parameters</b> (bold: fitted; the rest derived from them)")

        splitter = QSplitter(Qt.Horizontal)
        splitter.addWidget(self.plot_tabs)
        splitter.addWidget(table_box)
        splitter.setStretchFactor(0, 3)
        splitter.setStretchFactor(1, 1)
        splitter.setSizes([960, 420])
        self.splitter = splitter

        header = QHBoxLayout()
        header.addWidget(self.source_label, 1)
        content = QWidget()
        content_layout = QVBoxLayout(content)
        content_layout.setContentsMargins(0, 0, 0, 0)
        content_layout.addLayout(header)
        content_layout.addWidget(self.validity_box)
        content_layout.addWidget(self.fit_quality)
        line = QFrame()
        line.setFrameShape(QFrame.HLine)
        line.setFrameShadow(QFrame.Sunken)
        content_layout.addWidget(line)
        content_layout.addWidget(splitter, 1)

        self.stack = QStackedWidget()
        self.stack.addWidget(self.empty)
        self.stack.addWidget(content)
        self.content = content
        layout = QVBoxLayout(self)
        layout.addWidget(self.stack)

        self.spl_panel.sd_changed.connect(self.on_sd_changed)
        self.spl_panel.clear()

    @property
    def has_result(self) -> bool:
        return self.result is not None

    def set_busy(self, text: str) -> None:
        """While a first recording is analysed the empty page says so; a shown result stays until replaced."""
        if self.result is None:
            self.empty.setText(text)

    def set_idle(self) -> None:
        if self.result is None:
            self.empty.setText(EMPTY_TEXT)

    def show_outcome(self, outcome: AnalysisOutcome) -> None:
        self._filling += 1
        for _ in self._showing(outcome):
            pass

    def show_outcome_in_turns(self, outcome: AnalysisOutcome, then: Callable[[], None]) -> None:
        """show_outcome, each plot in a later turn of the event loop than the table (a finished measurement's
        hand-off: the whole page in one turn held the GUI thread 30-40 ms of CPU). `then()` once it is shown, or
        once a newer result (show_outcome, clear) replaced it on its way: what waits for it (the archive's store)
        is never lost."""
        self._filling += 1
        filling = self._filling
        in_turns(self, self._showing(outcome), going_on=lambda: filling == self._filling, then=then)

    def _showing(self, outcome: AnalysisOutcome) -> Iterator[None]:
        """The result taken and announced (result_changed); its widgets filled in four steps, each up to a `yield`
        (the words and the table, |Z|, Hx, the rest), or, on a page behind another one, once it is shown."""
        self.result, self.curves = outcome.result, outcome.curves
        self._nominal_ohm = outcome.nominal_ohm
        self._unshown = self._behind_another_page()
        if not self._unshown:
            yield from self._drawing(self.result, self.curves, outcome.nominal_ohm)
        self.result_changed.emit(self.result)       # with Sd as edited meanwhile, if it was

    def _behind_another_page(self) -> bool:
        """The window is on screen but this page is not (another tab is in front). A version of the Model lab's,
        adopted while the lab is in front, was drawn here at every refit: ~20 ms of the GUI thread's CPU for a page
        nobody saw. A window not shown yet (tests, the start) fills at once."""
        window = self.window()
        return window is not self and window.isVisible() and not self.isVisible()

    def showEvent(self, event) -> None:
        if self._unshown and self.result is not None:
            self._unshown = False
            for _ in self._drawing(self.result, self.curves, self._nominal_ohm):      # before its first paint
                pass
        super().showEvent(event)

    def _drawing(self, result: AnalysisResult, curves, nominal_ohm: float | None) -> Iterator[None]:
        """The widgets filled with `result` in four steps, each up to a `yield`: the words and the table, |Z|, Hx,
        the rest."""
        imported = is_imported(result)
        self.source_label.setText(source_html(result) if imported else
                                  source_text(result) + self._re_remark(result, nominal_ohm))
        self.validity_box.set_state(str(result.validity.overall), imported_meaning(result.validity))
        self.fit_quality.set_result(result)
        self._show_parameters(result)
        if curves is None:          # a broken measurement: judged (validity, reasons), nothing fitted
            self.impedance_plot.clear_curves()
            self.displacement_plot.clear_curves()
            self.measured_spectra.show_result(result)
            self.impedance_stack.setCurrentWidget(self.measured_spectra)
            self.plot_tabs.setTabText(0, "Measured")
            self.displacement_stack.setCurrentWidget(self.displacement_plot)
            self.spl_panel.clear()
            self.stack.setCurrentWidget(self.content)
            return
        yield
        self.impedance_stack.setCurrentWidget(self.impedance_plot)
        self.plot_tabs.setTabText(0, "Impedance Z")
        self.impedance_plot.set_curves(curves.impedance, "Impedance Z = U / I")
        yield
        if curves.displacement is not None:
            self.displacement_plot.set_curves(curves.displacement, "Displacement per volt Hx = X / U")
            self.displacement_stack.setCurrentWidget(self.displacement_plot)
        else:
            self.displacement_plot.clear_curves()
            self.displacement_stack.setCurrentWidget(self.no_displacement)
        yield
        if imported:
            draw_references(result, {"impedance": self.impedance_plot, "displacement": self.displacement_plot})
        self.spl_panel.set_data(curves.displacement, self.result.sd_m2)
        self.stack.setCurrentWidget(self.content)

    def show_model_part(self, outcome: AnalysisOutcome) -> bool:
        """The same result with the model part of its uncertainties (AnalysisWorker.start_model_part): the table
        and the fit's words updated, the pages that follow this one told. False (nothing shown) when the page
        has moved on to another result meanwhile."""
        shown = self.result
        if shown is None or shown.fit is not outcome.result.fit:
            return False
        result = outcome.result
        if shown.sd_m2 != result.sd_m2:         # Sd edited while the refits ran: the parts at the Sd shown
            from analysis.fit.model_uncertainty import with_sd
            result = with_sd(result, parameter_table(result.fit, shown.sd_m2), shown.sd_m2)
        self.result = result
        if not self._unshown:           # else drawn with it when the page is shown
            self.fit_quality.set_result(result)
            self._show_parameters(result)
        self.result_changed.emit(result)
        return True

    @staticmethod
    def _re_remark(result: AnalysisResult, nominal_ohm: float | None) -> str:
        """Re against the nominal impedance entered, on a line of its own when it is unusual (not a verdict)."""
        from analysis.validity.nominal_remark import re_nominal_remark
        re = result.parameters.get("RE")
        remark = re_nominal_remark(None if re is None else re.value, nominal_ohm)
        return f"<br><span style='color:{style.VALIDITY_COLOURS['yellow'][1]}'>{html.escape(remark)}</span>" if remark else ""

    def clear(self) -> None:
        self._filling += 1
        self.result = self.curves = None
        self._unshown = False
        self.impedance_plot.clear_curves()
        self.displacement_plot.clear_curves()
        self.spl_panel.clear()
        self.parameter_table.set_parameters({})
        self.empty.setText(EMPTY_TEXT)
        self.stack.setCurrentWidget(self.empty)

    def on_sd_changed(self, sd_m2: float | None) -> None:
        """Sd feeds only derived parameters (Vas, eta0, SPL): recomputed here, no new fit needed."""
        if self.result is None or self.result.fit is None:
            return
        # parameter_table propagates through the covariance: milliseconds, fine on the GUI thread; the model
        # part comes again from the members already fitted (analysis.fit.model_uncertainty.with_sd).
        from analysis.fit.model_uncertainty import with_sd
        result = with_sd(self.result, parameter_table(self.result.fit, sd_m2), sd_m2)
        self.result = result
        self._show_parameters(result)
        self.result_changed.emit(result)

    def _show_parameters(self, result: AnalysisResult) -> None:
        descriptions = {spec.name: spec.description for spec in result.fit.model.param_specs} if result.fit else {}
        self.parameter_table.set_parameters(result.parameters, descriptions, result.sd_m2)
