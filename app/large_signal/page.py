"""The Large-signal page: Bl(x), Kms(x), Le(x) of a driver from recordings at large signal, with the coil's rest
offset, the excursion limits and the distortion the model predicts against the distortion measured.

The identification (analysis.large_signal, a few seconds per recording) is a
job (app.jobs.book) shown by a JobControls; the page shows what it returns.
It is reached from the Series page's level series ("Large-signal curves")
or with its own button.
"""
from __future__ import annotations

import html
import math
from pathlib import Path
from typing import Sequence

import numpy as np
from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (QComboBox, QFileDialog, QGridLayout, QHBoxLayout, QLabel, QPushButton, QSplitter,
                               QVBoxLayout, QWidget)

from analysis.large_signal import LargeSignalResult, large_signal
from app.jobs.book import JobRunner, failure_text
from app.jobs.controls import JobControls
from app.large_signal.plots import CurvePlot, DistortionPlot
from app.widgets.style import VALIDITY_COLOURS

RECORDING_FILTER = "Recordings (*.wav *.json)"
SAVE_FILTER = "PDF report (*.pdf);;HTML report (*.html);;Curves as CSV (*.csv);;Curves as JSON (*.json)"
EMPTY_TEXT = ("No large-signal curves yet: choose recordings of one driver at large signal (a level series, or "
              "the steps of a large-signal measurement).")


