"""The QA page: is this driver good, and can the measurement be trusted?

One large light for the measurement's validity, the channel lights with
their findings and remedies, pass/fail of the parameters against a limits
file (analysis.limits), and the report export (analysis.report). Both come
from other packages: when one is not installed its button stays disabled and
says why, rather than pretending.

The verdict is the one every output gives (analysis.qa_verdict): a red
measurement is INVALID in its own word and colour (measure again; the unit
itself was not judged), one whose model misses a curve by more than the
fit-error tolerance is NOT JUDGED; otherwise each parameter is judged by its
interval (value ± 2 σ): PASS, FAIL naming the failing parameters with their
margins, or UNCERTAIN (measure again) when an interval straddles a limit.
"""
from __future__ import annotations

import html
import importlib.util
from pathlib import Path

from PySide6.QtCore import QSettings, Qt, Signal
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (QAbstractItemView, QFileDialog, QGroupBox, QHBoxLayout, QHeaderView, QLabel,
                               QPushButton, QTableWidget, QTableWidgetItem, QVBoxLayout, QWidget)

from analysis.pipeline import AnalysisResult
from analysis.validity.result import ResultValidity
from app.qa import imported_words
from app.results.fit_quality import model_words
from app.jobs.book import Job, JobRunner
from app.jobs.controls import JobControls
from app.results.parameter_table import display_name, value_with_unit
from app.widgets.traffic_light import CHANNELS, ChannelLight, TrafficLight


LIMITS_MODULE, REPORT_MODULE = "analysis.limits", "analysis.report"
NO_LIMITS = "QA limits need analysis/limits.py, which this installation does not have."
NO_REPORT = "Reports need the analysis.report package, which this installation does not have."
LIMITS_KEY = "qa/limits_file"
ESTIMATING = "estimating"         # the verdict while the model part of the uncertainties is being estimated
ESTIMATING_WHY = ("model part: estimating… each parameter is judged by its interval once that includes what "
                  "the model misses (refits in the background)")
NO_VERDICT = ("#e6e6e6", "#404040")         # (background, text) before there is anything to judge
COLUMNS = ("Parameter", "Measured", "Limit", "Result")


