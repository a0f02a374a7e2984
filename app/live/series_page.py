"""The Series page: several recordings of one driver analysed together.

Two questions a lab asks of a set of recordings:
- Repeatability (the paper's Table I): the same driver measured N times:
  mean, standard deviation and percent per parameter;
- Level series (Table II and Fig. 14): the same driver at rising levels:
  the parameters against peak excursion.

Each set is analysed by a job (app.jobs.book, one recording after the other)
shown by the panel's JobControls; the page only shows what
analysis.repeatability and analysis.level_series return.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable, Sequence

from PySide6.QtCore import Signal
from PySide6.QtWidgets import (QAbstractItemView, QFileDialog, QHBoxLayout, QLabel, QPushButton, QTableWidget,
                               QTableWidgetItem, QTabWidget, QVBoxLayout, QWidget)

from analysis.level_series import level_series
from analysis.pipeline import analyze_path, require_fit
from analysis.repeatability import Spread, repeatability
from analysis.report.numbers import pretty_unit
from app.jobs.book import Job, JobRunner
from app.jobs.controls import JobControls
from app.live.level_series_view import LevelSeriesView
from app.results.parameter_table import display_name

RECORDING_FILTER = "Recordings (*.wav *.json)"


def analysed_set(job: Job, kind: str, paths: list[Path]):
    """The set analysed one recording after the other (a cancel is heard between them), then its spread."""
    results = []
    for done, path in enumerate(paths):
        job.check()
        job.progress(done / len(paths), f"analysing recording {done + 1} of {len(paths)}")
        result = analyze_path(path)
        require_fit(result, f"be one of the {kind} results")
        results.append(result)
    if kind == "repeatability":
        return repeatability([r.parameters for r in results]), len(results)
    return level_series(results)


class RepeatabilityTable(QTableWidget):
    COLUMNS = ("Parameter", "Mean", "Std", "Std %", "Fit σ (mean)", "Unit", "n")

    def __init__(self, parent=None):
        super().__init__(0, len(self.COLUMNS), parent)
        self.setHorizontalHeaderLabels(self.COLUMNS)
        self.setEditTriggers(QAbstractItemView.NoEditTriggers)
        self.verticalHeader().setVisible(False)

    def set_spreads(self, spreads: dict[str, Spread]) -> None:
        self.setRowCount(len(spreads))
        for row, s in enumerate(spreads.values()):
            scale = s.display_scale

            def shown(x, digits=5):
                return "n/a" if x is None else f"{x * scale:.{digits}g}"
            unit = "" if s.display_unit in ("1", "-") else pretty_unit(s.display_unit)
            cells = (display_name(s.name), shown(s.mean), shown(s.std, 2),
                     "" if s.percent is None else f"{s.percent:.2g}", shown(s.mean_fit_std, 2), unit, str(s.n))
            for col, text in enumerate(cells):
                self.setItem(row, col, QTableWidgetItem(text))
        self.resizeColumnsToContents()


class _SetPanel(QWidget):
    """A button to choose recordings, the job's progress and Cancel, a status line, and the result widget below."""

    def __init__(self, title: str, hint: str, result: QWidget, choose: Callable[[], None], worker: JobRunner):
        super().__init__()
        self.choose_button = QPushButton(title)
        self.choose_button.clicked.connect(choose)
        self.jobs = JobControls(worker, cancel_tip="Stop the analysis of the set; the result shown stays")
        self.jobs.busy_changed.connect(lambda busy: self.choose_button.setEnabled(not busy))
        self.status = QLabel(hint)
        self.status.setWordWrap(True)
        row = QHBoxLayout()
        row.addWidget(self.choose_button)
        row.addWidget(self.jobs, 1)
        layout = QVBoxLayout(self)
        layout.addLayout(row)
        layout.addWidget(self.status)
        layout.addWidget(result, 1)


class SeriesPage(QTabWidget):
    """Repeatability and level series of several recordings."""

    # The level series' recordings, for the Large-signal page (the drift's reason: Bl(x), Kms(x), Le(x)).
    large_signal_requested = Signal(list)

    def __init__(self, parent=None):
        super().__init__(parent)
        # One thread: a set's recordings are analysed one after the other, and a second set waits for the first.
        self.worker = JobRunner(self, max_threads=1)
        self.level_paths: list[Path] = []
        self.repeat_table = RepeatabilityTable()
        self.levels_view = LevelSeriesView()
        self.panels = {
            "repeatability": _SetPanel("Choose repeated recordings…",
                                       "The same driver measured several times (remounted between): mean, standard "
                                       "deviation and percent per parameter.",
                                       self.repeat_table, lambda: self.on_choose("repeatability"), self.worker),
            "levels": _SetPanel("Choose recordings at rising levels…",
                                "The same driver at rising drive levels: the parameters and fs against peak "
                                "excursion.",
                                self.levels_view, lambda: self.on_choose("levels"), self.worker),
        }
        self.large_signal_button = QPushButton("Large-signal curves of these recordings…")
        self.large_signal_button.setToolTip("Bl(x), Kms(x) and Le(x) behind the drift, the coil's rest offset and the "
                                            "excursion limits, on the Large-signal page")
        self.large_signal_button.setEnabled(False)
        self.large_signal_button.clicked.connect(lambda: self.large_signal_requested.emit(list(self.level_paths)))
        self.panels["levels"].layout().itemAt(0).layout().insertWidget(1, self.large_signal_button)
        self.addTab(self.panels["repeatability"], "Repeatability")
        self.addTab(self.panels["levels"], "Level series")

    def on_choose(self, kind: str) -> None:
        paths, _ = QFileDialog.getOpenFileNames(self, "Choose recordings", "", RECORDING_FILTER)
        if paths:
            self.analyse(kind, [Path(p) for p in paths])

    def analyse(self, kind: str, paths: Sequence[Path]) -> None:
        stems = sorted({p.with_suffix("") for p in paths})
        panel = self.panels[kind]
        if len(stems) < 2:
            panel.status.setText("Choose at least two recordings: a spread needs more than one.")
            return
        if kind == "levels":
            self.level_paths = list(stems)
            self.large_signal_button.setEnabled(False)
        job = self.worker.run(kind, lambda job: analysed_set(job, kind, stems), f"the {kind} analysis")
        panel.status.setText("")
        panel.jobs.run(job, f"Analysing {len(stems)} recordings…", lambda outcome: self.on_finished(kind, outcome),
                       lambda message: panel.status.setText(f"Not analysed: {message}"),
                       lambda: panel.status.setText("Cancelled: the result shown (if any) is the previous one."))

    def on_finished(self, kind: str, outcome) -> None:
        if kind == "repeatability":
            spreads, n = outcome
            self.repeat_table.set_spreads(spreads)
            self.panels[kind].status.setText(f"{n} recordings analysed.")
        else:
            self.levels_view.set_series(outcome)
            self.panels[kind].status.setText(f"{len(outcome.levels)} levels analysed.")
            self.large_signal_button.setEnabled(True)

    def shutdown(self, wait_ms: int) -> bool:
        """Cancel the set being analysed and wait for it; whatever it says later is dropped."""
        for panel in self.panels.values():
            panel.jobs.drop()
        return self.worker.shutdown(wait_ms)
