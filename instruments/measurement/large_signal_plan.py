"""The large-signal plan: measure at rising levels until a limit, each step a recording, stopping safely.

    run_large_signal(plan, audio, laser, out_dir, name=...) -> LargeSignalOutcome

From ``start_level_v`` (a small-signal level) the level rises by ``step``
per measurement until one of the user's limits is reached: a peak
excursion, a voltage, the current's distortion, a rise of the coil's
temperature (RE per period); analysis.large_signal.stepping decides, and
shortens the steps near a limit. Every step is an ordinary measurement
(runner.py: written before anything reads it, NAME-sNN-<level>V.wav/.json),
measured without the linear analysis (the plan reads its periods itself).

Any fault (a device failing mid-step, a cancel, a disk that refuses the
recording) ends the plan at once: the steps before stay, the failed step's
whole periods stay too (marked partial by the runner), and the outcome says
what stopped it. NAME.large-signal.json, rewritten atomically after every
step, lists the plan, the steps (level, peak, distortion, RE per period)
and why it stopped: the input of `linpar large-signal`, and what is left
after a crash.

A step whose displacement did not repeat from period to period (its laser
stream was placed wrong in time: the host's moment, not the driver's) is
measured once more at the same level before the plan stops on it, as one of
its max_steps (the last of them stops it at once); the first recording stays
on disk, marked unusable, with the reason in its message.
"""
from __future__ import annotations

import dataclasses
import json
import threading
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Callable

from analysis.archive.atomic import write_atomic
from analysis.bounds import LEVEL_STEP
from analysis.errors import LinparError
from analysis.files import check_output
from analysis.large_signal.data import LargeSignalError
from analysis.large_signal.plan_summary import SUMMARY_SUFFIX
from analysis.large_signal.stepping import (StepLimits, StepMeasures, displacement_not_repeating, next_level,
                                            step_measures, stop_reason)
from instruments.measurement.errors import MeasurementError
from instruments.measurement.plan import MeasurementPlan

DEFAULT_STEP = 1.41          # +3 dB
MAX_STEPS = 24


@dataclass(frozen=True, slots=True)
class LargeSignalPlan:
    base: MeasurementPlan                 # band, period, periods averaged, laser: the level is each step's
    start_level_v: float
    step: float = DEFAULT_STEP
    limits: StepLimits = field(default_factory=StepLimits)
    max_steps: int = MAX_STEPS

    def __post_init__(self) -> None:
        if not (0 < self.start_level_v <= self.limits.max_voltage_v):
            raise LargeSignalError(f"the start level must be above 0 and at most the maximum voltage "
                                   f"{self.limits.max_voltage_v:g} V, got {self.start_level_v!r}")
        LEVEL_STEP.check(self.step, "the step", LargeSignalError)
        if not (isinstance(self.max_steps, int) and 1 <= self.max_steps <= 100):
            raise LargeSignalError(f"max_steps must be a whole number from 1 to 100, got {self.max_steps!r}")

    def as_json(self) -> dict:
        return {"base": self.base.as_json(), "start_level_v": self.start_level_v, "step": self.step,
                "limits": self.limits.as_json(), "max_steps": self.max_steps}


@dataclass(frozen=True, slots=True)
class PlanStep:
    index: int
    level_v: float
    recording_path: Path | None
    measures: StepMeasures | None
    partial: bool = False
    message: str = ""

    @property
    def usable(self) -> bool:
        """Complete, no input clipped, the displacement repeating: a step the identification may take (the
        others stay on disk)."""
        return (not self.partial and self.measures is not None and not self.measures.clipped
                and self.measures.displacement_repeats)


@dataclass(frozen=True, slots=True)
class LargeSignalOutcome:
    steps: tuple[PlanStep, ...]
    stopped_by: str                       # one of stepping.STOPS
    message: str
    summary_path: Path

    @property
    def recordings(self) -> list[Path]:
        """The usable steps' recordings, by rising level."""
        return [s.recording_path for s in self.steps if s.recording_path is not None and s.usable]


StepListener = Callable[[PlanStep], None]


