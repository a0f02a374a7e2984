"""The main window: menus, pages, the status bar, and the analysis of opened recordings."""
from __future__ import annotations

import time
from pathlib import Path

from PySide6.QtCore import Signal, Slot
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import (QFileDialog, QLabel, QMainWindow, QMessageBox, QProgressBar, QPushButton,
                               QTabWidget)

from app import style
from app.model_lab import ModelLab
from app.placeholders import PlaceholderPage
from app.results_view import ResultsView
from app.settings import Settings
from app.workers import AnalysisJob, AnalysisOutcome, AnalysisWorker

RECORDING_SUFFIXES = (".wav", ".json")
FILE_FILTER = "Recordings (*.wav *.json);;All files (*)"
PAGE_ORDER = ("Measure", "Results", "Model lab", "QA")
CLOSE_WAIT_MS = 5000        # a cancelled fit stops at its next iteration; this is ample


def recording_paths_from_urls(urls) -> list[Path]:
    """Local files among dropped URLs that look like a recording's .wav or .json."""
    paths = []
    for url in urls:
        if url.isLocalFile():
            path = Path(url.toLocalFile())
            if path.suffix.lower() in RECORDING_SUFFIXES:
                paths.append(path)
    return paths


class MainWindow(QMainWindow):
    analysis_started = Signal(str)           # path
    analysis_shown = Signal(object)          # AnalysisOutcome, after the results page shows it
    analysis_failed = Signal(str)            # the message shown to the user
    analysis_cancelled = Signal()

    def __init__(self, settings: Settings | None = None, parent=None):
        style.configure_pyqtgraph()
        super().__init__(parent)
        self.settings = settings or Settings()
        self.worker = AnalysisWorker(self)
        self.job: AnalysisJob | None = None     # the analysis whose outcome will be shown
        self._started_at = 0.0
        self.setWindowTitle("linpar")
        self.setAcceptDrops(True)

        self.results = ResultsView()
        self.model_lab = ModelLab()
        # The lab starts from each result the Results page shows; its versions go back there.
        self.results.result_changed.connect(self.model_lab.set_result)
        self.model_lab.model_adopted.connect(self.results.show_outcome)
        built = {"Results": self.results, "Model lab": self.model_lab}
        self.pages = QTabWidget()
        self.pages.setDocumentMode(True)
        for name in PAGE_ORDER:
            self.pages.addTab(built[name] if name in built else PlaceholderPage(name), name)
        self.pages.setCurrentWidget(self.results)
        self.setCentralWidget(self.pages)

        self._build_menus()
        self._build_status_bar()
        self.worker.progress.connect(self.on_progress)
        self.worker.finished.connect(self.on_finished)
        self.worker.failed.connect(self.on_failed)
        self.worker.cancelled.connect(self.on_cancelled)
        self._restore_window()

    # -- construction ------------------------------------------------------
    def _build_menus(self) -> None:
        file_menu = self.menuBar().addMenu("&File")
        self.open_action = QAction("&Open recording…", self, shortcut=QKeySequence.Open)
        self.open_action.triggered.connect(self.on_open)
        file_menu.addAction(self.open_action)
        self.recent_menu = file_menu.addMenu("Open &recent")
        file_menu.addSeparator()
        self.quit_action = QAction("&Quit", self, shortcut=QKeySequence("Ctrl+Q"))
        self.quit_action.triggered.connect(self.close)
        file_menu.addAction(self.quit_action)
        self._rebuild_recent_menu()

    def _build_status_bar(self) -> None:
        bar = self.statusBar()
        self.status_label = QLabel("No recording loaded")
        bar.addWidget(self.status_label, 1)
        self.progress = QProgressBar()
        self.progress.setRange(0, 0)         # the fit reports no fraction: a busy indicator
        self.progress.setMaximumWidth(160)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.setToolTip("Stop the analysis; the results shown so far stay")
        self.cancel_button.clicked.connect(self.on_cancel)
        for widget in (self.progress, self.cancel_button):
            bar.addPermanentWidget(widget)
            widget.hide()

    def _restore_window(self) -> None:
        geometry, state = self.settings.window_geometry()
        if geometry is None or not self.restoreGeometry(geometry):
            self.resize(1400, 900)
        if state is not None:
            self.restoreState(state)

    def _rebuild_recent_menu(self) -> None:
        self.recent_menu.clear()
        files = self.settings.recent_files()
        for index, path in enumerate(files, start=1):
            action = self.recent_menu.addAction(f"&{index} {Path(path).name}")
            action.setToolTip(path)
            action.setData(path)
            action.triggered.connect(self.on_recent)
        if files:
            self.recent_menu.addSeparator()
            self.recent_menu.addAction("Clear list", self.on_clear_recent)
        self.recent_menu.setEnabled(bool(files))

    # -- opening and analysing ---------------------------------------------
    @property
    def busy(self) -> bool:
        return self.job is not None

    def open_path(self, path: str | Path) -> None:
        """Analyse `path` in a worker thread; a running analysis is cancelled and its outcome ignored."""
        if self.job is not None:
            self.job.cancel()
        path = Path(path)
        self._started_at = time.monotonic()
        self.job = self.worker.start(path)
        self._set_busy(True, f"Analysing {path.name}…")
        self.pages.setCurrentWidget(self.results)
        self.analysis_started.emit(str(path))

    def _take(self, job: int) -> AnalysisJob | None:
        """The current job if `job` is it (and forget it); None for an outcome to drop."""
        if self.job is None or self.job.id != job:
            return None
        current, self.job = self.job, None
        self._set_busy(False)
        return current

    @Slot(int, str)
    def on_progress(self, job: int, stage: str) -> None:
        if self.job is not None and self.job.id == job:
            self.status_label.setText(stage[:1].upper() + stage[1:] + "…")

    @Slot(int, object)
    def on_finished(self, job: int, outcome: AnalysisOutcome) -> None:
        if self._take(job) is None:
            return
        elapsed = time.monotonic() - self._started_at
        self.results.show_outcome(outcome)
        self.settings.add_recent_file(outcome.path)
        self._rebuild_recent_menu()
        self.setWindowTitle(f"linpar — {outcome.path.name}")
        self.status_label.setText(f"Loaded {outcome.path} — model {outcome.result.fit.model.describe()}, "
                                  f"analysed in {elapsed:.2g} s")
        self.analysis_shown.emit(outcome)

    @Slot(int, str)
    def on_failed(self, job: int, message: str) -> None:
        current = self._take(job)
        if current is None:
            return
        shown = self.results.result
        still = f"; still showing {shown.source.name}" if shown is not None and shown.source else ""
        self.status_label.setText(f"Could not analyse {current.path.name}{still}")
        if not current.path.exists():          # a recent file that has gone: do not offer it again
            self.settings.remove_recent_file(str(current.path.resolve()))
            self._rebuild_recent_menu()
        self.show_error(f"Cannot analyse {current.path.name}", message)
        self.analysis_failed.emit(message)

    @Slot(int)
    def on_cancelled(self, job: int) -> None:
        if self._take(job) is None:
            return
        self.status_label.setText("Analysis cancelled")
        self.analysis_cancelled.emit()

    @Slot()
    def on_cancel(self) -> None:
        if self.job is not None:
            self.job.cancel()
            self.status_label.setText("Cancelling…")

    def _set_busy(self, busy: bool, text: str = "") -> None:
        self.progress.setVisible(busy)
        self.cancel_button.setVisible(busy)
        if busy:
            self.status_label.setText(text)
            self.results.set_busy(text)
        else:
            self.results.set_idle()

    def show_error(self, title: str, message: str) -> None:
        """The message only: tracebacks go to the log, never to the user."""
        QMessageBox.warning(self, title, message)

    # -- slots of the menus ------------------------------------------------
    @Slot()
    def on_open(self) -> None:
        recent = self.settings.recent_files()
        start = str(Path(recent[0]).parent) if recent else ""
        path, _ = QFileDialog.getOpenFileName(self, "Open recording", start, FILE_FILTER)
        if path:
            self.open_path(path)

    @Slot()
    def on_recent(self) -> None:
        action = self.sender()
        if action is not None and action.data():
            self.open_path(action.data())

    @Slot()
    def on_clear_recent(self) -> None:
        self.settings.clear_recent_files()
        self._rebuild_recent_menu()

    # -- drag and drop -----------------------------------------------------
    def dragEnterEvent(self, event) -> None:
        if recording_paths_from_urls(event.mimeData().urls()):
            event.acceptProposedAction()
        else:
            event.ignore()

    def dragMoveEvent(self, event) -> None:
        self.dragEnterEvent(event)

    def dropEvent(self, event) -> None:
        paths = recording_paths_from_urls(event.mimeData().urls())
        if paths:
            event.acceptProposedAction()
            self.open_path(paths[0])     # a recording is one file pair: open the first

    # -- closing -----------------------------------------------------------
    def closeEvent(self, event) -> None:
        self.worker.shutdown(CLOSE_WAIT_MS)
        self.model_lab.shutdown(CLOSE_WAIT_MS)
        self.settings.save_window(self.saveGeometry(), self.saveState())
        super().closeEvent(event)
