"""One job mechanism for the GUI: a JobRunner runs jobs off the GUI thread, a JobControls shows one of them.

A runner (a QObject of the GUI thread) owns a QThreadPool and the signals;
a job is a plain callable `work(job)` run by the pool, so it owns no QObject
whose lifetime could end in the pool thread. Every signal carries the job's
id, so a page drops what a job it has replaced still says. What crosses to
the GUI thread is frozen, or one line of text.

The skeleton every job shares is written once, in Job.__call__: what `work`
returns goes out as the runner's result signal (`finished` unless a runner
names one per kind); a cancel (JobCancelled, the runner's own cancel errors,
or a user error raised after cancel(): a device stopped on its way out) as
`cancelled`; anything else as `failed`, with the line `failure_text` makes.
`failure_text` is the GUI's one error boundary (analysis.errors): a user
error is its own message; anything else is a bug: "internal error while
...: ... (details in FILE)", with a crash report written (app.crash_report).

Closing a window: `shutdown` cancels every job, waits a while, then detaches
the runner: a job that cannot stop midway (a large-signal identification)
finishes in the background and whatever it still says is dropped, never
emitted from a source Qt has deleted with the window.
"""
from __future__ import annotations

import itertools
import logging
import threading
from typing import Callable

from PySide6.QtCore import QObject, QThreadPool, Signal

from analysis.errors import is_user_error, user_message

log = logging.getLogger(__name__)
PROGRESS_STEP = 0.005       # a progress bar 200 pixels wide does not move for less
UNKNOWN = -1.0              # a progress fraction that says "busy, how far is not known"


def failure_text(exc: BaseException, doing: str) -> str:
    """The one line the GUI shows for a job that raised `exc` while `doing` ("analysing x.wav")."""
    if is_user_error(exc):
        return user_message(exc)
    from app.crash_report import internal_error_line
    log.error("%s failed", doing, exc_info=exc)
    return internal_error_line(exc, doing)


class JobCancelled(Exception):
    """Raised by Job.check() in the pool thread once the GUI has cancelled the job."""


class Job:
    """One job in the pool thread: `work(job)` returns what the runner's result signal carries."""

    def __init__(self, job: int, kind: str, work: Callable[["Job"], object], runner: "JobRunner", doing: str):
        self.id = job
        self.kind = kind
        self.doing = doing              # for a failure's line: "analysing x.wav"
        self._work = work
        self._runner = runner
        # NB: set by the GUI thread, read by the work (its fit, capture loop, ...) in the pool thread.
        self.cancel_event = threading.Event()
        self._last_progress = (UNKNOWN - 1, "")

    def cancel(self) -> None:
        self.cancel_event.set()

    @property
    def cancelled(self) -> bool:
        return self.cancel_event.is_set()

    def check(self) -> None:
        if self.cancel_event.is_set():
            raise JobCancelled(f"{self.kind} cancelled")

    def progress(self, fraction: float, text: str) -> None:
        """Forwarded when it says something new: a measurement reports every audio block."""
        last_fraction, last_text = self._last_progress
        if text != last_text or abs(fraction - last_fraction) >= PROGRESS_STEP:
            self._last_progress = (fraction, text)
            self._runner.send("progress", self.id, float(fraction), text)

    def say(self, text: str) -> None:
        """What is being done, when how far is not known."""
        self.progress(UNKNOWN, text)

    def frame(self, frame) -> None:
        self._runner.send("frame_ready", self.id, frame)

    def __call__(self) -> None:
        runner = self._runner
        if self.cancelled:      # cancelled while it waited for a thread (a one-thread runner's queue): not run
            runner.send("cancelled", self.id)
            return
        try:
            result = self._work(self)
        except runner.cancel_errors:
            runner.send("cancelled", self.id)
        except Exception as exc:  # noqa: BLE001 - the job runner is the GUI's error boundary
            if self.cancelled and is_user_error(exc):
                runner.send("cancelled", self.id)
            else:
                runner.send("failed", self.id, failure_text(exc, self.doing))
        else:
            if self.cancelled:
                runner.send("cancelled", self.id)
            else:
                runner.send(runner.result_signal(self), self.id, result)


class JobRunner(QObject):
    """Runs jobs in its own pool; `max_threads=1` runs them one after the other (shared hardware, an archive)."""

    progress = Signal(int, float, str)      # job id, fraction 0..1 (UNKNOWN: busy), what is being done
    frame_ready = Signal(int, object)       # job id, a live frame (the measurement's panels)
    finished = Signal(int, object)          # job id, what the job returned
    failed = Signal(int, str)               # job id, a one-line message for the user
    cancelled = Signal(int)                 # job id
    cancel_errors: tuple[type[BaseException], ...] = (JobCancelled,)
    result_signals: tuple[str, ...] = ("finished",)     # a runner with one result signal per kind lists them

    def __init__(self, parent: QObject | None = None, max_threads: int | None = None):
        super().__init__(parent)
        self.pool = QThreadPool(self)
        if max_threads is not None:
            self.pool.setMaxThreadCount(max_threads)
        self._ids = itertools.count(1)
        self._jobs: dict[int, Job] = {}
        # NB: the pool threads emit under this lock, and shutdown detaches under it: after shutdown, nothing.
        self._lock = threading.Lock()
        self._detached = False
        for name in (*self.result_signals, "failed", "cancelled"):
            getattr(self, name).connect(self._forget)

    @property
    def busy(self) -> bool:
        return bool(self._jobs)

    def run(self, kind: str, work: Callable[[Job], object], doing: str | None = None) -> Job:
        job = Job(next(self._ids), kind, work, self, doing or f"the {kind}")
        self._jobs[job.id] = job
        self.pool.start(job)
        return job

    def result_signal(self, job: Job) -> str:
        return "finished"

    def send(self, signal: str, *args) -> None:
        """Emit from any thread, unless the runner has been shut down (its window may be gone)."""
        with self._lock:
            if not self._detached:
                getattr(self, signal).emit(*args)

    def cancel_all(self) -> None:
        for job in list(self._jobs.values()):
            job.cancel()

    def shutdown(self, wait_ms: int) -> bool:
        """Cancel every job, wait up to `wait_ms` for the pool, then detach; True when all stopped in time."""
        self.cancel_all()
        done = self.pool.waitForDone(wait_ms)
        with self._lock:
            self._detached = True
        if not done:
            log.info("%d job(s) still running at shutdown: they finish in the background, unheard",
                     len(self._jobs))
        return done

    def _forget(self, job: int, *_args) -> None:
        self._jobs.pop(job, None)