class LargeSignalPage(QWidget):
    result_shown = Signal(object)       # LargeSignalResult, once on screen

    def __init__(self, parent=None):
        super().__init__(parent)
        # large_signal() cannot stop midway (seconds): a cancelled identification finishes in the background
        # and its result is dropped (app.jobs.book).
        self.worker = JobRunner(self, max_threads=1)
        self.result: LargeSignalResult | None = None
        self.choose_button = QPushButton("Choose recordings…")
        self.choose_button.setToolTip("Recordings of one driver at large signal, with the laser")
        self.jobs = JobControls(self.worker, cancel_tip="Stop the identification; the curves shown stay",
                                bar_width=160)
        self.jobs.busy_changed.connect(lambda busy: self.choose_button.setEnabled(not busy))
        self.save_button = QPushButton("Save report or curves…")
        self.save_button.setToolTip("The report as PDF or HTML, the curves as CSV or JSON")
        self.save_button.setEnabled(False)
        self.status = QLabel(EMPTY_TEXT)
        self.status.setWordWrap(True)
        self.summary = QLabel()
        self.summary.setWordWrap(True)
        self.summary.setTextFormat(self.summary.textFormat().RichText)
        self.summary.setTextInteractionFlags(self.summary.textInteractionFlags().TextSelectableByMouse)
        self.summary.setMinimumWidth(280)
        self.summary.setAlignment(Qt.AlignTop | Qt.AlignLeft)
        self.plots = {"Bl": CurvePlot("Bl", "Bl (T·m)", 1.0), "Kms": CurvePlot("Kms", "Kms (N/mm)", 1e-3),
                      "Le": CurvePlot("Le", "Le (mH)", 1e3)}
        self.distortion = DistortionPlot()
        self.level_choice = QComboBox()
        self.level_choice.setToolTip("The recording whose measured distortion the prediction is compared with")
        controls = QHBoxLayout()
        for w in (self.choose_button, self.save_button):
            controls.addWidget(w)
        controls.addWidget(self.jobs)
        controls.addWidget(self.status, 1)
        grid = QGridLayout()
        grid.addWidget(self.plots["Bl"], 0, 0)
        grid.addWidget(self.plots["Kms"], 0, 1)
        grid.addWidget(self.plots["Le"], 1, 0)
        distortion_box = QVBoxLayout()
        distortion_box.addWidget(self.level_choice)
        distortion_box.addWidget(self.distortion, 1)
        grid.addLayout(distortion_box, 1, 1)
        plots = QWidget()
        plots.setLayout(grid)
        splitter = QSplitter()
        splitter.addWidget(self.summary)
        splitter.addWidget(plots)
        splitter.setStretchFactor(1, 3)
        layout = QVBoxLayout(self)
        layout.addLayout(controls)
        layout.addWidget(splitter, 1)
        self.choose_button.clicked.connect(self.on_choose)
        self.save_button.clicked.connect(self.on_save)
        self.level_choice.currentIndexChanged.connect(self.on_level_chosen)

    # --- slots ----------------------------------------------------------------------------------------------------

    def on_choose(self) -> None:
        paths, _ = QFileDialog.getOpenFileNames(self, "Recordings at large signal", "", RECORDING_FILTER)
        if paths:
            self.analyse([Path(p) for p in paths])

    def analyse(self, paths: Sequence[Path]) -> None:
        stems = sorted({Path(p).with_suffix("") for p in paths})
        self.status.setText("")
        job = self.worker.run("identification", lambda job: large_signal(stems),
                              "the large-signal identification")
        self.jobs.run(job, f"Identifying the curves from {len(stems)} recording(s)…", self.on_finished,
                      lambda message: self.status.setText(f"Not identified: {message}"),
                      lambda: self.status.setText("Cancelled: the curves shown (if any) are the previous ones."),
                      stops_midway=False)       # the identification cannot stop midway: let the page go now

    def on_finished(self, result: LargeSignalResult) -> None:
        self.status.setText(f"{len(result.fits)} recording(s) identified.")
        self.show_result(result)

    def shutdown(self, wait_ms: int) -> bool:
        """Cancel the identification; one that cannot stop in time finishes in the background, unheard."""
        self.jobs.drop()
        return self.worker.shutdown(wait_ms)

    def on_save(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Save the large-signal report or curves", "", SAVE_FILTER)
        if path:
            self.save(Path(path))

    def save(self, path: Path) -> None:
        """Write the report (.pdf, .html) or the curves (.csv, .json), by the file's suffix; the outcome is said
        on the status line."""
        from analysis.archive.atomic import write_atomic
        from analysis.export.large_signal import curves_csv, curves_json
        from analysis.report.large_signal import render_large_signal_html, render_large_signal_pdf
        render = {".pdf": render_large_signal_pdf, ".html": render_large_signal_html, ".csv": curves_csv,
                  ".json": curves_json}.get(path.suffix.lower())
        if self.result is None or render is None:
            self.status.setText(f"Not saved: {path.name}: name a .pdf, .html, .csv or .json file")
            return
        if path.exists() and not path.is_file():
            self.status.setText(f"Not saved: {path} is not a regular file")
            return
        try:
            write_atomic(path, render(self.result))
        except Exception as exc:  # noqa: BLE001 - a full disk is the user's, a bug is said as one (job_book)
            self.status.setText(f"Not saved: {failure_text(exc, f'saving {path.name}')}")
            return
        self.status.setText(f"Saved {path}")

    def on_level_chosen(self, index: int) -> None:
        if self.result is not None and 0 <= index < len(self.result.fits):
            self.distortion.set_fit(self.result.fits[index])

    # --- showing ----------------------------------------------------------------------------------------------------

    def show_result(self, result: LargeSignalResult) -> None:
        self.result = result
        model, derived, thresholds = result.model, result.derived, result.thresholds
        limits = derived.limits

        def both_sides(limit):
            if limit.value is None:
                return []
            text = f"{limit.name} {limit.value * 1e3:.2f} mm" + (" (beyond)" if limit.beyond_range else "")
            return [(limit.value, text), (-limit.value, "")]
        self.plots["Bl"].set_curve(model.Bl, both_sides(limits["X_Bl"]),
                                   (model.Bl.coefficients[0] * thresholds.bl_ratio,
                                    f"{thresholds.bl_ratio * 100:g} % of Bl(0)"),
                                   [(derived.offset_m, f"Bl max {derived.offset_m * 1e3:+.2f} mm")])
        self.plots["Kms"].set_curve(model.Kms, both_sides(limits["X_C"]),
                                    (model.Kms.coefficients[0] / thresholds.compliance_ratio * 1e-3,
                                     f"Cms at {thresholds.compliance_ratio * 100:g} %"))
        self.plots["Le"].set_curve(model.Le, both_sides(limits["X_L"]),
                                   (model.Le.coefficients[0] * (1 + thresholds.le_change) * 1e3,
                                    f"+{thresholds.le_change * 100:g} %"))
        self.level_choice.blockSignals(True)
        self.level_choice.clear()
        for fit in result.fits:
            self.level_choice.addItem(f"{fit.label} ({fit.drive_rms_v:.3g} V)")
        self.level_choice.setCurrentIndex(len(result.fits) - 1)
        self.level_choice.blockSignals(False)
        self.distortion.set_fit(result.fits[-1] if result.fits else None)
        self.summary.setText(summary_html(result))
        self.save_button.setEnabled(True)
        self.result_shown.emit(result)


def summary_html(result: LargeSignalResult) -> str:
    """What a technician reads first: the curves at rest, where to move the coil, the limits, how good the fit is,
    and what to read with care."""
    model, derived = result.model, result.derived
    lo, hi = model.x_range

    def at_rest(curve, scale, unit, digits):
        value = curve.coefficients[0] * scale
        sigma = float(curve.sigma(np.array([0.0]))[0]) * abs(scale)
        return f"{value:.{digits}f} ± {sigma:.{digits}f} {unit}" if sigma * 10**digits >= 0.5 else \
            f"{value:.{digits}f} {unit}"
    rows = [("Bl(0)", at_rest(model.Bl, 1.0, "T·m", 3)), ("Kms(0)", at_rest(model.Kms, 1e-3, "N/mm", 3)),
            ("Le(0)", at_rest(model.Le, 1e3, "mH", 4)),
            ("Measured range", f"{lo * 1e3:+.2f} to {hi * 1e3:+.2f} mm"),
            ("Stiffness asymmetry", f"{derived.asymmetry_percent:+.1f} % at ±{derived.asymmetry_at_m * 1e3:.2f} mm")]
    for limit in derived.limits.values():
        if limit.value is None:
            continue
        value = (f"more than {limit.value * 1e3:.2f} mm" if limit.beyond_range else
                 f"{limit.value * 1e3:.2f} mm ({limit.side})")
        rows.append((f"{limit.name} ({limit.criterion})", value))
    table = "".join(f"<tr><td><b>{html.escape(a)}</b>&nbsp;</td><td>{html.escape(b)}</td></tr>" for a, b in rows)
    chi2 = result.identification.solution.chi2_red
    quality = ("the model fits to the noise" if chi2 < 1.5 else
               f"the model leaves a misfit {chi2:.1f} times the noise")
    explained = [f.channels["current"].explained_percent for f in result.fits
                 if not f.failed and math.isfinite(f.channels["current"].explained_percent)]
    if explained:
        quality += f"; it explains {min(explained):.0f} % or more of the current's distortion"
    if result.verdict == "red":
        quality = ("not to be judged by its chi², whose weights count the misfit as noise: the laser's delay was "
                   "not found")
    parts = [f"<p><b>Coil:</b> {html.escape(derived.coil_advice())}</p>", f"<table>{table}</table>",
             f"<p><b>Fit:</b> {html.escape(quality)}.</p>"]
    if result.verdict == "red":
        # Above the numbers: a laser delay not found leaves curves that are not a measurement (trust.py).
        background, text = VALIDITY_COLOURS["red"]
        parts.insert(0, f'<p style="background:{background}; color:{text}"><b>Not to be trusted:</b> the laser\'s '
                        "delay was not found; the values below are not a measurement (see below).</p>")
    if result.flags:
        parts.append("<p><b>To read with care:</b></p><ul>" +
                     "".join(f"<li>{html.escape(flag)}</li>" for flag in result.flags) + "</ul>")
    return "".join(parts)
