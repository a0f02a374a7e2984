"""One measurement: play, record, align the laser, write, then analyse. No Qt.

    run_measurement(plan, audio, laser, out_dir) ->
        the laser opened and streaming (its reader thread empties it into a list)
        capture() on a TimedAudio (notes block arrivals, ends on cancel / xrun / lost laser)
            each kept period -> LiveFrame -> listeners
        the laser stopped once its stream covers the last period
        the laser's stream aligned and resampled onto the audio grid (alignment.py)
        NAME.laser.npz (raw laser stream and arrival times), then NAME.wav + NAME.json
        then, and only then, the analysis

Everything is on disk before anything analyses it. When a device fails (the
audio stream stops, its JACK client is killed, the laser's link is lost), an
xrun comes once periods are being kept (plan.on_xrun "end", the default with
the serial laser; during the settling an xrun only makes capture() settle
again), or the caller cancels, the capture ends within about a second, the
whole periods captured so far are written (the sidecar's "measurement"
says "partial": true and why) and MeasurementFailed (MeasurementCancelled)
is raised with a one-line message that says what happened and where the
data are. Trailing periods that hold the inputs' digital silence (what
capture() keeps while it makes sure its inputs went dead) are left out.

The sidecar gets, besides the recording format's keys: "capture" (what
analysis.validity.assessment reads, with the laser's error counts and out-of-range
share), "audio_capture" (every count of the capture), "measurement" (the
plan, the devices, how it ended), and for the serial laser
"displacement_max_hz" and "laser_alignment" (alignment.py).

The analysis is `linpar analyze`'s (analysis.pipeline.analyze_recording): the default model, plus `delay-x`
with the serial laser (analysis/serial_laser.py); ``effects`` replaces it.
"""
from __future__ import annotations

import dataclasses
import gc
import re
import sys
import threading
import time
from dataclasses import dataclass
from datetime import datetime
from enum import StrEnum
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from analysis.pipeline import AnalysisResult, analyze_recording
from analysis.serial_laser import DISPLACEMENT_MAX_KEY, SERIAL_LASER
from analysis.recording.format import Recording, make_recording, read_recording, write_recording
from analysis.session import SESSION_KEY, new_session
from instruments.audio import CapturedSignals, capture
from instruments.audio.errors import AudioError, CaptureCancelled
from instruments.audio.interface import AudioInterface
from instruments.laser.sensor import DisplacementSensor, LaserError
from instruments.measurement.alignment import AlignedDisplacement, align_laser, stream_of_blocks
from instruments.measurement.clocks import lower_envelope
from instruments.measurement.laser_reader import LaserReader
from instruments.measurement.live_periods import Listener, LivePeriods
from instruments.measurement.plan import MeasurementPlan
from instruments.measurement.raw_stream import raw_capture_path, write_raw_capture
from instruments.measurement.resample import HALF_TAPS
from instruments.measurement.timed_audio import TimedAudio
from instruments.measurement.errors import MeasurementError  # noqa: F401  (re-exported)

_CAPTURE_KEPT = re.compile(r"; kept \d+ of \d+ periods$")
GIL_SWITCH_S = 0.001
SILENT_SHARE = 0.01      # a period with this share of exact zeros on every input is not the driver's
STAGES = ("laser", "settling", "averaging", "aligning", "writing", "analysing", "done")


class MeasurementFailed(MeasurementError):
    """A device failed mid-measurement; ``outcome`` says what was kept on disk."""

    def __init__(self, message: str, outcome: MeasurementOutcome):
        super().__init__(message)
        self.outcome = outcome


class MeasurementCancelled(MeasurementFailed):
    """The caller cancelled; what was captured is kept as for a failure."""


@dataclass(frozen=True, slots=True)
class MeasurementProgress:
    stage: str                 # one of STAGES
    periods_kept: int
    periods_wanted: int
    elapsed_s: float
    message: str = ""


class EndedBy(StrEnum):
    """How a measurement ended (str-valued: the sidecar's "ended_by" reads the same as before)."""

    COMPLETE = "complete"
    CANCELLED = "cancelled"
    LASER = "laser"
    XRUN = "xrun"
    AUDIO = "audio"
    CRASH = "crash"             # written from the journal after a crash (instruments.measurement.recovery)


@dataclass(frozen=True, kw_only=True)
class MeasurementOutcome:
    recording_path: Path | None      # NAME.wav; None when fewer than 2 whole periods were captured
    raw_path: Path | None            # NAME.laser.npz, with the serial laser
    recording: Recording | None
    result: AnalysisResult | None    # None for a partial measurement (or analyse=False)
    periods: int
    partial: bool
    ended_by: EndedBy
    message: str                     # one line; "" when complete
    alignment: dict | None = None

    @property
    def sidecar_path(self) -> Path | None:
        return None if self.recording_path is None else self.recording_path.with_suffix(".json")


