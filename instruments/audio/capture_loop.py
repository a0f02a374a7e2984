"""One measurement on any AudioInterface: play the looped excitation, keep whole settled periods.

``capture`` fades the excitation in, lets the driver settle, keeps
``n_periods`` whole periods (instruments.audio.periods), fades out and stops.
It returns them in volts, amperes and metres with a CaptureStats that says
what went wrong on the way (xruns, lost samples, clipping, silent inputs).
It ends with an AudioError, carrying the periods kept so far as ``partial``,
when the device stops delivering (no block for ``stall_timeout_s``, or the
stream ended by itself), when every input turns to digital silence after
having carried signal (the JACK client feeding them is gone), when no input
ever carries signal, after too many dropouts, at the time limit; and with
CaptureCancelled when ``cancel`` is set.
"""
from __future__ import annotations

import threading
import time
from typing import Callable

import numpy as np

from instruments.audio.captured import CLIP_LEVEL, CaptureEnd, CapturedSignals, CaptureStats
from instruments.audio.errors import AudioError, CaptureCancelled
from instruments.audio.interface import AudioInterface
from instruments.audio.periods import PeriodCollector
from instruments.audio.stream_core import LoopedExcitation, StreamCounters


def capture(audio: AudioInterface, excitation_waveform: np.ndarray, n_periods: int, settle_periods: int, *,
            fade_s: float = 0.1, cancel: threading.Event | None = None, timeout_s: float | None = None,
            stall_timeout_s: float = 1.0, silence_timeout_s: float = 1.0, signal_timeout_s: float = 3.0,
            max_restarts: int = 3, progress: Callable[[int, int], None] | None = None) -> CapturedSignals:
    """Play one period of ``excitation_waveform`` (V at the terminals) in a loop and keep ``n_periods``.

    ``settle_periods`` periods are discarded after the fade-in (use at least
    the driver's decay time; on the virtual rig, its FIR length). The default
    time limit is twice the nominal duration plus 5 s.
    """
    waveform = np.asarray(excitation_waveform, dtype=np.float64).ravel()
    period, fs = waveform.size, audio.sample_rate
    if n_periods < 1 or settle_periods < 0:
        raise ValueError(f"need n_periods >= 1 and settle_periods >= 0, got {n_periods} and {settle_periods}")
    fade = int(round(fade_s * fs))
    excitation = LoopedExcitation.from_volts(waveform, audio.calibration, fade)
    collector = PeriodCollector(period, audio.channel_map.n_inputs, n_periods, settle_periods * period, fade)
    if timeout_s is None:
        timeout_s = 2 * (2 * fade + (settle_periods + n_periods) * period) / fs + 5.0
    failure: str | None = None
    audio.start(excitation)
    started = last_block = time.monotonic()
    try:
        while not collector.done:
            blocks = audio.read_blocks(0.05)
            now = time.monotonic()
            for block in blocks:
                collector.add(block)
            if blocks:
                last_block = now
                if progress is not None:
                    progress(len(collector.kept), n_periods)
            failure = _failure(audio, collector, now - started, now - last_block, fs, timeout_s,
                               stall_timeout_s, silence_timeout_s, signal_timeout_s, max_restarts)
            if failure or (cancel is not None and cancel.is_set()):
                break
    finally:
        if failure is None:
            _fade_out(audio, fade / fs)
        audio.stop()
    ended_by = (CaptureEnd.COMPLETE if collector.done else CaptureEnd.CANCELLED if failure is None
                else CaptureEnd.FAILED)
    result = _result(audio, collector, excitation, ended_by, failure or "")
    if failure is not None:
        raise AudioError(f"{failure}; kept {result.n_periods} of {n_periods} periods", partial=result)
    if not collector.done:
        raise CaptureCancelled(f"capture cancelled; kept {result.n_periods} of {n_periods} periods",
                               partial=result)
    return result


def _failure(audio, collector: PeriodCollector, elapsed: float, since_block: float, fs: int, timeout_s: float,
             stall_timeout_s: float, silence_timeout_s: float, signal_timeout_s: float,
             max_restarts: int) -> str | None:
    if since_block > stall_timeout_s:
        return (f"the sound card delivered no samples for {since_block:.1f} s (device unplugged, audio "
                f"server stopped or its client killed)")
    if since_block > 0.1 and not audio.running:
        return "the audio stream stopped by itself (device unplugged or audio server gone)"
    if collector.had_signal and collector.silent_samples > silence_timeout_s * fs:
        return (f"every input has read exact zeros for {collector.silent_samples / fs:.1f} s after carrying "
                f"signal: whatever fed the inputs went away (JACK client of the rig killed?)")
    if not collector.had_signal and collector.expected > signal_timeout_s * fs:
        return (f"no input carried any signal in {signal_timeout_s:g} s: is the rig running and connected, "
                f"are the inputs wired?")
    if collector.restarts > max_restarts:
        return f"{collector.restarts} dropouts interrupted the averaging (more than {max_restarts})"
    if elapsed > timeout_s:
        return f"the capture took longer than its limit of {timeout_s:.1f} s"
    return None


def _fade_out(audio, fade_s: float) -> None:
    """Fade the output out and wait until it has been played (the driver is not left with a click)."""
    audio.fade_out()
    deadline = time.monotonic() + 2 * fade_s + 0.5
    while not audio.output_finished and audio.running and time.monotonic() < deadline:
        audio.read_blocks(0.02)   # keep the queue drained, so no block is dropped and counted


def _result(audio, collector: PeriodCollector, excitation: LoopedExcitation, ended_by: CaptureEnd,
            failure: str) -> CapturedSignals:
    cm, cal, fs = audio.channel_map, audio.calibration, audio.sample_rate
    raw = collector.data()
    signals: dict[str, np.ndarray] = {}
    clipped, silent, peaks = [], [], []
    for signal, channel in cm.input_channels().items():
        column = raw[:, channel]
        clipped.append((signal, int(np.count_nonzero(np.abs(column) >= CLIP_LEVEL))))
        peaks.append((signal, float(np.max(np.abs(column))) if column.size else 0.0))
        if column.size and not np.any(column):
            silent.append(signal)
        si = cal.to_si(signal, column)
        si.flags.writeable = False
        signals[signal] = si
    counters: StreamCounters = audio.counters()
    first_kept = collector.kept_start if collector.kept else collector.expected
    stats = CaptureStats(
        sample_rate=fs, period_samples=collector.period, periods_kept=len(collector.kept[:collector.n_periods]),
        fade_samples=collector.fade, settle_samples=collector.settle, discarded_samples=int(first_kept),
        samples_received=collector.samples_received, samples_lost=collector.samples_lost, gaps=collector.gaps,
        queue_overflows=counters.queue_overflows, input_overflows=counters.input_overflows,
        input_underflows=counters.input_underflows, output_underflows=counters.output_underflows,
        output_overflows=counters.output_overflows, restarts=collector.restarts,
        output_clipped_samples=excitation.clipped_per_period, output_peak_fs=excitation.requested_peak_fs,
        clipped_inputs=tuple(clipped), full_scale_fraction=tuple(peaks), silent_channels=tuple(silent),
        device=audio.describe(), ended_by=ended_by, failure=failure)
    return CapturedSignals(sample_rate=fs, period_samples=collector.period, voltage=signals["voltage"],
                           current=signals["current"], displacement=signals.get("displacement"), stats=stats)
