"""The Series page: several recordings of one driver analysed together.

Two questions a lab asks of a set of recordings:
- Repeatability (the paper's Table I): the same driver measured N times:
  mean, standard deviation and percent per parameter;
- Level series (Table II and Fig. 14): the same driver at rising levels:
  the parameters against peak excursion.

Each set is analysed by a pool thread (one recording after the other); the
page only shows what analysis.repeatability and analysis.level_series return.
"""
from __future__ import annotations

import threading
from pathlib import Path
from typing import Callable, Sequence

from PySide6.QtCore import QObject, QThreadPool, Signal
from PySide6.QtWidgets import (QAbstractItemView, QFileDialog, QHBoxLayout, QLabel, QProgressBar, QPushButton,
                               QTableWidget, QTableWidgetItem, QTabWidget, QVBoxLayout, QWidget)

from analysis.level_series import level_series
from analysis.pipeline import analyze_path, require_fit
from analysis.repeatability import Spread, repeatability
from app.level_series_view import LevelSeriesView
from app.job_book import failure_text

RECORDING_FILTER = "Recordings (*.wav *.json)"


class SeriesCancelled(Exception):
    pass


class SeriesWorker(QObject):
    """Runs one set at a time in a pool thread; signals carry the kind ("repeatability" or "levels")."""

    progress = Signal(str, int, int)        # kind, done, total
    finished = Signal(str, object)          # kind, result
    failed = Signal(str, str)               # kind, message

    def __init__(self, parent=None):
        super().__init__(parent)
        self.pool = QThreadPool(self)
        self.pool.setMaxThreadCount(1)
        # NB: set by the GUI thread, read by the pool thread between recordings.
        self.cancel_event = threading.Event()

    def start(self, kind: str, paths: Sequence[Path]) -> None:
        self.cancel_event = threading.Event()
        cancel = self.cancel_event
        self.pool.start(lambda: self._run(kind, list(paths), cancel))

    def cancel(self) -> None:
        self.cancel_event.set()

    def _analysed(self, kind: str, paths: list[Path], cancel: threading.Event) -> list:
        results = []
        for done, path in enumerate(paths):
            if cancel.is_set():
                raise SeriesCancelled()
            self.progress.emit(kind, done, len(paths))
            result = analyze_path(path)
            require_fit(result, f"be one of the {kind} results")
            results.append(result)
        return results

    def _run(self, kind: str, paths: list[Path], cancel: threading.Event) -> None:
        try:
            results = self._analysed(kind, paths, cancel)
            if kind == "repeatability":
                outcome = (repeatability([r.parameters for r in results]), len(results))
            else:
                outcome = level_series(results)
            self.finished.emit(kind, outcome)
        except SeriesCancelled:
            self.failed.emit(kind, "cancelled")
        except Exception as exc:  # noqa: BLE001 - the job runner is the GUI's error boundary (job_book)
            self.failed.emit(kind, failure_text(exc, f"the {kind} analysis"))


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
            cells = (s.name, shown(s.mean), shown(s.std, 2), "" if s.percent is None else f"{s.percent:.2g}",
                     shown(s.mean_fit_std, 2), s.display_unit, str(s.n))
            for col, text in enumerate(cells):
                self.setItem(row, col, QTableWidgetItem(text))
        self.resizeColumnsToContents()