def run_large_signal(plan: LargeSignalPlan, audio, laser=None, out_dir: Path | str = ".", *,
                     name: str | None = None, cancel: threading.Event | None = None, progress=None,
                     on_step: StepListener | None = None, measure=None) -> LargeSignalOutcome:
    """Run the plan (module doc). ``measure`` is run_measurement's signature (default: run_journaled, whose
    journal survives a crash); MeasurementError before the first step is not caught: nothing was recorded."""
    from instruments.measurement.recovery import run_journaled
    from instruments.measurement.runner import MeasurementCancelled, MeasurementFailed
    measure = measure or run_journaled
    out_dir = Path(out_dir)
    name = name or datetime.now().strftime("large-signal-%Y%m%d-%H%M%S")
    summary = out_dir / f"{name}{SUMMARY_SUFFIX}"
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        check_output(summary)
    except OSError as exc:          # OutputError is one too
        why = str(exc) if isinstance(exc, LinparError) else f"{out_dir}: cannot be written ({exc.strerror or exc})"
        raise MeasurementError(f"{why}; nothing was measured") from None
    steps: list[PlanStep] = []
    re_lines = None
    re_reference = float("nan")
    level = float(plan.start_level_v)
    stopped, message = "steps", f"the plan's {plan.max_steps} steps were all measured"
    measured_again = False          # this level was measured again after a misplaced laser stream
    for index in range(1, plan.max_steps + 1):
        step_plan = dataclasses.replace(plan.base, level_v_rms=level)
        step_name = f"{name}-s{index:02d}-{level:.3g}V"
        try:
            outcome = measure(step_plan, audio, laser, out_dir, name=step_name, cancel=cancel,
                              progress=_prefixed(progress, index, level), analyse=False)
        except MeasurementCancelled as exc:
            steps.append(_kept(index, level, exc.outcome, str(exc)))
            stopped, message = "cancelled", f"cancelled during step {index} ({level:.3g} V)"
            break
        except MeasurementFailed as exc:
            steps.append(_kept(index, level, exc.outcome, str(exc)))
            stopped, message = "fault", f"step {index} ({level:.3g} V): {exc}"
            break
        except (MeasurementError, OSError) as exc:
            if not steps:
                raise
            stopped, message = "fault", f"step {index} ({level:.3g} V) could not be measured: {exc}"
            break
        measures, re_lines = step_measures(outcome.recording, level, re_lines)
        if index == 1:
            re_reference = measures.re_per_period[0] if measures.re_per_period else float("nan")
        reached = stop_reason(measures, plan.limits, re_reference, measured_again)
        again = (reached is not None and reached[0] == "fault" and not measured_again
                 and index < plan.max_steps)
        step = PlanStep(index, level, outcome.recording_path, measures,
                        message=f"measured again at the same level: {displacement_not_repeating(measures)}"
                        if again else "")
        steps.append(step)
        _write_summary(summary, plan, steps, None, "", re_reference)
        if on_step is not None:
            on_step(step)
        if again:
            measured_again = True
            continue
        if reached is not None:
            stopped, message = reached
            break
        measured_again = False
        nxt, why = next_level(measures, plan.limits, plan.step)
        if nxt is None:
            stopped = why if why in ("excursion", "voltage", "distortion") else "voltage"
            message = f"the next step would pass the {why} limit (predicted from {level:.3g} V)"
            break
        level = nxt
    _write_summary(summary, plan, steps, stopped, message, re_reference)
    return LargeSignalOutcome(tuple(steps), stopped, message, summary)


def _kept(index: int, level: float, outcome, message: str) -> PlanStep:
    path = None if outcome is None else outcome.recording_path
    return PlanStep(index, level, path, None, partial=True, message=message)


def _prefixed(progress, index: int, level: float):
    if progress is None:
        return None

    def report(p) -> None:
        progress(dataclasses.replace(p, message=f"step {index} at {level:.3g} V" + (f": {p.message}"
                                                                                      if p.message else "")))
    return report


def _write_summary(path: Path, plan: LargeSignalPlan, steps: list[PlanStep], stopped: str | None, message: str,
                   re_reference: float) -> None:
    doc = {"format": "linpar-large-signal-plan/1", "plan": plan.as_json(), "stopped_by": stopped,
           "message": message, "steps": [
               {"index": s.index, "level_v": s.level_v, "partial": s.partial, "usable": s.usable,
                "message": s.message,
                "recording": None if s.recording_path is None else s.recording_path.name,
                "measures": None if s.measures is None else s.measures.as_json(re_reference)} for s in steps]}
    write_atomic(path, json.dumps(doc, indent=1, allow_nan=False, default=str) + "\n")
