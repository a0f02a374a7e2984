"""What every wizard page shares: the state handed from page to page, the page base, the job controls."""
from __future__ import annotations

import html
from dataclasses import dataclass, field
from typing import Callable

from PySide6.QtCore import QSettings, Qt, Signal
from PySide6.QtWidgets import QHBoxLayout, QLabel, QProgressBar, QPushButton, QWidget

from app.layout_room import keep_room_when_hidden
from app.measure_session import MeasureSession, SessionJob
from app.wizard.calibration import Corrections
from app.wizard.hardware import HardwareConfig
from app.wizard.plans import DriverInfo

ERROR_COLOUR = "#8e1b1b"
OK_COLOUR = "#1b5e20"


@dataclass
class WizardState:
    """What the pages have settled so far; GUI thread only."""

    settings: QSettings
    driver: DriverInfo | None = None
    hardware: HardwareConfig = field(default_factory=HardwareConfig)
    corrections: Corrections | None = None
    level_v: float | None = None
    level_reason: str = ""
    level_words: str = ""                     # the reason in a few words ("enough signal")
    outcome: object | None = None            # app.measure_session.MeasureOutcome


class WizardPage(QWidget):
    """A step. `missing()` is why Next is not possible yet (None: it is); emit `changed` when it may differ."""

    changed = Signal()
    title = ""
    subtitle = ""

    def __init__(self, state: WizardState, session: MeasureSession, parent=None):
        super().__init__(parent)
        self.state = state
        self.session = session

    def missing(self) -> str | None:
        return None

    @property
    def busy(self) -> bool:
        return False

    def enter(self) -> None:
        """The page is shown (forwards or backwards): refresh from the state."""

    def commit(self) -> None:
        """Next was pressed: put what the page settled into the state."""


def rich_label(text: str = "", selectable: bool = False) -> QLabel:
    label = QLabel(text)
    label.setTextFormat(Qt.RichText)
    label.setWordWrap(True)
    if selectable:
        label.setTextInteractionFlags(Qt.TextSelectableByMouse)
    return label


def coloured(text: str, colour: str) -> str:
    return f"<span style='color:{colour}'>{html.escape(text)}</span>"


class JobControls(QWidget):
    """Progress bar, what is being done, and Cancel, for one session job at a time.

    Filters the session's signals by the job's id, so a replaced job's late
    signals are dropped. The callbacks run on the GUI thread.
    """

    busy_changed = Signal(bool)

    def __init__(self, session: MeasureSession, parent=None):
        super().__init__(parent)
        self.session = session
        self.job: SessionJob | None = None
        self.progress = QProgressBar()
        self.progress.setRange(0, 1000)
        self.progress.setTextVisible(False)
        self.progress.setMaximumWidth(220)
        self.text = QLabel()
        self.text.setWordWrap(True)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.setToolTip("Stop this job; nothing it has measured so far is kept")
        self.cancel_button.clicked.connect(self.on_cancel)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.progress)
        layout.addWidget(self.text, 1)
        layout.addWidget(self.cancel_button)
        keep_room_when_hidden(self.progress, self.cancel_button)
        self._callbacks: dict[str, Callable] = {}
        session.progress.connect(self.on_progress)
        session.frame_ready.connect(self.on_frame)
        session.finished.connect(self.on_finished)
        session.failed.connect(self.on_failed)
        session.cancelled.connect(self.on_cancelled)
        self._show(False)

    @property
    def busy(self) -> bool:
        return self.job is not None

    def run(self, job: SessionJob, text: str, finished: Callable[[object], None],
            failed: Callable[[str], None], cancelled: Callable[[], None] | None = None,
            frame: Callable[[object], None] | None = None) -> None:
        if self.job is not None:
            self.job.cancel()
        self.job = job
        self._callbacks = {"finished": finished, "failed": failed, "cancelled": cancelled, "frame": frame}
        self.progress.setValue(0)
        self.progress.setRange(0, 0)          # busy until the job reports a fraction
        self.text.setText(text)
        self._show(True)
        self.busy_changed.emit(True)

    def _mine(self, job: int) -> bool:
        return self.job is not None and self.job.id == job

    def _end(self) -> dict[str, Callable]:
        callbacks, self._callbacks = self._callbacks, {}
        self.job = None
        self._show(False)
        self.busy_changed.emit(False)
        return callbacks

    def _show(self, busy: bool) -> None:
        self.progress.setVisible(busy)
        self.cancel_button.setVisible(busy)
        self.cancel_button.setEnabled(busy)
        if not busy:
            self.text.setText("")

    def on_progress(self, job: int, fraction: float, text: str) -> None:
        if self._mine(job):
            if self.progress.maximum() == 0:
                self.progress.setRange(0, 1000)
            self.progress.setValue(int(round(1000 * max(0.0, min(1.0, fraction)))))
            self.text.setText(text[:1].upper() + text[1:])

    def on_frame(self, job: int, frame) -> None:
        if self._mine(job) and self._callbacks.get("frame"):
            self._callbacks["frame"](frame)

    def on_finished(self, job: int, result) -> None:
        if self._mine(job):
            self._end()["finished"](result)

    def on_failed(self, job: int, message: str) -> None:
        if self._mine(job):
            self._end()["failed"](message)

    def on_cancelled(self, job: int) -> None:
        if self._mine(job):
            callback = self._end().get("cancelled")
            if callback:
                callback()

    def on_cancel(self) -> None:
        if self.job is not None:
            self.job.cancel()
            self.cancel_button.setEnabled(False)
            self.text.setText("Cancelling…")