class _SetPanel(QWidget):
    """A button to choose recordings, a progress line, and the result widget below."""

    def __init__(self, title: str, hint: str, result: QWidget, choose: Callable[[], None], cancel: Callable[[], None]):
        super().__init__()
        self.choose_button = QPushButton(title)
        self.choose_button.clicked.connect(choose)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.clicked.connect(cancel)
        self.cancel_button.setEnabled(False)
        self.progress = QProgressBar()
        self.progress.setVisible(False)
        self.status = QLabel(hint)
        self.status.setWordWrap(True)
        row = QHBoxLayout()
        for w in (self.choose_button, self.cancel_button, self.progress):
            row.addWidget(w)
        row.addStretch(1)
        layout = QVBoxLayout(self)
        layout.addLayout(row)
        layout.addWidget(self.status)
        layout.addWidget(result, 1)

    def busy(self, done: int, total: int) -> None:
        self.choose_button.setEnabled(False)
        self.cancel_button.setEnabled(True)
        self.progress.setVisible(True)
        self.progress.setRange(0, total)
        self.progress.setValue(done)
        self.status.setText(f"analysing recording {done + 1} of {total}…")

    def idle(self, message: str) -> None:
        self.choose_button.setEnabled(True)
        self.cancel_button.setEnabled(False)
        self.progress.setVisible(False)
        self.status.setText(message)


class SeriesPage(QTabWidget):
    """Repeatability and level series of several recordings."""

    # The level series' recordings, for the Large-signal page (the drift's reason: Bl(x), Kms(x), Le(x)).
    large_signal_requested = Signal(list)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.worker = SeriesWorker(self)
        self.level_paths: list[Path] = []
        self.repeat_table = RepeatabilityTable()
        self.levels_view = LevelSeriesView()
        self.panels = {
            "repeatability": _SetPanel("Choose repeated recordings…",
                                       "The same driver measured several times (remounted between): mean, standard "
                                       "deviation and percent per parameter.",
                                       self.repeat_table, lambda: self.on_choose("repeatability"), self.worker.cancel),
            "levels": _SetPanel("Choose recordings at rising levels…",
                                "The same driver at rising drive levels: the parameters and fs against peak "
                                "excursion.",
                                self.levels_view, lambda: self.on_choose("levels"), self.worker.cancel),
        }
        self.large_signal_button = QPushButton("Large-signal curves of these recordings…")
        self.large_signal_button.setToolTip("Bl(x), Kms(x) and Le(x) behind the drift, the coil's rest offset and the "
                                            "excursion limits, on the Large-signal page")
        self.large_signal_button.setEnabled(False)
        self.large_signal_button.clicked.connect(lambda: self.large_signal_requested.emit(list(self.level_paths)))
        self.panels["levels"].layout().itemAt(0).layout().insertWidget(2, self.large_signal_button)
        self.addTab(self.panels["repeatability"], "Repeatability")
        self.addTab(self.panels["levels"], "Level series")
        self.worker.progress.connect(self.on_progress)
        self.worker.finished.connect(self.on_finished)
        self.worker.failed.connect(self.on_failed)

    def on_choose(self, kind: str) -> None:
        paths, _ = QFileDialog.getOpenFileNames(self, "Choose recordings", "", RECORDING_FILTER)
        if paths:
            self.analyse(kind, [Path(p) for p in paths])

    def analyse(self, kind: str, paths: Sequence[Path]) -> None:
        stems = sorted({p.with_suffix("") for p in paths})
        if len(stems) < 2:
            self.panels[kind].idle("Choose at least two recordings: a spread needs more than one.")
            return
        self.panels[kind].busy(0, len(stems))
        if kind == "levels":
            self.level_paths = list(stems)
            self.large_signal_button.setEnabled(False)
        self.worker.start(kind, stems)

    def on_progress(self, kind: str, done: int, total: int) -> None:
        self.panels[kind].busy(done, total)

    def on_finished(self, kind: str, outcome) -> None:
        if kind == "repeatability":
            spreads, n = outcome
            self.repeat_table.set_spreads(spreads)
            self.panels[kind].idle(f"{n} recordings analysed.")
        else:
            self.levels_view.set_series(outcome)
            self.panels[kind].idle(f"{len(outcome.levels)} levels analysed.")
            self.large_signal_button.setEnabled(True)

    def on_failed(self, kind: str, message: str) -> None:
        self.panels[kind].idle(f"Not analysed: {message}")
