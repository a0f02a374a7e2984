"""The Qt bridge to the measurement: device tests, calibration, level check and measurement off the GUI thread.

Built like app.workers: one long-lived MeasureSession (a QObject of the GUI
thread) owns a QThreadPool and the signals; each job is a plain callable run
by the pool and every signal carries the job's id, so a page drops what a job
it has replaced still says. The pool has ONE thread: the jobs share the
hardware (one sound card stream, one PortAudio initialisation, one serial
port), so they run one after the other, never side by side.

What crosses to the GUI thread is frozen: LiveFrames (analysis.live), the
level decision, the resistor check, the finished measurement (a
MeasureOutcome holding an app.workers.AnalysisOutcome, ready for the Results
page and the Model lab), or one line of text.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from PySide6.QtCore import QObject, Signal

from analysis.fit import FitCancelled
from app.result_curves import result_curves
from analysis.errors import is_user_error
from app.workers import AnalysisOutcome
from app.job_book import JobBook, failure_text


PROGRESS_STEP = 0.005       # a progress bar 200 pixels wide does not move for less


def _cancel_errors() -> tuple[type[BaseException], ...]:
    from instruments.audio.errors import CaptureCancelled
    from instruments.measurement import MeasurementCancelled
    return CaptureCancelled, FitCancelled, MeasurementCancelled


@dataclass(frozen=True, slots=True)
class MeasureOutcome:
    """A finished measurement: where it was written, its analysis, and what it was asked to do."""

    analysis: AnalysisOutcome
    request: object                 # app.wizard.tasks.MeasurementRequest

    @property
    def path(self) -> Path:
        return self.analysis.path


class SessionJob:
    """One job in the pool thread: `work(job)` returns what `finished` carries."""

    def __init__(self, job: int, kind: str, work: Callable[["SessionJob"], object], session: "MeasureSession"):
        self.id = job
        self.kind = kind
        self._work = work
        self._session = session
        # NB: set by the GUI thread, read by the capture loop and the fit in the pool thread.
        self.cancel_event = threading.Event()
        self._last_progress = (-1.0, "")

    def cancel(self) -> None:
        self.cancel_event.set()

    @property
    def cancelled(self) -> bool:
        return self.cancel_event.is_set()

    def frame(self, frame) -> None:
        self._session.frame_ready.emit(self.id, frame)

    def progress(self, fraction: float, text: str) -> None:
        """Forwarded when it says something new: the runner reports every audio block."""
        last_fraction, last_text = self._last_progress
        if text != last_text or abs(fraction - last_fraction) >= PROGRESS_STEP:
            self._last_progress = (fraction, text)
            self._session.progress.emit(self.id, float(fraction), text)

    def __call__(self) -> None:
        session = self._session
        try:
            result = self._work(self)
        except _cancel_errors():
            session.cancelled.emit(self.id)
        except Exception as exc:  # noqa: BLE001 - the job runner is the GUI's error boundary (job_book)
            if self.cancel_event.is_set() and is_user_error(exc):   # a device stopped on its way out: a cancel
                session.cancelled.emit(self.id)
            else:
                session.failed.emit(self.id, failure_text(exc, f"the {self.kind}"))
        else:
            if self.cancel_event.is_set():
                session.cancelled.emit(self.id)
            else:
                session.finished.emit(self.id, result)


class MeasureSession(QObject, JobBook):
    frame_ready = Signal(int, object)       # job id, analysis.live.LiveFrame
    progress = Signal(int, float, str)      # job id, fraction 0..1, what is being done
    finished = Signal(int, object)          # job id, the job's result
    failed = Signal(int, str)               # job id, a one-line message for the user
    cancelled = Signal(int)                 # job id

    def __init__(self, parent: QObject | None = None):
        super().__init__(parent)
        self._init_jobs(self, (self.finished, self.failed, self.cancelled), max_threads=1)

    @property
    def busy(self) -> bool:
        return bool(self._jobs)

    # -- jobs ----------------------------------------------------------------
    # Each job imports what it needs in the pool thread: a first import of the measurement's modules takes
    # ~70 ms, which on the GUI thread would be a visible stall.
    def list_sound_cards(self) -> SessionJob:
        def work(job):
            from app.wizard.hardware import list_sound_cards
            return list_sound_cards()
        return self._launch("device list", work)

    def test_audio(self, config) -> SessionJob:
        def work(job):
            from app.wizard.hardware import test_audio
            job.progress(0.0, "playing a quiet test signal")
            return test_audio(config, job.cancel_event,
                              lambda kept, wanted: job.progress(kept / wanted, f"{kept} of {wanted} periods"))
        return self._launch("sound card test", work)

    def test_laser(self, config) -> SessionJob:
        def work(job):
            from app.wizard.hardware import test_laser
            return test_laser(config)
        return self._launch("laser test", work)

    def calibrate(self, config, r_ohm: float, level_v: float) -> SessionJob:
        def work(job):
            from app.wizard.calibration import measure_resistor
            return measure_resistor(config, r_ohm, level_v, job.cancel_event,
                                    lambda kept, wanted: job.progress(kept / wanted,
                                                                      f"measuring the resistor: {kept} of {wanted} "
                                                                      f"periods"))
        return self._launch("calibration", work)

    def check_level(self, config, template, corrections, v_min: float, v_max: float, x_limit_m: float) -> SessionJob:
        def work(job):
            from app.wizard.tasks import run_level_check
            job.progress(0.0, "designing the multitone")
            return run_level_check(config, template, corrections, v_min, v_max, x_limit_m, job.frame,
                                   job.cancel_event, job.progress)
        return self._launch("level check", work)

    def measure(self, request) -> SessionJob:
        def work(job):
            from app.wizard.tasks import run_measurement
            job.progress(0.0, "designing the multitone")
            wav, result = run_measurement(request, job.frame, job.cancel_event, job.progress)
            job.progress(0.99, "preparing the plots")
            return MeasureOutcome(AnalysisOutcome(job.id, wav, result, result_curves(result)), request)
        return self._launch("measurement", work)

    def measure_large_signal(self, request) -> SessionJob:
        def work(job):
            from app.wizard.tasks import run_large_signal_plan
            job.progress(0.0, "designing the multitone")
            return run_large_signal_plan(request, job.frame, job.cancel_event, job.progress)
        return self._launch("large-signal measurement", work)

    # -- bookkeeping -----------------------------------------------------------
    def _launch(self, kind: str, work: Callable[[SessionJob], object]) -> SessionJob:
        return self._start(SessionJob(self._next_id(), kind, work, self))

