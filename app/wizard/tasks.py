"""The level check and the measurement, run in a worker thread. Qt-free.

Both go through instruments.measurement's run_measurement when it is
installed (the level check's probes too, with analyse=False, written to a
temporary folder: so a serial laser is read during the level check as well).
Without it the fallback here measures: instruments.audio.capture_loop, with its
input blocks teed to a second PeriodCollector so that each kept period also
goes to an analysis.live.LiveAccumulator (the live panels), then
write_recording, then analyze_recording. The tee sees the same blocks in the
same order as capture's own collector, so it keeps the same periods.
"""
from __future__ import annotations

import dataclasses
import re
import tempfile
import threading
import time
from pathlib import Path
from typing import Callable

import numpy as np

from analysis.level_check import LevelDecision, LevelProbe, level_check
from analysis.live import LiveAccumulator, LiveFrame
from analysis.recording import make_recording, read_recording, write_recording
from analysis.session import SESSION_KEY, new_session
from app.wizard.calibration import Corrections
from app.wizard.corrected_audio import corrected_audio
from app.wizard.hardware import SERIAL_LASER, HardwareConfig, open_audio
from app.wizard.plans import DriverInfo, Template, find_runner, multitone_for
from instruments.audio import CapturedSignals, capture
from instruments.audio.periods import PeriodCollector

FADE_S = 0.1
FrameSink = Callable[[LiveFrame], None]
Progress = Callable[[float, str], None]
# Where a runner's stage sits on the progress bar; "averaging" runs from SETTLED to AVERAGED.
STAGE_FRACTION = {"laser": 0.0, "settling": 0.02, "aligning": 0.86, "writing": 0.88, "analysing": 0.9, "done": 1.0}
SETTLED, AVERAGED = 0.05, 0.85


@dataclasses.dataclass(frozen=True, slots=True)
class MeasurementRequest:
    driver: DriverInfo
    hardware: HardwareConfig
    template: Template
    corrections: Corrections
    level_v: float
    level_reason: str
    out_dir: Path
    limits: object = None           # analysis.large_signal.stepping.StepLimits, for the large-signal template


def recording_stem(driver: DriverInfo) -> str:
    """driver-serial-date-time, in characters every file system takes."""
    parts = [driver.name, driver.serial, time.strftime("%Y%m%d-%H%M%S")]
    text = "-".join(p for p in parts if p)
    return re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("_") or "measurement"


def open_devices(hardware: HardwareConfig, corrections: Corrections):
    """(audio with the corrections applied, serial laser or None) for one job."""
    audio = corrected_audio(open_audio(hardware, corrections.apply(hardware.calibration)), corrections)
    laser = None
    if hardware.laser == SERIAL_LASER:
        from instruments.laser import open_laser
        laser = open_laser(hardware.laser_spec())
    return audio, laser


def runner_progress(progress: Progress | None, prefix: str = "") -> Callable | None:
    """A MeasurementProgress callback that moves a progress bar."""
    if progress is None:
        return None

    def report(p) -> None:
        if p.stage == "averaging":
            fraction = SETTLED + (AVERAGED - SETTLED) * p.periods_kept / max(p.periods_wanted, 1)
            text = f"{p.periods_kept} of {p.periods_wanted} periods averaged"
        else:
            fraction = STAGE_FRACTION.get(p.stage, 0.0)
            text = p.message or p.stage
        progress(fraction, prefix + text)
    return report


def run_level_check(hardware: HardwareConfig, template: Template, corrections: Corrections,
                    v_min: float, v_max: float, x_limit_m: float, on_frame: FrameSink | None = None,
                    cancel: threading.Event | None = None, progress: Progress | None = None) -> LevelDecision:
    """analysis.level_check, each probe a short measurement on the hardware (its frames go to the panels)."""
    runner = find_runner()
    count = [0]
    with tempfile.TemporaryDirectory(prefix="linpar-level-") as folder:
        def measure_at(level: float) -> LevelProbe:
            count[0] += 1
            n = count[0]
            prefix = f"probe {n} at {level:.3g} V rms: "

            def moved(fraction: float, text: str) -> None:
                if progress is not None:     # each probe takes 30 % of what is left: the bar never fills
                    progress(1.0 - 0.7 ** (n - 1 + fraction), text)
            audio, laser = open_devices(hardware, corrections)
            if runner is not None:
                from instruments.measurement import MeasurementPlan
                plan = MeasurementPlan.from_template(template.key, level_v_rms=level, n_periods=template.probe_periods,
                                                     laser_rate_hz=hardware.laser_rate_hz)
                outcome = runner(plan, audio, laser, folder, name=f"probe-{n}",
                                 listeners=[on_frame] if on_frame else (), cancel=cancel,
                                 progress=runner_progress(moved, prefix), analyse=False)
                recording = outcome.recording
            else:
                mt = multitone_for(template)
                captured = captured_with_frames(audio, mt.scaled(rms=level).waveform, template.probe_periods,
                                                template.settle_periods, mt.excited_bins, on_frame, cancel,
                                                lambda kept, wanted: moved(kept / wanted, f"{prefix}{kept} of "
                                                                                         f"{wanted} periods"))
                recording = captured.to_recording(mt.excited_bins)
            return LevelProbe.from_recording(level, recording)

        return level_check(measure_at, v_min, v_max, x_limit_m)


