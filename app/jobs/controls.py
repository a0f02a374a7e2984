"""Progress bar, what is being done, and Cancel, for one job of a JobRunner at a time (app.jobs.book).

Every page that runs work shows it with one of these: the wizard's steps,
the main window's analysis, the Model lab, the Series, Large-signal and
Production pages. It filters the runner's signals by the job's id, so a
replaced job's late signals are dropped, and calls the page back on the GUI
thread: finished(result), failed(message), cancelled(), frame(frame).
"""
from __future__ import annotations

from typing import Callable

from PySide6.QtCore import Signal
from PySide6.QtWidgets import QHBoxLayout, QLabel, QProgressBar, QPushButton, QSizePolicy, QWidget

from app.jobs.book import Job, JobRunner
from app.widgets.elided_label import ElidedLabel
from app.widgets.layout_room import keep_room_when_hidden


TEXT_LINES = 2
ONE_LINE_MIN_CHARS = 30


class JobControls(QWidget):
    busy_changed = Signal(bool)

    def __init__(self, runner: JobRunner, parent=None, cancel_tip: str = "Stop this job; nothing it has measured so "
                                                                          "far is kept", bar_width: int = 220,
                 one_line: bool = False):
        """one_line: what is being done on one line, cut with "…" (the status bar's room), not on TEXT_LINES."""
        super().__init__(parent)
        self.runner = runner
        self.job: Job | None = None
        self.progress = QProgressBar()
        self.progress.setRange(0, 1000)
        self.progress.setTextVisible(False)
        self.progress.setMaximumWidth(bar_width)
        self.progress.setMinimumWidth(40)       # it shrinks before its page sets the window's minimum width
        if one_line:
            self.text = ElidedLabel()
            # Its start stays readable when the row is short of room (a long path beside it in the status bar).
            self.text.setMinimumWidth(ONE_LINE_MIN_CHARS * self.text.fontMetrics().averageCharWidth())
        else:
            self.text = QLabel()
            self.text.setWordWrap(True)
            self.text.setSizePolicy(QSizePolicy.Preferred, QSizePolicy.Fixed)
        # Always as tall, whatever it says: a text that wrapped to one line more or less than the one
        # before changed the row's height and so resized every plot below it, and pyqtgraph laid them out
        # and redrew them all in one go (the Model lab's diagnosis: 65 ms of the GUI thread's CPU per change).
        # A longer text is cut; the whole of it is the tooltip.
        lines = 1 if one_line else TEXT_LINES
        self.text.setFixedHeight(lines * self.text.fontMetrics().lineSpacing() + 2)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.setToolTip(cancel_tip)
        self.cancel_button.clicked.connect(self.on_cancel)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.progress)
        layout.addWidget(self.text, 1)
        layout.addWidget(self.cancel_button)
        keep_room_when_hidden(self.progress, self.cancel_button)
        self._callbacks: dict[str, Callable] = {}
        self._stops_midway = True
        runner.progress.connect(self.on_progress)
        runner.frame_ready.connect(self.on_frame)
        for name in runner.result_signals:
            getattr(runner, name).connect(self.on_finished)
        runner.failed.connect(self.on_failed)
        runner.cancelled.connect(self.on_cancelled)
        self._show(False)

    @property
    def busy(self) -> bool:
        return self.job is not None

    def run(self, job: Job, text: str, finished: Callable[[object], None],
            failed: Callable[[str], None], cancelled: Callable[[], None] | None = None,
            frame: Callable[[object], None] | None = None, stops_midway: bool = True) -> None:
        """Show `job` (a running one is cancelled: its outcome is dropped) and call back when it ends.

        `stops_midway=False`: the work does not look at its cancel flag (one long fit), so Cancel lets the page
        go at once and the late outcome is dropped, instead of "Cancelling…" until the work ends."""
        if self.job is not None:
            self.job.cancel()
        self.job = job
        self._stops_midway = stops_midway
        self._callbacks = {"finished": finished, "failed": failed, "cancelled": cancelled, "frame": frame}
        self.progress.setValue(0)
        self.progress.setRange(0, 0)          # busy until the job reports a fraction
        self._say(text)
        self._show(True)
        self.busy_changed.emit(True)

    def drop(self) -> None:
        """Cancel the job shown and forget it: whatever it still says is ignored, no callback is called."""
        if self.job is not None:
            self.job.cancel()
            self._end()

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
            self._say("")

    def _say(self, text: str) -> None:
        self.text.setText(text)
        self.text.setToolTip(text)

    def on_progress(self, job: int, fraction: float, text: str) -> None:
        if self._mine(job):
            if fraction >= 0:
                if self.progress.maximum() == 0:
                    self.progress.setRange(0, 1000)
                self.progress.setValue(int(round(1000 * min(1.0, fraction))))
            self._say(text[:1].upper() + text[1:] + ("…" if fraction < 0 else ""))

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
        if self.job is None:
            return
        self.job.cancel()
        if not self._stops_midway:
            callback = self._end().get("cancelled")
            if callback:
                callback()
            return
        self.cancel_button.setEnabled(False)
        self._say("Cancelling…")
