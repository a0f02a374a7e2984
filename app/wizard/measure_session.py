"""The Qt bridge to the measurement: device tests, calibration, level check and measurement off the GUI thread.

A MeasureSession is a JobRunner (app.jobs.book) whose pool has ONE thread:
the jobs share the hardware (one sound card stream, one PortAudio
initialisation, one serial port), so they run one after the other, never
side by side.

What crosses to the GUI thread is frozen: LiveFrames (analysis.live), the
level decision, the resistor check, the finished measurement (a
MeasureOutcome holding an app.jobs.workers.AnalysisOutcome, ready for the Results
page and the Model lab), or one line of text.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from PySide6.QtCore import QObject

from analysis.fit.least_squares import FitCancelled
from app.jobs.book import Job, JobRunner
from app.results.curves import result_curves
from app.jobs.workers import AnalysisOutcome


# A Start click empties the live panels, a channel a turn (25-30 ms of the GUI thread's CPU on a 2-core machine).
# A measurement begun at once opened its devices meanwhile (imports, PortAudio, the rig's files) and held the
# GIL against those turns: the click's turn took 45-57 ms wall for 27-29 ms of CPU. So a measurement waits
# until the page says its panels are drawn: at most this long, so that a page that never says so only delays it.
PANELS_DRAWN_WAIT_S = 0.5


def _begin_after(panels_drawn: threading.Event | None) -> None:
    if panels_drawn is not None:
        panels_drawn.wait(PANELS_DRAWN_WAIT_S)


@dataclass(frozen=True, slots=True)
class MeasureOutcome:
    """A finished measurement: where it was written, its analysis, and what it was asked to do."""

    analysis: AnalysisOutcome
    request: object                 # app.wizard.tasks.MeasurementRequest

    @property
    def path(self) -> Path:
        return self.analysis.path


class MeasureSession(JobRunner):
    """The wizard's runner: one thread (the jobs share the hardware), and a measurement's own cancel errors."""

    def __init__(self, parent: QObject | None = None):
        super().__init__(parent, max_threads=1)
        from instruments.audio.errors import CaptureCancelled
        from instruments.measurement import MeasurementCancelled
        self.cancel_errors = (*JobRunner.cancel_errors, CaptureCancelled, FitCancelled, MeasurementCancelled)

    # -- jobs ----------------------------------------------------------------
    # Each job imports what it needs in the pool thread: a first import of the measurement's modules takes
    # ~70 ms, which on the GUI thread would be a visible stall.
    def list_sound_cards(self) -> Job:
        def work(job):
            from app.wizard.hardware import list_sound_cards
            return list_sound_cards()
        return self._launch("device list", work)

    def test_audio(self, config) -> Job:
        def work(job):
            from app.wizard.hardware import test_audio
            job.progress(0.0, "playing a quiet test signal")
            return test_audio(config, job.cancel_event,
                              lambda kept, wanted: job.progress(kept / wanted, f"{kept} of {wanted} periods"))
        return self._launch("sound card test", work)

    def test_laser(self, config) -> Job:
        def work(job):
            from app.wizard.hardware import test_laser
            return test_laser(config)
        return self._launch("laser test", work)

    def calibrate(self, config, r_ohm: float, level_v: float) -> Job:
        def work(job):
            from app.wizard.calibration import measure_resistor
            return measure_resistor(config, r_ohm, level_v, job.cancel_event,
                                    lambda kept, wanted: job.progress(kept / wanted,
                                                                      f"measuring the resistor: {kept} of {wanted} "
                                                                      f"periods"))
        return self._launch("calibration", work)

    def check_level(self, config, template, corrections, v_min: float, v_max: float, x_limit_m: float) -> Job:
        def work(job):
            from app.wizard.tasks import run_level_check
            job.progress(0.0, "designing the multitone")
            return run_level_check(config, template, corrections, v_min, v_max, x_limit_m, job.frame,
                                   job.cancel_event, job.progress)
        return self._launch("level check", work)

    def measure(self, request, panels_drawn: threading.Event | None = None) -> Job:
        """The measurement of `request`; it begins once `panels_drawn` is set (see PANELS_DRAWN_WAIT_S)."""
        def work(job):
            _begin_after(panels_drawn)
            from app.wizard.tasks import run_measurement
            job.progress(0.0, "designing the multitone")
            wav, result = run_measurement(request, job.frame, job.cancel_event, job.progress)
            job.progress(0.99, "preparing the plots")
            return MeasureOutcome(AnalysisOutcome(job.id, wav, result, result_curves(result)), request)
        return self._launch("measurement", work)

    def measure_large_signal(self, request, panels_drawn: threading.Event | None = None) -> Job:
        """The large-signal plan of `request`, begun as measure() begins."""
        def work(job):
            _begin_after(panels_drawn)
            from app.wizard.tasks import run_large_signal_plan
            job.progress(0.0, "designing the multitone")
            return run_large_signal_plan(request, job.frame, job.cancel_event, job.progress)
        return self._launch("large-signal measurement", work)

    def _launch(self, kind: str, work: Callable[[Job], object]) -> Job:
        return self.run(kind, work, f"the {kind}")

