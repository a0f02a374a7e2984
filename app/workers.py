"""Analysis off the GUI thread.

One long-lived AnalysisWorker (a QObject of the GUI thread) owns a QThreadPool
and the signals; each job is a plain callable run by the pool. Jobs therefore
own no QObject whose lifetime could end in the pool thread: the signals are
emitted from the pool thread and Qt queues them to the GUI thread's slots.
Every signal carries the job's id, so the GUI can drop the outcome of a job it
has replaced. What crosses over is frozen (AnalysisOutcome) or a string.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass
from pathlib import Path

from PySide6.QtCore import QObject, Signal

from analysis.errors import one_line as _one_line
from analysis.fit import FitCancelled
from analysis.pipeline import AnalysisResult, analyze_recording
from analysis.recording import read_recording
from app.result_curves import ResultCurves, result_curves
from app.job_book import JobBook, failure_text


@dataclass(frozen=True, slots=True)
class AnalysisOutcome:
    job: int
    path: Path
    result: AnalysisResult
    curves: ResultCurves | None         # None: nothing was fitted (result.not_fitted says why)


class AnalysisJob:
    """Read one recording and analyse it; runs in a pool thread."""

    def __init__(self, job: int, path: Path, sd_m2: float | None, worker: "AnalysisWorker"):
        self.id = job
        self.path = path
        self.sd_m2 = sd_m2
        self._worker = worker
        # NB: set by the GUI thread, read by the fit's iteration callback in the pool thread.
        self.cancel_event = threading.Event()

    def cancel(self) -> None:
        self.cancel_event.set()

    def __call__(self) -> None:
        signals = self._worker
        try:
            signals.progress.emit(self.id, f"reading {self.path.name}")
            recording = read_recording(self.path)
            if self.cancel_event.is_set():
                raise FitCancelled("cancelled before the fit")
            signals.progress.emit(self.id, f"estimating spectra and fitting {self.path.name}")
            result = analyze_recording(recording, self.sd_m2, cancel=self.cancel_event)
            curves = result_curves(result)
        except FitCancelled:
            signals.cancelled.emit(self.id)
        except Exception as exc:  # noqa: BLE001 - the job runner is the GUI's error boundary (job_book)
            signals.failed.emit(self.id, failure_text(exc, f"analysing {self.path.name}"))
        else:
            signals.finished.emit(self.id, AnalysisOutcome(self.id, self.path, result, curves))


class AnalysisWorker(QObject, JobBook):
    progress = Signal(int, str)         # job id, the stage being worked on
    finished = Signal(int, object)      # job id, AnalysisOutcome
    failed = Signal(int, str)           # job id, a one-line message for the user
    cancelled = Signal(int)             # job id

    def __init__(self, parent: QObject | None = None):
        super().__init__(parent)
        self._init_jobs(self, (self.finished, self.failed, self.cancelled))

    def start(self, path: str | Path, sd_m2: float | None = None) -> AnalysisJob:
        return self._start(AnalysisJob(self._next_id(), Path(path), sd_m2, self))



def one_line(exc: BaseException) -> str:
    return _one_line(exc) or type(exc).__name__