Progress = Callable[[MeasurementProgress], None]


def run_measurement(plan: MeasurementPlan, audio: AudioInterface, laser: DisplacementSensor | None = None,
                    out_dir: Path | str = ".", *, name: str | None = None, listeners: Sequence[Listener] = (),
                    cancel: threading.Event | None = None, progress: Progress | None = None,
                    analyse: bool = True, effects=None) -> MeasurementOutcome:
    """Measure (module doc). ``laser``: a serial DisplacementSensor, or None (the displacement comes from the
    sound card's laser_analog input, or there is none). MeasurementError before anything was recorded,
    MeasurementFailed / MeasurementCancelled after."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    stem = out_dir / (name or datetime.now().strftime("measurement-%Y%m%d-%H%M%S"))
    started = time.monotonic()
    report = _Reporter(progress, plan.n_periods, started)
    multitone = plan.excitation(audio.sample_rate)
    serial = laser is not None
    stop = threading.Event()
    timed = TimedAudio(audio, stop, cancel=cancel, end_on_xrun=plan.end_on_xrun(serial),
                       keep_samples=3 * plan.period_samples)
    reader = None
    if serial:
        report("laser", 0, "opening the laser")
        reader = LaserReader(laser, stop, plan.laser_rate_hz)
        try:
            reader.open()
            reader.start()
        except LaserError as exc:
            reader.close()
            raise MeasurementError(f"laser: {exc}") from None
    live = LivePeriods(timed, plan.period_samples, multitone.excited_bins, listeners,
                       _provisional_displacement(plan, timed, reader, multitone.excited_bins) if serial else None)

    def on_capture(kept: int, wanted: int) -> None:
        timed.keeping = kept > 0
        live.on_progress(kept)
        report("averaging" if kept else "settling", kept)

    # NB: process-wide while it runs. The audio callback is Python and must get the GIL within one cycle of
    # the audio server (21 ms on the rig); with the pump, the laser's readers and the live view also asking
    # for it, the default interval (5 ms per holder) let it wait longer: xruns. 1 ms keeps it well inside.
    # Likewise the cyclic garbage collector: a full collection holds the GIL for tens of ms. The capture makes
    # no reference cycles; what it leaves is collected after.
    switch_interval, collecting = sys.getswitchinterval(), gc.isenabled()
    sys.setswitchinterval(min(switch_interval, GIL_SWITCH_S))
    gc.disable()
    try:
        captured, failure = _capture(timed, multitone, plan, on_capture)
        if captured is None:          # the stream never started: nothing was recorded
            raise MeasurementError(f"sound card: {failure}")
        ended_by, message = _how_it_ended(failure, reader, timed, cancel)
        captured = _without_silence(captured)
        starts = _kept_period_starts(captured, timed)
        blocks = [] if reader is None else reader.finish(_laser_needed_until(timed, starts, plan),
                                                         timeout_s=0.0 if failure else 0.5)
    except BaseException:             # Ctrl-C, a bug: the laser stops streaming all the same
        if reader is not None:
            reader.close()
        raise
    finally:
        sys.setswitchinterval(switch_interval)
        if collecting:
            gc.enable()
    aligned, laser_info, raw_path = None, None, None
    if reader is not None:
        report("aligning", captured.n_periods)
        if ended_by is EndedBy.COMPLETE and reader.failure:
            ended_by, message = EndedBy.LASER, reader.failure
        aligned, align_problem = _align(blocks, timed, starts, plan, audio.sample_rate, multitone.excited_bins)
        if align_problem and ended_by is EndedBy.COMPLETE:
            ended_by, message = EndedBy.LASER, align_problem
        laser_info = _laser_info(reader, aligned, audio.sample_rate, plan)
    live.emit_ready()
    n_kept = captured.n_periods if aligned is None else aligned.periods
    report("writing", n_kept)
    partial = ended_by is not EndedBy.COMPLETE
    recording = _recording(captured, aligned, n_kept, multitone.excited_bins, plan, audio, laser_info, ended_by,
                           message, serial)
    if reader is not None:
        extra = {} if recording is not None else {"voltage": captured.voltage, "current": captured.current}
        raw_path = write_raw_capture(raw_capture_path(stem), blocks, timed.arrivals(), starts,
                                     {"plan": plan.as_json(), "audio_rate": audio.sample_rate,
                                      "laser": laser_info, "ended_by": ended_by, "message": message}, extra)
    wav_path = write_recording(stem, recording)[0] if recording is not None else None
    if wav_path is not None:
        recording = read_recording(wav_path)      # what is analysed is what is on disk, as `linpar analyze` reads it
    outcome = MeasurementOutcome(recording_path=wav_path, raw_path=raw_path, recording=recording, result=None,
                                 periods=n_kept, partial=partial, ended_by=ended_by, message=message,
                                 alignment=None if aligned is None else laser_info.get("alignment"))
    if partial:
        kept = (f"{n_kept} whole period(s) kept in {wav_path}" if wav_path else
                f"{n_kept} whole period(s) captured, too few for a recording (2 needed)")
        if n_kept < captured.n_periods:
            kept += f" (of {captured.n_periods} captured, the laser's stream covers {n_kept})"
        if raw_path is not None:
            kept += f"; raw laser stream in {raw_path}"
        error = MeasurementCancelled if ended_by is EndedBy.CANCELLED else MeasurementFailed
        raise error(f"{message}; {kept} (marked partial)", outcome)
    result = None
    if analyse:
        report("analysing", n_kept)
        result = analyze_recording(recording, effects=effects, cancel=cancel)
    report("done", n_kept)
    return dataclasses.replace(outcome, result=result)


class _Reporter:
    def __init__(self, progress: Progress | None, wanted: int, started: float):
        self.progress, self.wanted, self.started = progress, wanted, started

    def __call__(self, stage: str, kept: int, message: str = "") -> None:
        if self.progress is not None:
            self.progress(MeasurementProgress(stage, kept, self.wanted, time.monotonic() - self.started, message))


def _capture(timed: TimedAudio, multitone, plan: MeasurementPlan, on_capture) -> tuple[CapturedSignals | None,
                                                                                          str | None]:
    try:
        return capture(timed, multitone.waveform, plan.n_periods, plan.settle, cancel=timed.stop_event,
                       progress=on_capture), None
    except CaptureCancelled as exc:
        return exc.partial, "cancelled"
    except AudioError as exc:
        return exc.partial, str(exc)


def _how_it_ended(failure: str | None, reader: LaserReader | None, timed: TimedAudio,
                  cancel: threading.Event | None) -> tuple[EndedBy, str]:
    if failure is None:
        return EndedBy.COMPLETE, ""
    if reader is not None and reader.failure:
        return EndedBy.LASER, f"the laser failed: {reader.failure}"
    if timed.xrun_at is not None:
        return EndedBy.XRUN, (f"the audio driver reported an xrun at input sample {timed.xrun_at} (samples lost or "
                        f"invented): the measurement ended, as the driver left its steady state and the audio "
                        f"clock jumped; close other programs or raise the audio buffer, and measure again")
    if cancel is not None and cancel.is_set():
        return EndedBy.CANCELLED, "the measurement was cancelled"
    if failure == "cancelled":
        return EndedBy.CANCELLED, "the measurement was stopped"
    # capture() ends its message with how many periods it kept; the runner says what it kept itself.
    return EndedBy.AUDIO, "the sound card failed: " + _CAPTURE_KEPT.sub("", failure)


def _without_silence(captured: CapturedSignals) -> CapturedSignals:
    """The periods before the first one in which every input reads exact zeros for SILENT_SHARE of it.

    capture() notices that its inputs went silent (the JACK client feeding
    them killed) only after a second of silence, and keeps the periods it
    filled meanwhile; they are not the driver's.
    """
    period, n = captured.period_samples, captured.n_periods
    rows = [captured.voltage, captured.current] + ([captured.displacement] if captured.displacement is not None
                                                  else [])
    silent = np.all(np.stack([r[:n * period] for r in rows]) == 0.0, axis=0).reshape(n, period)
    bad = np.flatnonzero(silent.mean(axis=1) >= SILENT_SHARE)
    if bad.size == 0:
        return captured
    keep = int(bad[0]) * period
    cut = {name: (None if value is None else value[:keep]) for name, value in
           (("voltage", captured.voltage), ("current", captured.current), ("displacement", captured.displacement))}
    return dataclasses.replace(captured, **cut)


def _kept_period_starts(captured: CapturedSignals, timed: TimedAudio) -> np.ndarray:
    """Input index of each kept period: consecutive from the first, except around lost samples."""
    period, n = captured.period_samples, captured.n_periods
    first = captured.stats.discarded_samples
    if captured.stats.gaps == 0 or n == 0:
        return first + period * np.arange(n, dtype=np.int64)
    start, stop, _ = timed.arrivals()
    order = np.argsort(start)
    start, stop = start[order], stop[order]
    starts, candidate = [], first
    while len(starts) < n and candidate + period <= stop.max():
        inside = (stop > candidate) & (start < candidate + period)
        s, e = start[inside], stop[inside]
        whole = s.size and s[0] <= candidate and e[-1] >= candidate + period and np.all(s[1:] == e[:-1])
        if whole:
            starts.append(candidate)
        candidate += period
    return np.asarray(starts, dtype=np.int64)


def _laser_needed_until(timed: TimedAudio, starts: np.ndarray, plan: MeasurementPlan) -> float:
    """Host time by which the laser has measured past the last kept period, with the interpolator's taps."""
    _, stop, arrived = timed.arrivals(since_xrun=True)
    if starts.size == 0 or stop.size < 4:
        return time.monotonic()
    line = lower_envelope(stop, arrived)
    end = float(line.time_of(starts[-1] + plan.period_samples))
    return end + (HALF_TAPS + 4) / plan.laser_rate_hz + plan.laser_latency_s


