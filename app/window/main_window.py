"""The main window: menus, pages, the status bar, and the analysis of opened recordings."""
from __future__ import annotations

import dataclasses
import time
from pathlib import Path

from PySide6.QtCore import Signal, Slot
from PySide6.QtWidgets import QFileDialog, QMainWindow, QMessageBox, QTabWidget

from app.widgets import style
from app.archive.page import ArchivePage
from app.jobs.controls import JobControls
from app.widgets.elided_label import ElidedLabel
from app.large_signal.page import LargeSignalPage
from app.window.menus import Menus
from app.window.page_settle import settle_on_switch
from app.model_lab.page import ModelLab
from app.production.page import ProductionPage
from app.qa.view import QAView
from app.results.view import ResultsView
from app.live.series_page import SeriesPage
from app.window.settings import Settings
from app.window.unfinished import ask_unfinished, offer_unfinished
from app.jobs.next_turn import in_a_later_turn
from app.jobs.staged_fanout import StagedFanOut
from app.window.window_fit import fit_window
from app.wizard import MeasureWizard
from app.wizard.archive_meta import measurement_meta
from app.jobs.workers import AnalysisOutcome, AnalysisWorker
from app.jobs.curves import CurvesRequest
from app.window.open_curves import OpenCurvesDialog

RECORDING_SUFFIXES = (".wav", ".json")
FILE_FILTER = "Recordings (*.wav *.json);;All files (*)"
PAGE_ORDER = ("Measure", "Results", "Model lab", "Series", "Large signal", "QA", "Production", "Archive")
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
    measurement_shown = Signal(object)       # MeasureOutcome, after the Results page shows it
    # AnalysisOutcome with the model part of its uncertainties, after the Results page (and so QA) shows it;
    # at once for a result whose model describes its data (nothing to refit).
    model_part_shown = Signal(object)

    def __init__(self, settings: Settings | None = None, parent=None):
        style.configure_pyqtgraph()
        super().__init__(parent)
        self.settings = settings or Settings()
        self.worker = AnalysisWorker(self)
        # The model part's jobs by id (start_model_part): what to do once each ends, however it ends.
        self._model_part_jobs: dict[int, tuple] = {}
        self._started_at = 0.0
        self.setWindowTitle("linpar")
        self.setWindowIcon(style.app_icon())
        self.setAcceptDrops(True)

        self.results = ResultsView()
        self.model_lab = ModelLab()
        # The lab starts from each result the Results page shows; its versions go back there.
        self.model_lab.model_adopted.connect(self.on_model_adopted)
        self.wizard = MeasureWizard(self.settings.qsettings)
        self.qa = QAView(self.settings.qsettings)
        # Reports are written by the QA page from any page (File > Export report…): the window says how it went.
        self.qa.report_written.connect(lambda written: self.status_label.setText(f"Report written: {written}"))
        self.qa.report_failed.connect(lambda why: self.show_error("Could not write the report", why))
        # A finished measurement goes to the Results page, and from there to the lab and QA.
        self.wizard.measurement_finished.connect(self.on_measured)
        self.wizard.open_results_requested.connect(self.on_open_measured)
        # The lab and QA follow the Results page, each in its own turn of the event loop (app/jobs/staged_fanout.py).
        self.result_pages = StagedFanOut([self.model_lab.setting_result, self.qa.set_result], self)
        self.results.result_changed.connect(self.result_pages.send)
        self.series = SeriesPage()
        self.large_signal = LargeSignalPage()
        self.series.large_signal_requested.connect(self.on_large_signal_requested)
        self.wizard.large_signal_finished.connect(self.on_large_signal_measured)
        # Every measurement the wizard finishes is stored in the archive; an archived one opens like a file.
        self.archive = ArchivePage(self.settings)
        self.archive.open_requested.connect(self.on_open_archived)
        self.archive.stored.connect(self.on_archived)
        self.archive.store_failed.connect(self.on_archive_failed)
        self._titles: dict[Path, str] = {}      # recording path -> what the title bar calls it (archived ones)
        # Statistics over the archive's units: the line's drift, Cpk, the stations (app/production/page.py).
        self.production = ProductionPage(self.settings)
        built = {"Measure": self.wizard, "Results": self.results, "Model lab": self.model_lab,
                 "Series": self.series, "Large signal": self.large_signal, "QA": self.qa,
                 "Production": self.production, "Archive": self.archive}
        self.pages = QTabWidget()
        self.pages.setDocumentMode(True)
        for name in PAGE_ORDER:
            self.pages.addTab(built[name], name)
        # A first start (no window saved yet) opens on the wizard's first step: a newcomer starts by measuring.
        first_start = self.settings.window_geometry()[0] is None
        self.pages.setCurrentWidget(self.wizard if first_start else self.results)
        self.setCentralWidget(self.pages)
        settle_on_switch(self.pages)            # a page switched to is laid out and painted once

        self._build_menus()
        self._build_status_bar()
        # After the status bar's job controls: the Results page shows a model part before this hears of it.
        for ended in (self.worker.finished, self.worker.failed, self.worker.cancelled):
            ended.connect(self._model_part_ended)
        self._restore_window()

    # -- construction ------------------------------------------------------
    def _build_menus(self) -> None:
        self.menus = Menus(self)            # File, View, Help (app/window/menus.py)
        self.open_action, self.quit_action = self.menus.open_action, self.menus.quit_action
        self.results.result_changed.connect(self.menus.update)
        self._rebuild_recent_menu()

    def _build_status_bar(self) -> None:
        bar = self.statusBar()
        # One line each, cut with "…" and whole in the tooltip: the bar has room for no second line, and a
        # long path must not widen the window.
        self.status_label = ElidedLabel("No recording loaded")
        bar.addWidget(self.status_label, 1)
        # The analysis of an opened recording: its stage, a busy indicator and Cancel.
        self.jobs = JobControls(self.worker, cancel_tip="Stop the analysis; the results shown so far stay",
                                bar_width=160, one_line=True)
        self.jobs.busy_changed.connect(lambda busy: self.results.set_busy(self.jobs.text.text()) if busy
                                       else self.results.set_idle())
        bar.addPermanentWidget(self.jobs)

    def _restore_window(self) -> None:
        geometry, state = self.settings.window_geometry()
        restored = geometry is not None and self.restoreGeometry(geometry)
        if state is not None:
            self.restoreState(state)
        # At most the screen's room, maximized on a small screen; a size remembered elsewhere is clamped.
        fit_window(self, restored)

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
        return self.jobs.busy

    @Slot(list)
    def on_large_signal_requested(self, paths: list) -> None:
        """The Series page's level series, identified on the Large-signal page."""
        self.pages.setCurrentWidget(self.large_signal)
        self.large_signal.analyse(paths)

    @Slot(object)
    def on_large_signal_measured(self, done) -> None:
        """The wizard's large-signal plan, identified: shown on the Large-signal page."""
        self.large_signal.show_result(done.result)
        self.pages.setCurrentWidget(self.large_signal)

    def open_path(self, path: str | Path) -> None:
        """Analyse `path` in a worker thread; a running analysis is cancelled and its outcome ignored."""
        path = Path(path)
        self._started_at = time.monotonic()
        self.status_label.setText("")            # the job controls beside it say what is being done
        self.jobs.run(self.worker.start(path), f"Analysing {path.name}…", self.on_finished,
                      lambda message: self.on_failed(path, message), self.on_cancelled)
        self.pages.setCurrentWidget(self.results)
        self.analysis_started.emit(str(path))

    def open_curves(self, request: CurvesRequest) -> None:
        """Analyse imported curves (File > Open curves…) in a worker thread, as open_path a recording."""
        self._started_at = time.monotonic()
        self.status_label.setText("")
        self.jobs.run(self.worker.start_curves(request), f"Analysing {request.name}…", self.on_finished,
                      lambda message: self.on_failed(request.path, message), self.on_cancelled)
        self.pages.setCurrentWidget(self.results)
        self.analysis_started.emit(str(request.path))

    def on_finished(self, outcome: AnalysisOutcome) -> None:
        elapsed = time.monotonic() - self._started_at
        self.results.show_outcome(outcome)
        if hasattr(outcome.result, "spectra"):      # Open recent opens recordings, not imported curves
            self.settings.add_recent_file(outcome.path)
            self._rebuild_recent_menu()
        self.setWindowTitle(f"linpar — {self._titles.get(outcome.path, outcome.path.name)}")
        fit = outcome.result.fit
        model = "fitted" if fit is not None else "nothing could be fitted"
        self.status_label.setText(f"Loaded {outcome.path} — {model}, analysed in {elapsed:.2g} s")
        self.result_pages.after(lambda: (self.analysis_shown.emit(outcome), self.start_model_part(outcome)))

    # -- the model part of the uncertainties (analysis.fit.model_uncertainty) -------------------------------
    def start_model_part(self, outcome: AnalysisOutcome, then=None) -> None:
        """Refit `outcome` (shown) with the other forms of its model in the background; the Results page says
        "Model part: estimating…" meanwhile. `then(outcome)` runs once with whatever outcome is final: the one
        with its model part, or `outcome` itself when nothing needs refitting or the refits fail or are cancelled
        (also when another job replaces this one in the status bar: it listens to the runner, not to that)."""
        from analysis.fit.model_uncertainty import pending
        if not pending(outcome.result):
            self.model_part_shown.emit(outcome)
            if then is not None:
                then(outcome)
            return
        job = self.worker.start_model_part(outcome)
        self._model_part_jobs[job.id] = (outcome, then, time.monotonic())
        self.jobs.run(job, "Model part: estimating…", self.on_model_part,
                      lambda message: self.status_label.setText(
                          f"The model part of the uncertainties could not be estimated: {message}"))

    def on_model_part(self, final: AnalysisOutcome) -> None:
        shown = self.results.show_model_part(final)
        self.wizard.model_part_arrived(final)
        started = self._model_part_jobs.get(final.job, (None, None, time.monotonic()))[2]
        if shown:
            self.status_label.setText(f"{self.status_label.text()}; the model part of the uncertainties "
                                      f"{time.monotonic() - started:.2g} s later")

    def _model_part_ended(self, job: int, final: object = None) -> None:
        """Whatever became of a model part's job (the runner's signal): its `then`, and model_part_shown."""
        entry = self._model_part_jobs.pop(job, None)
        if entry is None:
            return
        outcome, then, _started = entry
        if isinstance(final, AnalysisOutcome):
            done = final
        else:
            # Cancelled or failed: the page says so (QA then judges on the noise alone, and says that too);
            # `then` gets the result as it was, so that the archive's store estimates the part itself.
            from analysis.fit.model_uncertainty import NOT_ESTIMATED, ModelPart, with_estimated
            why = "cancelled" if final is None else f"the refits failed: {final}"
            part = ModelPart(state=NOT_ESTIMATED, why=why)
            done = dataclasses.replace(outcome, result=with_estimated(outcome.result, part))
            self.results.show_model_part(done)
            self.wizard.model_part_arrived(done)
        # Once the lab and QA have it too (the Results page sent it on: show_model_part), as analysis_shown.
        self.result_pages.after(lambda: self._model_part_done(done, then, done if done is final else outcome))

    def _model_part_done(self, final: AnalysisOutcome, then, stored: AnalysisOutcome) -> None:
        if then is not None:
            then(stored)
        self.model_part_shown.emit(final)

    def on_model_adopted(self, outcome: AnalysisOutcome) -> None:
        """A version of the Model lab's, adopted: shown, and its model part estimated as for an opened file's.

        The Results page fills in turns of its own (show_outcome_in_turns): the lab has just drawn the new version,
        and the Results page's update of it (~25 ms of the GUI thread) came in the same turn after a refit that a
        checkbox asked for."""
        self.results.show_outcome_in_turns(
            outcome, then=lambda: self.result_pages.after(lambda: self.start_model_part(outcome)))

    def on_failed(self, path: Path, message: str) -> None:
        shown = self.results.result
        still = f"; still showing {shown.source.name}" if shown is not None and shown.source else ""
        self.status_label.setText(f"Could not analyse {path.name}{still}")
        if not path.exists():          # a recent file that has gone: do not offer it again
            self.settings.remove_recent_file(str(path.resolve()))
            self._rebuild_recent_menu()
        self.show_error(f"Cannot analyse {path.name}", message)
        self.analysis_failed.emit(message)

    def on_cancelled(self) -> None:
        self.status_label.setText("Analysis cancelled")
        self.analysis_cancelled.emit()

    def show_error(self, title: str, message: str) -> None:
        """The message only: tracebacks go to the log, never to the user."""
        QMessageBox.warning(self, title, message)

    # -- measurements of the wizard -----------------------------------------
    @Slot(object)
    def on_measured(self, outcome) -> None:
        """A measurement the wizard finished: shown (it is already analysed), and remembered.

        In the next turn of the event loop: the wizard's own page updates first, so the two do not add
        up to one long stall of the GUI (the Results page took ~30 ms to show it, the lab as much again: both
        now fill in steps of their own turns, ResultsView.show_outcome_in_turns and ModelLab.setting_result).
        """
        self.jobs.drop()                    # an opened file still being analysed would replace it: drop that
        in_a_later_turn(self, lambda: self._show_measured(outcome))

    def _show_measured(self, outcome) -> None:
        self.results.show_outcome_in_turns(outcome.analysis, lambda: self._measured_shown(outcome))
        self.settings.add_recent_file(outcome.path)
        self._rebuild_recent_menu()
        self.setWindowTitle(f"linpar — {outcome.path.name}")
        self.status_label.setText(f"Measured {outcome.path}; storing it in the archive…")

    def _measured_shown(self, outcome) -> None:
        # Stored once the lab and QA have it (the store's thread would slow their setting up: the GIL), and
        # with the model part of its uncertainties once that is estimated (the archive's record, like the CLI's).
        self.result_pages.after(lambda: (self.measurement_shown.emit(outcome), self.start_model_part(
            outcome.analysis, lambda analysis: self._store_measured(dataclasses.replace(outcome, analysis=analysis)))))

    def _store_measured(self, outcome) -> None:
        """Into the archive, in its worker. Whatever happens there, the recording stays where it was written."""
        self.archive.store_measurement(outcome.path, outcome.analysis.result, measurement_meta(outcome.request))

    @Slot(str, str)
    def on_archived(self, measurement_id: str, recording: str) -> None:
        self.status_label.setText(f"Measured {recording}; stored in the archive as {measurement_id}")

    @Slot(str, str)
    def on_archive_failed(self, message: str, recording: str) -> None:
        self.status_label.setText(f"Measured {recording}, but NOT stored in the archive ({message}); "
                                  "the recording stays where it was written")

    @Slot(object, str)
    def on_open_archived(self, path: Path, title: str) -> None:
        self._titles[Path(path)] = title
        self.open_path(path)

    @Slot(object)
    def on_open_measured(self, outcome: AnalysisOutcome) -> None:
        if self.results.result is None or self.results.result.source != outcome.result.source:
            self.results.show_outcome(outcome)
        self.pages.setCurrentWidget(self.results)

    # -- measurements that a crash cut short ----------------------------------
    def measurement_folder(self) -> Path:
        """Where the wizard writes its recordings (and where their crash journals are)."""
        from app.wizard.measure_page import OUT_DIR_KEY, default_out_dir
        saved = self.settings.qsettings.value(OUT_DIR_KEY, "")
        return Path(saved) if saved else default_out_dir()

    @Slot()
    def offer_unfinished(self, directory: Path | None = None) -> list[str]:
        """Offer each measurement whose process died before writing it: keep it, analyse it, or discard it
        (app.window.unfinished). Returns the choices made, in order (for tests and the log)."""
        return offer_unfinished(directory or self.measurement_folder(), ask=self.ask_unfinished,
                                open_path=self.open_path, say=self.status_label.setText, show_error=self.show_error)

    def ask_unfinished(self, unfinished) -> str:
        """'analyse', 'keep', 'discard' or 'later' (asked again at the next start)."""
        return ask_unfinished(self, unfinished)

    # -- slots of the menus ------------------------------------------------
    @Slot()
    def on_open(self) -> None:
        recent = self.settings.recent_files()
        start = str(Path(recent[0]).parent) if recent else ""
        path, _ = QFileDialog.getOpenFileName(self, "Open recording", start, FILE_FILTER)
        if path:
            self.open_path(path)

    @Slot()
    def on_open_curves(self) -> None:
        recent = self.settings.recent_files()
        dialog = OpenCurvesDialog(str(Path(recent[0]).parent) if recent else "", self)
        if dialog.exec() == OpenCurvesDialog.Accepted:
            self.open_curves(dialog.request())

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
        # One deadline for all: a job that cannot stop midway (a large-signal fit) costs the close at most once.
        deadline = time.monotonic() + CLOSE_WAIT_MS / 1000
        for part in (self.worker, self.model_lab, self.wizard, self.qa, self.archive, self.production, self.series,
                     self.large_signal):
            part.shutdown(max(0, int(1000 * (deadline - time.monotonic()))))
        self.settings.save_window(self.saveGeometry(), self.saveState())
        super().closeEvent(event)
