"""The Archive page: the stored measurements, filtered as one types; open one, compare up to eight.

The archive is a folder, or the line's PostgreSQL server when $LINPAR_ARCHIVE_URL
names one (it then wins over the folder chosen here, as on the command line).
A folder's list is read on the GUI thread: the index answers 1000 entries in ~0.1 s
(a stale index on a read-only archive is rebuilt in memory from the folders
each time, 0.4 s for 1000: rare, and then the page is slow to filter); a
server's is read in app.archive.worker, since the network may be slow or
gone. Storing, comparing (it reads every results file) and rebuilding the
index (for a server: sending the station's queue) run there too. Open hands the stored recording to the main window,
which analyses it again like any opened file: the Results page, the Model lab
and QA then have a full analysis (a stored results file has no covariance to
refit or diagnose from). Every archive error is one line on the page.
"""
from __future__ import annotations

import html
import os
from pathlib import Path

from PySide6.QtCore import QItemSelection, QItemSelectionModel, Qt, QTimer, Signal
from PySide6.QtWidgets import (QFileDialog, QHBoxLayout, QLabel, QPushButton, QSizePolicy, QTabWidget, QVBoxLayout,
                               QWidget)

from analysis.archive import MAX_COMPARED, ArchiveError, archive_spec, is_url, open_archive
from analysis.archive.backends import URL_ENV, shown
from app.widgets import style
from app.archive.filter import FilterBar
from app.archive.overlay import CompareView
from app.archive.table import ArchiveTable
from app.archive.worker import ArchiveWorker
from app.jobs.book import failure_text
from app.jobs.controls import JobControls


FILTER_DELAY_MS = 250           # typing a serial number should not list the archive once per key
LIST_LIMIT = 2000               # newest first; more than this is a filter's job, not a scroll bar's
ROOT_KEY = "archive/root"       # in the window's QSettings: the folder chosen on this page
COLOURS = {"error": style.VALIDITY_COLOURS["red"][1], "note": style.VALIDITY_COLOURS["yellow"][1],
           "info": style.VALIDITY_COLOURS["unknown"][1]}


def archive_source(qsettings) -> str:
    """$LINPAR_ARCHIVE_URL, else the folder chosen on the page, else analysis.archive's default
    ($LINPAR_ARCHIVE, else the archive in the platform's data folder)."""
    url = os.environ.get(URL_ENV, "").strip()
    if url:
        return url
    saved = qsettings.value(ROOT_KEY, "")
    return str(Path(saved).expanduser()) if isinstance(saved, str) and saved else archive_spec()