def session_of_request(request: MeasurementRequest) -> dict:
    """The recording's "session" (analysis.session): the operator and station the Driver step asked for."""
    driver = request.driver
    return new_session(driver.operator, driver.station, request.template.key)


def run_measurement(request: MeasurementRequest, on_frame: FrameSink | None = None,
                    cancel: threading.Event | None = None, progress: Progress | None = None):
    """Measure, write the recording, then analyse it: (wav path, AnalysisResult)."""
    runner = find_runner()
    if runner is None:
        return run_measurement_fallback(request, on_frame, cancel, progress)
    from instruments.measurement import MeasurementPlan
    hw = request.hardware
    plan = MeasurementPlan.from_template(request.template.key, level_v_rms=request.level_v,
                                         driver=request.driver.as_json(), laser_rate_hz=hw.laser_rate_hz,
                                         calibration={"corrections": request.corrections.to_dict()},
                                         session=session_of_request(request))
    audio, laser = open_devices(hw, request.corrections)
    outcome = runner(plan, audio, laser, request.out_dir, name=recording_stem(request.driver),
                     listeners=[on_frame] if on_frame else (), cancel=cancel, progress=runner_progress(progress),
                     analyse=True)
    return outcome.recording_path, outcome.result


# --- without instruments.measurement ---------------------------------------------------------------

class _TeeAudio:
    """An AudioInterface that hands every block read to `on_blocks` as well as to capture()."""

    def __init__(self, audio, on_blocks: Callable[[tuple], None]):
        self._audio = audio
        self._on_blocks = on_blocks

    def __getattr__(self, name):
        return getattr(self._audio, name)

    def read_blocks(self, timeout: float):
        blocks = self._audio.read_blocks(timeout)
        if blocks:
            self._on_blocks(blocks)
        return blocks


class _LiveTap:
    """The tee's collector and the accumulator it feeds: one LiveFrame per kept period."""

    def __init__(self, audio, period: int, n_periods: int, settle: int, excited_bins, on_frame: FrameSink | None):
        cm = audio.channel_map
        self.signals = dict(cm.input_channels())
        self.calibration = audio.calibration
        self.collector = PeriodCollector(period, cm.n_inputs, n_periods, settle * period,
                                         int(round(FADE_S * audio.sample_rate)))
        self.accumulator = LiveAccumulator(audio.sample_rate, period, excited_bins, signals=tuple(self.signals))
        self.on_frame = on_frame
        self.fed = 0
        self.restarts = 0

    def __call__(self, blocks) -> None:
        for block in blocks:
            self.collector.add(block)
        kept = self.collector.kept
        if self.collector.restarts != self.restarts or len(kept) < self.fed:
            self.restarts = self.collector.restarts       # an xrun discarded the periods: so do the panels
            self.accumulator.reset()
            self.fed = 0
        while self.fed < min(len(kept), self.collector.n_periods):
            raw = kept[self.fed]
            period = {name: self.calibration.to_si(name, raw[:, channel]) for name, channel in self.signals.items()}
            frame = self.accumulator.add_period(period)
            self.fed += 1
            if self.on_frame is not None:
                self.on_frame(frame)


def captured_with_frames(audio, waveform: np.ndarray, n_periods: int, settle: int, excited_bins,
                         on_frame: FrameSink | None, cancel: threading.Event | None,
                         progress: Callable[[int, int], None] | None) -> CapturedSignals:
    tap = _LiveTap(audio, waveform.size, n_periods, settle, excited_bins, on_frame)
    return capture(_TeeAudio(audio, tap), waveform, n_periods, settle, fade_s=FADE_S, cancel=cancel,
                   progress=progress)