def _align(blocks, timed: TimedAudio, starts: np.ndarray, plan: MeasurementPlan, audio_rate: int,
           excited_bins) -> tuple[AlignedDisplacement | None, str | None]:
    if starts.size == 0:
        return None, None
    _, stop, arrived = timed.arrivals(since_xrun=True)
    try:
        stream = stream_of_blocks(blocks)
        return align_laser(stream, stop, arrived, starts, plan.period_samples, audio_rate, plan.laser_rate_hz,
                           excited_bins, sign=plan.laser_sign, latency_s=plan.laser_latency_s), None
    except ValueError as exc:
        return None, f"the laser's stream cannot be aligned to the audio: {exc}"


def _provisional_displacement(plan: MeasurementPlan, timed: TimedAudio, reader: LaserReader, excited_bins):
    """For the live view: one period's displacement from the host times alone (no refinement)."""
    def displacement_of(start: int) -> np.ndarray | None:
        blocks = reader.blocks
        _, stop, arrived = timed.arrivals(since_xrun=True)
        if len(blocks) < 8 or stop.size < 8:
            return None
        try:
            aligned = align_laser(stream_of_blocks(blocks), stop, arrived, [start], plan.period_samples,
                                  timed.sample_rate, plan.laser_rate_hz, excited_bins, sign=plan.laser_sign,
                                  latency_s=plan.laser_latency_s, refine=False, quick=True)
        except ValueError:
            return None
        return aligned.displacement
    return displacement_of