class ArchivePage(QWidget):
    open_requested = Signal(object, str)    # the stored recording's path, a label for the window title
    listed = Signal(int)                    # the number of measurements the table now shows
    stored = Signal(str, str)               # the id of a measurement stored, the recording it was stored from
    store_failed = Signal(str, str)         # why a measurement was not stored (one line), its recording
    comparison_shown = Signal(object)       # app.archive.worker.ComparisonData
    rebuilt = Signal(str)                   # the rebuild's report

    def __init__(self, settings, parent=None):
        super().__init__(parent)
        self.settings = settings
        self.worker = ArchiveWorker(self)
        # A comparison or a rebuild the user asked for: what it does, a busy indicator and Cancel. Stores (after a
        # measurement) and a server's listing run unseen: the page says how they went.
        self.jobs = JobControls(self.worker, cancel_tip="Stop loading; the table shown stays", bar_width=120)
        self.jobs.busy_changed.connect(lambda busy: self.rebuild_button.setEnabled(not busy))
        self._jobs: dict[int, str] = {}      # job id -> what a background job does, for its failure's message
        self._storing: dict[int, Path] = {}  # job id -> the recording being stored
        self._list_job = None               # the archive Job listing a server (the newest asked for)
        self._list_error = False

        self.root_label = QLabel()
        self.root_label.setTextFormat(Qt.PlainText)
        self.root_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        # A long path must not set the window's minimum width: it is cut, and whole in the tooltip.
        self.root_label.setSizePolicy(QSizePolicy.Ignored, QSizePolicy.Preferred)
        self.root_button = QPushButton("Change…")
        self.root_button.setToolTip("Choose the archive's folder (shared by the people at this station)")
        self.rebuild_button = QPushButton("Rebuild index")
        self.rebuild_button.setToolTip("Read every measurement folder again and rebuild the index from them")
        self.refresh_button = QPushButton("Refresh")

        self.filters = FilterBar()

        self.message = QLabel()
        self.message.setWordWrap(True)
        self.message.setTextFormat(Qt.RichText)
        self.message.hide()
        self.table = ArchiveTable()
        self.count_label = QLabel()
        self.count_label.setWordWrap(True)      # "The archive is empty: ..." must not widen the window
        self.selection_label = QLabel()
        self.open_button = QPushButton("Open")
        self.open_button.setToolTip("Analyse the stored recording again and show it on the Results page "
                                    "(double-click a row does the same)")
        self.compare_button = QPushButton("Compare")
        self.compare_button.setToolTip(f"Overlay the curves and tabulate the parameters of up to {MAX_COMPARED} "
                                       "selected measurements (Ctrl- or Shift-click to select several)")
        self.compare_view = CompareView()
        self.tabs = QTabWidget()
        self._build_layout()

        self.filter_timer = QTimer(self)
        self.filter_timer.setSingleShot(True)
        self.filter_timer.setInterval(FILTER_DELAY_MS)
        self.filter_timer.timeout.connect(self.refresh_now)
        self.filters.changed.connect(self.refresh)
        self.root_button.clicked.connect(self.on_choose_root)
        self.rebuild_button.clicked.connect(self.on_rebuild)
        self.refresh_button.clicked.connect(self.refresh_now)
        self.open_button.clicked.connect(self.on_open)
        self.compare_button.clicked.connect(self.on_compare)
        self.table.doubleClicked.connect(lambda _index: self.on_open())
        self.table.selectionModel().selectionChanged.connect(self.on_selection_changed)
        self.worker.stored.connect(self.on_stored)
        self.worker.listed.connect(self.on_listed)
        self.worker.failed.connect(self.on_failed)
        self.worker.cancelled.connect(self.on_cancelled)
        self._show_root()
        self.on_selection_changed()

    def _build_layout(self) -> None:
        top = QHBoxLayout()
        top.addWidget(QLabel("<b>Archive</b>"))
        top.addWidget(self.root_label, 1)
        top.addWidget(self.jobs)
        for button in (self.root_button, self.rebuild_button, self.refresh_button):
            top.addWidget(button)
        actions = QHBoxLayout()
        actions.addWidget(self.count_label, 1)
        actions.addWidget(self.selection_label)
        actions.addWidget(self.open_button)
        actions.addWidget(self.compare_button)
        list_tab = QWidget()
        list_layout = QVBoxLayout(list_tab)
        list_layout.addWidget(self.filters)
        list_layout.addWidget(self.table, 1)
        list_layout.addLayout(actions)
        self.list_tab = list_tab
        self.tabs.addTab(list_tab, "Measurements")
        self.tabs.addTab(self.compare_view, "Comparison")
        layout = QVBoxLayout(self)
        layout.addLayout(top)
        layout.addWidget(self.message)
        layout.addWidget(self.tabs, 1)

    # -- the archive's folder (or server) ----------------------------------------
    @property
    def source(self) -> str:
        """The archive this page shows and stores into: a folder, or a postgresql:// URL."""
        return archive_source(self.settings.qsettings)

    @property
    def on_server(self) -> bool:
        return is_url(self.source)

    def set_root(self, path: str | Path) -> None:
        self.settings.qsettings.setValue(ROOT_KEY, str(path))
        self.settings.qsettings.sync()
        self._show_root()
        self.jobs.drop()                    # a comparison (or rebuild) of the other archive still running
        self.compare_view.clear()           # those were measurements of the other archive
        self.tabs.setCurrentWidget(self.list_tab)
        self.refresh_now()

    def _show_root(self) -> None:
        where = shown(self.source)
        self.root_label.setText(where)
        self.root_label.setToolTip(f"{where}\nEvery measurement finished on the Measure page is stored here")
        by_env = bool(os.environ.get(URL_ENV, "").strip())
        self.root_button.setEnabled(not by_env)
        self.root_button.setToolTip("The line's server, set by $LINPAR_ARCHIVE_URL for this station" if by_env else
                                    "Choose the archive's folder (shared by the people at this station)")
        self.rebuild_button.setText("Send queue" if self.on_server else "Rebuild index")
        self.rebuild_button.setToolTip("Send the measurements this station stored while the server could not be "
                                       "reached" if self.on_server else
                                       "Read every measurement folder again and rebuild the index from them")

    def on_choose_root(self) -> None:
        folder = QFileDialog.getExistingDirectory(self, "Archive folder", self.source)
        if folder:
            self.set_root(folder)

    # -- messages --------------------------------------------------------------
    def show_message(self, text: str, kind: str = "info") -> None:
        self.message.setText(f"<span style='color:{COLOURS[kind]}'>{html.escape(text)}</span>")
        self.message.setToolTip(text)
        self.message.setVisible(bool(text))

    def clear_message(self) -> None:
        self.message.clear()
        self.message.hide()

    def _error_text(self, exc: Exception) -> str:
        return failure_text(exc, f"reading the archive {shown(self.source)}")

    # -- listing -----------------------------------------------------------------
    def refresh(self, *_args) -> None:
        """List again once the typing stops."""
        self.filter_timer.start()

    def refresh_now(self) -> int:
        """List the archive with the filter now; the number of measurements shown."""
        self.filter_timer.stop()
        source = self.source
        self._show_root()
        if is_url(source):
            if self._list_job is not None:
                self._list_job.cancel()
            self._list_job = self.worker.list(source, self.filters.filter(LIST_LIMIT + 1))
            self._jobs[self._list_job.id] = "list"
            self.count_label.setText("Reading the archive's server…")
            return 0
        try:
            archive = open_archive(source)
            entries = archive.list(self.filters.filter(LIST_LIMIT + 1))
        except Exception as exc:  # noqa: BLE001 - every error is a message on the page
            self._list_failed(self._error_text(exc))
            return 0
        return self._show_entries(entries, archive.notes)

    def on_listed(self, job: int, listed) -> None:
        self._jobs.pop(job, None)
        if self._list_job is not None and job == self._list_job.id:
            self._list_job = None
            self._show_entries(list(listed.entries), listed.notes)

    def _list_failed(self, message: str) -> None:
        self.table.set_entries([])
        self.count_label.setText("")
        self.show_message(f"Cannot read the archive in {shown(self.source)}: {message}", "error")
        self._list_error = True
        self.listed.emit(0)

    def _show_entries(self, entries: list, notes) -> int:
        keep = {e.id for e in self.table.selected_entries()}
        if self._list_error:
            self.clear_message()
            self._list_error = False
        if notes:
            self.show_message(("" if self.on_server else "The index was repaired: ") + "; ".join(notes), "note")
        more = len(entries) > LIST_LIMIT
        entries = entries[:LIST_LIMIT]
        self.table.set_entries(entries)
        self._reselect(keep)
        self.count_label.setText(self._count_text(len(entries), more))
        self.listed.emit(len(entries))
        return len(entries)

    def _count_text(self, n: int, more: bool) -> str:
        filtered = self.filters.active
        if n == 0 and not filtered:
            return ("The archive is empty" if self.on_server or Path(self.source).is_dir()
                    else "No archive in this folder yet") + \
                ": every measurement finished on the Measure page is stored here."
        if n == 0:
            return "No measurement matches the filter."
        if more:
            return f"The newest {n} measurements{' that match' if filtered else ''}: narrow the filter to see older ones."
        return f"{n} measurement{'s' if n != 1 else ''}{' match the filter' if filtered else ''}."

    def _reselect(self, ids: set[str]) -> None:
        if not ids:
            return
        selection = QItemSelection()
        for row in range(self.table.proxy.rowCount()):
            if self.table.entry_at(row).id in ids:
                index = self.table.proxy.index(row, 0)
                selection.select(index, index)
        self.table.selectionModel().select(selection, QItemSelectionModel.Select | QItemSelectionModel.Rows)

    def on_selection_changed(self, *_args) -> None:
        n = len(self.table.selectionModel().selectedRows())
        self.open_button.setEnabled(n >= 1)
        self.compare_button.setEnabled(n >= 1)
        if n > MAX_COMPARED:
            self.selection_label.setText(f"<span style='color:{COLOURS['error']}'>{n} selected: at most "
                                         f"{MAX_COMPARED} can be compared</span>")
        else:
            self.selection_label.setText(f"{n} selected" if n else "")

    def showEvent(self, event) -> None:
        super().showEvent(event)
        self.refresh_now()          # another program (linpar archive store) may have added some

    # -- open and compare ----------------------------------------------------------
    def on_open(self) -> Path | None:
        entry = self.table.current_entry()
        if entry is None:
            self.show_message("Select the measurement to open.", "error")
            return None
        try:
            measurement = open_archive(self.source).get(entry.id)
            path = measurement.recording_path()
            if path is None or not path.is_file():
                raise ArchiveError(f"{measurement.folder}: the recording is missing")
        except Exception as exc:  # noqa: BLE001 - every error is a message on the page
            self.show_message(f"Cannot open {entry.id}: {self._error_text(exc)}", "error")
            return None
        label = " ".join(x for x in (entry.driver, entry.serial) if x) or entry.id
        self.show_message(f"Opened {label} ({entry.id}): its stored recording is analysed again for the "
                          "Results page.", "info")
        self.open_requested.emit(path, f"{label} (archive {entry.measured_at[:10]})")
        return path

    def on_compare(self) -> None:
        entries = self.table.selected_entries()
        if not entries:
            self.show_message("Select the measurements to compare (Ctrl- or Shift-click).", "error")
            return
        if len(entries) > MAX_COMPARED:
            self.show_message(f"{len(entries)} measurements are selected, but at most {MAX_COMPARED} can be "
                              f"compared: deselect {len(entries) - MAX_COMPARED}.", "error")
            return
        self.clear_message()
        # A comparison or rebuild still running is replaced: its outcome is dropped.
        self.jobs.run(self.worker.compare(self.source, [e.id for e in entries]),
                      f"Loading {len(entries)} measurement{'s' if len(entries) != 1 else ''}…", self.on_compared,
                      lambda message: self.show_message(f"Cannot compare: {message}", "error"))

    def on_compared(self, data) -> None:
        self.compare_view.set_data(data)
        self.tabs.setCurrentWidget(self.compare_view)
        if data.notes:
            self.show_message("The index was repaired: " + "; ".join(data.notes), "note")
        else:
            self.clear_message()
        self.comparison_shown.emit(data)

    # -- storing and rebuilding ------------------------------------------------------
    def store_measurement(self, recording: Path, result, meta: dict) -> int:
        """Store in the worker; `stored` or `store_failed` tells how it went. The job's id."""
        job = self.worker.store(self.source, Path(recording), result, meta)
        self._jobs[job.id] = "store"
        self._storing[job.id] = Path(recording)
        return job.id

    def on_stored(self, job: int, stored) -> None:
        self._jobs.pop(job, None)
        self._storing.pop(job, None)
        self.refresh_now()
        if stored.queued:
            text = (f"Measured {stored.recording.name} as {stored.id}: the server cannot be reached, it waits in this "
                    "station's queue and is sent with the next store or 'Send queue'.")
        else:
            text = f"Stored {stored.recording.name} as {stored.id}."
        if stored.notes:
            text += (" " if self.on_server else " The index was repaired: ") + "; ".join(stored.notes)
        self.show_message(text, "note" if stored.notes else "info")
        self.stored.emit(stored.id, str(stored.recording))

    def on_rebuild(self) -> None:
        self.clear_message()
        doing = "send the queue" if self.on_server else "rebuild the index"
        self.jobs.run(self.worker.rebuild(self.source),
                      "Sending this station's queue to the server…" if self.on_server else
                      "Rebuilding the index from the measurement folders…", self.on_rebuilt,
                      lambda message: self.show_message(f"Cannot {doing}: {message}", "error"))

    def on_rebuilt(self, done) -> None:
        self.refresh_now()
        self.show_message(done.text[:1].upper() + done.text[1:], "note" if done.skipped else "info")
        self.rebuilt.emit(done.text)

    def on_failed(self, job: int, message: str) -> None:
        kind = self._jobs.pop(job, "")
        if kind == "store":
            recording = self._storing.pop(job, Path())
            self.show_message(f"{recording.name} was not stored in the archive: {message}", "error")
            self.store_failed.emit(message, str(recording))
        elif kind == "list" and self._list_job is not None and job == self._list_job.id:
            self._list_job = None
            self._list_failed(message)

    def on_cancelled(self, job: int) -> None:
        self._jobs.pop(job, None)
        self._storing.pop(job, None)

    def shutdown(self, wait_ms: int) -> bool:
        self.jobs.drop()
        return self.worker.shutdown(wait_ms)