def available(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except ModuleNotFoundError:
        return False


def display(value: float | None, parameter) -> str:
    """The measured value as the Results page shows it: rounded to its sigma, the unit in proper notation."""
    if value is None:
        return "–"
    if parameter is None:
        return f"{value:.4g}"
    return value_with_unit(parameter)


def qa_verdict(validity: ResultValidity | str) -> tuple[str, str]:
    """(verdict, why) without limits loaded: the measurement's validity alone (analysis.validity.fit.qa_blocker)."""
    from analysis.validity.fit import qa_blocker
    validity = ResultValidity(overall=validity) if isinstance(validity, str) else validity
    blocker = qa_blocker(validity)
    if blocker is not None:
        return blocker
    return "none", imported_words.NO_LIMITS if imported_words.imported(validity) else \
        "no limits loaded: only the measurement's validity is judged"


def write_report_file(job: Job, result: AnalysisResult, path: Path, limits) -> str:
    """Render and write one report (matplotlib takes a second or two); what was written.

    limits: the analysis.limits.Limits the page shows, for the report's QA section (None: none).
    """
    from analysis.archive.results import StoredResult, calibration_of, header_of_recording, results_document
    from analysis.recording.format import read_recording
    from analysis.archive.atomic import write_atomic
    from analysis.report import build_report, render_html, render_pdf
    if not hasattr(result, "spectra"):          # imported curves (File > Open curves…): no recording to read
        from analysis.curves.stored import curve_header, curve_results_document
        recording, stored, header = None, StoredResult.from_json(curve_results_document(result)), curve_header(result)
    else:
        recording = read_recording(result.source) if result.source and Path(result.source).exists() else None
        stored = StoredResult.from_json(results_document(result, recording))
        # The header a report of the same recording has from the command line or the archive.
        header = header_of_recording(recording) if recording is not None else {}
    calibration = calibration_of(recording) if recording is not None else {}
    content = build_report(stored, header, None, calibration, limits)
    job.check()
    render = render_html if path.suffix.lower() in (".html", ".htm") else render_pdf
    data = render(content)          # the seconds a user may cancel in
    job.check()                     # cancelled: nothing written
    return str(write_atomic(path, data))


def _interval_tip(verdict) -> str:
    """The interval a parameter was judged by, in the limits file's unit, for the row's tooltip."""
    from analysis.limits import INTERVAL_K
    from analysis.qa_verdict import margin_text
    if verdict.interval is None:
        return verdict.note
    lo, hi = (x / verdict.limit.to_si for x in verdict.interval)
    return (f"judged by value ± {INTERVAL_K:g} σ: {lo:.4g} .. {hi:.4g} against {verdict.limit.text}; "
            f"the value is {margin_text(verdict)}" + (f"; {verdict.note}" if verdict.note else ""))


class QAView(QWidget):
    verdict_changed = Signal(str)       # "pass" | "fail" | "uncertain" | "invalid" | "not judged" | "none" | ESTIMATING
    report_written = Signal(str)
    report_failed = Signal(str)         # why; the window says it on whichever page is shown

    def __init__(self, settings: QSettings | None = None, parent=None):
        super().__init__(parent)
        self.settings = settings
        self.result: AnalysisResult | None = None
        self.limits = None
        self.verdicts: tuple = ()
        self.judgement = None           # analysis.qa_verdict.QAJudgement against the loaded limits
        self.verdict = "none"
        self.worker = JobRunner(self, max_threads=1)     # one report at a time

        self.source = QLabel("No result yet: measure a driver, or open a recording.")
        self.source.setTextFormat(Qt.PlainText)             # a recording's file name is never markup
        self.source.setWordWrap(True)
        self.overall_light = TrafficLight(96)
        self.overall_text = QLabel()
        self.overall_text.setTextFormat(Qt.RichText)
        self.overall_text.setWordWrap(True)
        self.verdict_label = QLabel()
        self.verdict_label.setTextFormat(Qt.RichText)
        self.verdict_label.setWordWrap(True)
        self.verdict_label.setMargin(10)
        self.channels = {name: ChannelLight(name, 20) for name in CHANNELS}
        self.no_channels = QLabel(imported_words.NO_CHANNELS)      # in their place for imported curves
        self.no_channels.setWordWrap(True)

        self.load_button = QPushButton("Load limits…")
        self.limits_label = QLabel()
        self.limits_label.setWordWrap(True)
        self.limits_label.setTextFormat(Qt.RichText)
        self.table = QTableWidget(0, len(COLUMNS))
        self.table.setHorizontalHeaderLabels(COLUMNS)
        self.table.verticalHeader().setVisible(False)
        self.table.setEditTriggers(QAbstractItemView.NoEditTriggers)
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeToContents)
        header.setSectionResizeMode(2, QHeaderView.Stretch)
        self.export_button = QPushButton("Export report…")
        self.export_label = QLabel()
        self.export_label.setTextFormat(Qt.PlainText)       # paths and messages that quote them
        self.export_label.setWordWrap(True)
        self.export_jobs = JobControls(self.worker, cancel_tip="Stop writing the report: nothing is written",
                                       bar_width=160)
        self.export_jobs.busy_changed.connect(lambda _busy: self._update_export())
        self._build_layout()

        self.load_button.clicked.connect(self.on_load_limits)
        self.export_button.clicked.connect(self.on_export)
        self._restore_limits()
        self.refresh()

    def _build_layout(self) -> None:
        light_row = QHBoxLayout()
        light_row.addWidget(self.overall_light, 0, Qt.AlignTop)
        light_row.addWidget(self.overall_text, 1)
        left = QVBoxLayout()
        left.addWidget(self.source)
        left.addLayout(light_row)
        left.addWidget(self.verdict_label)
        channel_box = QGroupBox("Channels")
        channel_layout = QVBoxLayout(channel_box)
        for light in self.channels.values():
            channel_layout.addWidget(light)
        channel_layout.addWidget(self.no_channels)
        left.addWidget(channel_box)
        left.addStretch(1)

        limits_box = QGroupBox("Limits")
        limits_layout = QVBoxLayout(limits_box)
        row = QHBoxLayout()
        row.addWidget(self.load_button)
        row.addWidget(self.limits_label, 1)
        limits_layout.addLayout(row)
        limits_layout.addWidget(self.table, 1)
        report_box = QGroupBox("Report")
        report_layout = QHBoxLayout(report_box)
        report_layout.addWidget(self.export_button)
        report_layout.addWidget(self.export_label, 1)
        report_layout.addWidget(self.export_jobs)
        right = QVBoxLayout()
        right.addWidget(limits_box, 1)
        right.addWidget(report_box)
        layout = QHBoxLayout(self)
        layout.addLayout(left, 1)
        layout.addLayout(right, 1)

    # -- input -------------------------------------------------------------------
    def set_result(self, result: AnalysisResult | None) -> None:
        self.result = result
        if not self.export_jobs.busy:
            self.export_label.setText("")          # "Written ..." was about the previous result
        self.refresh()

    def load_limits(self, path: str | Path) -> bool:
        """Load a limits file; False (and the reason on the page) when it cannot be used."""
        from analysis.limits import LimitsError, load_limits
        try:
            self.limits = load_limits(path)
        except LimitsError as exc:
            self.limits = None
            self.limits_label.setText(f"<span style='color:#8e1b1b'>{html.escape(str(exc))}</span>")
            self.refresh(keep_limits_text=True)
            return False
        if self.settings is not None:
            self.settings.setValue(LIMITS_KEY, str(path))
        self.refresh()
        return True

    def _restore_limits(self) -> None:
        if not available(LIMITS_MODULE):
            return
        saved = self.settings.value(LIMITS_KEY, "") if self.settings is not None else ""
        if saved and Path(saved).exists():
            self.load_limits(saved)

    # -- showing -----------------------------------------------------------------
    def refresh(self, keep_limits_text: bool = False) -> None:
        result = self.result
        validity = result.validity if result is not None else ResultValidity()
        overall = str(validity.overall)
        self.overall_light.set_status(overall)
        from app.widgets.style import VALIDITY_TEXT
        from app.widgets.traffic_light import STATE_WORDS
        curves = imported_words.imported(validity)
        if curves and overall != "red":     # red: the curve is no driver's, said as a measurement's red
            headline, meaning = imported_words.HEADLINE, imported_words.JUDGED_BY
        else:
            headline, meaning = f"Measurement {STATE_WORDS.get(overall, overall)}", VALIDITY_TEXT.get(overall, "")
        self.overall_text.setText(f"<h2>{html.escape(headline)}</h2>{html.escape(meaning)}")
        self.no_channels.setVisible(curves)
        for name, light in self.channels.items():
            light.setVisible(not curves)
            entry = validity.channels.get(name)
            light.set_state(("unknown" if result is None else "absent") if entry is None else
                            str(entry.status or "unknown"), () if entry is None else entry.findings)
        if result is not None:
            model = f"fitted with {model_words(result)}" if result.fit is not None else "nothing fitted"
            self.source.setText(f"Result of {result.source.name if result.source else 'an unsaved measurement'}"
                                f" — {model}")
        self._show_limits(keep_limits_text)
        self._show_verdict(overall)
        self._update_export()

    def _show_limits(self, keep_text: bool) -> None:
        self.table.setRowCount(0)
        self.verdicts = ()
        self.judgement = None
        if not available(LIMITS_MODULE):
            self.load_button.setEnabled(False)
            self.load_button.setToolTip(NO_LIMITS)
            self.limits_label.setText(html.escape(NO_LIMITS))
            return
        self.load_button.setEnabled(True)
        if self.limits is None:
            if not keep_text:
                self.limits_label.setText("No limits loaded: load a limits file (linpar-limits/1 JSON) to judge "
                                          "the parameters.")
            return
        self.limits_label.setText(f"<b>{html.escape(self.limits.name)}</b> ({html.escape(str(self.limits.path))})")
        if self.result is None or self._estimating():
            return
        from analysis.qa_verdict import judge, outcome_word
        self.judgement = judge(self.limits, self.result.parameters, self.result.validity)
        self.verdicts = self.judgement.verdicts
        # Parameters of an invalid measurement, or of a model that does not describe it, are worthless
        # (docs/physics.md section 5): no parameter is judged against its limit (the verdict says why).
        judged = self.judgement.judged
        colours = {"pass": Qt.darkGreen, "FAIL": Qt.darkRed, "uncertain": QColor("#8a4300")}
        self.table.setRowCount(len(self.verdicts))
        for row, v in enumerate(self.verdicts):
            parameter = self.result.parameters.get(v.limit.name)
            # Why a value is missing is long (the finding and its remedy): in the tooltip, so that the
            # Limit and Result columns stay in view.
            measured = display(v.value, parameter) if v.value is not None else "not measured"
            outcome = outcome_word(v, judged)
            cells = (display_name(v.limit.name), measured, v.limit.text, outcome)
            tip = v.note if v.value is None else _interval_tip(v)
            for col, text in enumerate(cells):
                item = QTableWidgetItem(text)
                if tip:
                    item.setToolTip(tip)
                if not judged:
                    item.setForeground(Qt.gray)
                elif col == 3:
                    item.setForeground(colours.get(outcome, Qt.black))
                self.table.setItem(row, col, item)

    def _show_verdict(self, overall: str) -> None:
        if self.result is None:
            verdict, why = "none", "nothing to judge yet"
        elif self._estimating():
            verdict, why = ESTIMATING, ESTIMATING_WHY
        elif self.judgement is not None:
            verdict, why = self.judgement.verdict, self.judgement.why
        else:
            verdict, why = qa_verdict(self.result.validity)
        from analysis.report.qa import VERDICT_COLOURS
        from analysis.validity.fit import VERDICT_HEADLINES
        background, text = VERDICT_COLOURS.get(verdict, NO_VERDICT)
        title = VERDICT_HEADLINES.get(verdict, "JUDGING…" if verdict == ESTIMATING else "NO VERDICT")
        self.verdict_label.setStyleSheet(f"QLabel {{ background: {background}; color: {text}; "
                                         f"border: 1px solid {text}; border-radius: 4px; }}")
        self.verdict_label.setText(f"<span style='font-size:20pt'><b>{html.escape(title)}</b></span><br>"
                                   f"{html.escape(why)}{self._fit_error_line()}")
        if verdict != self.verdict:
            self.verdict = verdict
            self.verdict_changed.emit(verdict)

    def _estimating(self) -> bool:
        """Limits loaded and the result's model part still being estimated: judged once it is (the interval
        includes it), never first on the noise alone (a false FAIL, or UNCERTAIN, for a few seconds)."""
        from analysis.fit.model_uncertainty import pending
        return self.limits is not None and self.result is not None and pending(self.result)

    def _fit_error_line(self) -> str:
        """Each curve's fit error against the limits' tolerance: what decided that the unit could be judged."""
        if self.judgement is None or not self.judgement.fit_error_percent or self.judgement.verdict == "invalid":
            return ""
        tolerance = self.limits.fit_error_percent
        said = ", ".join(f"{name} {err:.2g} % (tolerance {tolerance.get(name, float('nan')):g} %)"
                         for name, err in self.judgement.fit_error_percent.items())
        return f"<br><small>Fit error (rms misfit of each curve): {html.escape(said)}</small>"

    # -- export ------------------------------------------------------------------
    def _update_export(self) -> None:
        if not available(REPORT_MODULE):
            self.export_button.setEnabled(False)
            self.export_button.setToolTip(NO_REPORT)
            self.export_label.setText(NO_REPORT)
            return
        exporting = self.export_jobs.busy
        self.export_button.setEnabled(self.result is not None and not exporting)
        if exporting:
            return
        if self.result is None:
            self.export_label.setText("Nothing to report yet.")
        elif not self.export_label.text().startswith(("Written", "Could not", "Export cancelled")):
            self.export_label.setText("A PDF or HTML report of this result: parameters, validity, plots"
                                      + (", and the QA verdict against the loaded limits." if self.limits is not None
                                         else "."))

    def on_load_limits(self) -> None:
        start = str(Path(self.settings.value(LIMITS_KEY, "")).parent) if self.settings is not None else ""
        path, _ = QFileDialog.getOpenFileName(self, "Load QA limits", start, "Limits (*.json);;All files (*)")
        if path:
            self.load_limits(path)

    def on_export(self) -> None:
        if self.result is None:
            return
        stem = self.result.source.with_suffix("").name if self.result.source else "report"
        start = str(self.result.source.with_name(stem + "-report.pdf")) if self.result.source else "report.pdf"
        # The window is the dialog's parent: File > Export report… asks from whichever page is shown.
        path, _ = QFileDialog.getSaveFileName(self.window(), "Export report", start, "PDF (*.pdf);;HTML (*.html)")
        if path:
            self.export_to(Path(path))

    def export_to(self, path: Path) -> None:
        result, limits = self.result, self.limits   # frozen dataclasses: safe to hand to the pool thread
        job = self.worker.run("report", lambda job: write_report_file(job, result, path, limits),
                              f"writing the report {path.name}")
        self.export_label.setText("")
        self.export_jobs.run(job, f"Writing {path.name}…", self.on_report_written, self.on_report_failed,
                             lambda: self.export_label.setText("Export cancelled: nothing written."))

    def on_report_written(self, written: str) -> None:
        self.export_label.setText(f"Written: {written}")
        self.report_written.emit(written)

    def on_report_failed(self, message: str) -> None:
        self.export_label.setText(f"Could not write the report: {message}")
        self.report_failed.emit(message)

    def shutdown(self, wait_ms: int) -> bool:
        self.export_jobs.drop()
        return self.worker.shutdown(wait_ms)