def run_measurement_fallback(request: MeasurementRequest, on_frame: FrameSink | None = None,
                             cancel: threading.Event | None = None, progress: Progress | None = None):
    from analysis.pipeline import analyze_recording

    t = request.template
    if request.hardware.laser == SERIAL_LASER:
        raise ValueError("the serial laser needs instruments.measurement's runner, which is not installed")
    mt = multitone_for(t)
    session = session_of_request(request)       # dated when the measurement starts
    audio, _ = open_devices(request.hardware, request.corrections)

    def periods_done(kept: int, wanted: int) -> None:
        if progress is not None:
            progress(SETTLED + (AVERAGED - SETTLED) * kept / wanted, f"{kept} of {wanted} periods averaged")
    captured = captured_with_frames(audio, mt.scaled(rms=request.level_v).waveform, t.n_periods, t.settle_periods,
                                    mt.excited_bins, on_frame, cancel, periods_done)
    extra = {"capture": captured.stats.capture_info(), "audio_capture": captured.stats.as_dict(),
             SESSION_KEY: session,
             "measurement": {"template": t.as_json(), "level_v_rms": request.level_v,
                             "level_reason": request.level_reason, "hardware": request.hardware.describe(),
                             "corrections": request.corrections.to_dict(), "runner": "app.wizard.tasks"}}
    recording = make_recording(captured.sample_rate, dict(captured.signals()), captured.period_samples,
                               excited_bins=tuple(int(b) for b in mt.excited_bins),
                               driver=request.driver.as_json(), extra=extra)
    if progress is not None:
        progress(STAGE_FRACTION["writing"], "writing the recording")
    request.out_dir.mkdir(parents=True, exist_ok=True)
    wav, _ = write_recording(request.out_dir / recording_stem(request.driver), recording)
    if progress is not None:
        progress(STAGE_FRACTION["analysing"], f"analysing {wav.name}")
    # Read back: the analysis sees exactly what the file holds (float32), and knows its source.
    return wav, analyze_recording(read_recording(wav), request.driver.sd_m2, cancel=cancel)


# --- the large-signal plan ---------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True, slots=True)
class LargeSignalMeasured:
    """The plan's outcome (instruments.measurement.large_signal_plan) and the identification of its steps."""

    plan: object                    # LargeSignalOutcome
    result: object | None           # analysis.large_signal.LargeSignalResult, None when it could not be made
    error: str = ""                 # why not
    request: object = None


def run_large_signal_plan(request: MeasurementRequest, on_frame: FrameSink | None = None,
                          cancel: threading.Event | None = None, progress: Progress | None = None
                          ) -> LargeSignalMeasured:
    """The large-signal plan from the level check's level, each step's periods to the live panels, then the
    identification of the usable steps."""
    from analysis.large_signal import LargeSignalError, large_signal
    from analysis.large_signal.stepping import StepLimits
    from instruments.measurement import MeasurementPlan
    from instruments.measurement.large_signal_plan import LargeSignalPlan, run_large_signal
    hw = request.hardware
    base = MeasurementPlan.from_template(request.template.key, driver=request.driver.as_json(),
                                         laser_rate_hz=hw.laser_rate_hz,
                                         calibration={"corrections": request.corrections.to_dict()},
                                         session=session_of_request(request))
    limits = request.limits or StepLimits()
    if request.level_v > limits.max_voltage_v:
        from instruments.measurement import MeasurementError
        raise MeasurementError(f"the level {request.level_v:.3g} V is above the plan's maximum voltage "
                               f"{limits.max_voltage_v:.3g} V: raise the maximum, or choose a lower level")
    plan = LargeSignalPlan(base, request.level_v, limits=limits)
    audio, laser = open_devices(hw, request.corrections)
    steps = [0]

    def measure(*args, **kwargs):
        steps[0] += 1
        fraction = 1.0 - 0.85 ** steps[0]           # the number of steps is not known: the bar never fills
        return find_runner()(*args, listeners=[on_frame] if on_frame else (),
                             **{**kwargs, "progress": runner_progress(
                                 None if progress is None else lambda f, text: progress(fraction, text))})
    outcome = run_large_signal(plan, audio, laser, request.out_dir, name=recording_stem(request.driver),
                               cancel=cancel, measure=measure)
    if not outcome.recordings:
        return LargeSignalMeasured(outcome, None, f"no usable step: {outcome.message}", request)
    if progress is not None:
        progress(0.97, f"identifying Bl(x), Kms(x), Le(x) from {len(outcome.recordings)} step(s)")
    try:
        return LargeSignalMeasured(outcome, large_signal(outcome.recordings), "", request)
    except LargeSignalError as exc:
        return LargeSignalMeasured(outcome, None, str(exc), request)
