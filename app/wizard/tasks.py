"""The level check and the measurement, run in a worker thread. Qt-free.

Both go through instruments.measurement's run_measurement, with its crash
journal (recovery.run_journaled); the level check's probes too, with
analyse=False, written to a temporary folder: so a serial laser is read
during the level check as well.
"""
from __future__ import annotations

import dataclasses
import re
import tempfile
import threading
import time
from pathlib import Path
from typing import Callable

from analysis.level_check import LevelDecision, LevelProbe, level_check
from analysis.live import LiveFrame
from analysis.session import new_session
from app.wizard.calibration import Corrections
from app.wizard.corrected_audio import corrected_audio
from app.wizard.hardware import SERIAL_LASER, HardwareConfig, open_audio
from app.wizard.plans import DriverInfo, Template
from instruments.measurement import MeasurementPlan
from instruments.measurement.recovery import run_journaled

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
            plan = MeasurementPlan.from_template(template.key, level_v_rms=level, n_periods=template.probe_periods,
                                                 laser_rate_hz=hardware.laser_rate_hz)
            outcome = run_journaled(plan, audio, laser, folder, name=f"probe-{n}",
                                    listeners=[on_frame] if on_frame else (), cancel=cancel,
                                    progress=runner_progress(moved, prefix), analyse=False)
            return LevelProbe.from_recording(level, outcome.recording)

        return level_check(measure_at, v_min, v_max, x_limit_m)


def session_of_request(request: MeasurementRequest) -> dict:
    """The recording's "session" (analysis.session): the operator and station the Driver step asked for."""
    driver = request.driver
    return new_session(driver.operator, driver.station, request.template.key)


def run_measurement(request: MeasurementRequest, on_frame: FrameSink | None = None,
                    cancel: threading.Event | None = None, progress: Progress | None = None):
    """Measure, write the recording, then analyse it: (wav path, AnalysisResult)."""
    hw = request.hardware
    plan = MeasurementPlan.from_template(request.template.key, level_v_rms=request.level_v,
                                         driver=request.driver.as_json(), laser_rate_hz=hw.laser_rate_hz,
                                         calibration={"corrections": request.corrections.to_dict()},
                                         session=session_of_request(request))
    audio, laser = open_devices(hw, request.corrections)
    outcome = run_journaled(plan, audio, laser, request.out_dir, name=recording_stem(request.driver),
                            listeners=[on_frame] if on_frame else (), cancel=cancel,
                            progress=runner_progress(progress), analyse=True)
    return outcome.recording_path, outcome.result


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
        return run_journaled(*args, listeners=[on_frame] if on_frame else (),
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