def _laser_info(reader: LaserReader, aligned: AlignedDisplacement | None, audio_rate: int,
                plan: MeasurementPlan) -> dict[str, Any]:
    info = reader.info
    out: dict[str, Any] = {"sensor": None if info is None else {"name": info.name, "serial": info.serial,
                                                                "measuring_range_m": info.measuring_range_m,
                                                                "firmware": info.firmware},
                           "rate_hz": plan.laser_rate_hz, "failure": reader.failure}
    if aligned is not None:
        out["alignment"] = aligned.as_json(audio_rate, plan.laser_rate_hz)
        out["counts"] = aligned.counts.capture_json()
    return out


def _recording(captured: CapturedSignals, aligned: AlignedDisplacement | None, n: int, excited_bins,
               plan: MeasurementPlan, audio: AudioInterface, laser_info: dict | None, ended_by: EndedBy, message: str,
               serial: bool) -> Recording | None:
    if n < 2:
        return None
    keep = n * captured.period_samples
    signals = {"voltage": captured.voltage[:keep], "current": captured.current[:keep]}
    if aligned is not None:
        signals["displacement"] = aligned.displacement[:keep]
    elif captured.displacement is not None and not serial:
        signals["displacement"] = captured.displacement[:keep]
    stats = captured.stats
    capture_info = stats.capture_info()
    if aligned is not None:
        capture_info.update(aligned.counts.capture_json())
    extra: dict[str, Any] = {
        "capture": capture_info, "audio_capture": stats.as_dict(),
        "measurement": {"plan": plan.as_json(), "partial": ended_by != "complete", "ended_by": ended_by,
                        "message": message, "periods": n, "audio": audio.describe(),
                        "displacement_source": SERIAL_LASER if serial else (
                            "sound card (laser analog)" if "displacement" in signals else "none"),
                        "laser": laser_info},
    }
    calibration = plan.sidecar_calibration(getattr(audio, "calibration", None))
    if calibration:
        extra["calibration"] = calibration
    extra[SESSION_KEY] = {**new_session(template=plan.template), **dict(plan.session)}
    if aligned is not None:
        extra[DISPLACEMENT_MAX_KEY] = aligned.max_hz
        extra["laser_alignment"] = aligned.as_json(captured.sample_rate, plan.laser_rate_hz)
    return make_recording(captured.sample_rate, signals, captured.period_samples, 0,
                          tuple(int(b) for b in excited_bins), dict(plan.driver), extra)

