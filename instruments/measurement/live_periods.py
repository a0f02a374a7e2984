"""Per-period LiveFrames for the live panels, from the capture's progress.

capture() says how many periods it has kept; the periods are consecutive on
the grid of the input sample counter, so when it reports k kept periods and
has handed out input up to index E, the newest kept period ends at
floor(E / P) * P and the first began k periods earlier. Their raw samples
are still in TimedAudio's ring; they are scaled to SI units (the channel map
and calibration of the sound card) and fed to an analysis.live.LiveAccumulator.

With the serial laser, the displacement of a period comes from a provisional
alignment (host times only, no refinement: ``displacement_of``), once the
laser's stream covers it; a period waits (in order) until it does. The
recording gets the refined alignment later; the live view is for judging
levels and noise while the measurement runs.

Listeners are called in the measurement thread with each new LiveFrame; one
that raises is counted and left out of the next frames, never allowed to end
the measurement.
"""
from __future__ import annotations

import logging
from typing import Callable, Sequence

import numpy as np

from analysis.live import LiveAccumulator, LiveFrame
from instruments.measurement.timed_audio import TimedAudio

log = logging.getLogger(__name__)

Listener = Callable[[LiveFrame], None]
DisplacementOf = Callable[[int], "np.ndarray | None"]


class LivePeriods:
    def __init__(self, timed: TimedAudio, period_samples: int, excited_bins: Sequence[int],
                 listeners: Sequence[Listener] = (), displacement_of: DisplacementOf | None = None):
        self.timed = timed
        self.period = int(period_samples)
        self.listeners = list(listeners)
        self.displacement_of = displacement_of
        cm = timed.channel_map
        self._inputs = cm.input_channels()
        has_x = displacement_of is not None or "displacement" in self._inputs
        signals = ("voltage", "current", "displacement") if has_x else ("voltage", "current")
        self._new_accumulator = lambda: LiveAccumulator(timed.sample_rate, self.period, excited_bins, signals)
        self.accumulator = self._new_accumulator()
        self.restarts = 0
        self._first_start: int | None = None
        self._pending: list[int] = []
        self._queued = 0
        self.frames = 0
        self.listener_errors = 0
        self.last_frame: LiveFrame | None = None

    def on_progress(self, kept: int) -> None:
        """capture() kept ``kept`` periods so far; queue the new ones, emit what can be."""
        if kept < self._queued:
            self._restart()
        if not self.listeners or kept <= self._queued:
            return
        if self._first_start is None:
            newest_end = (self.timed.handed_out_until // self.period) * self.period
            self._first_start = newest_end - kept * self.period
        for index in range(self._queued, kept):
            self._pending.append(self._first_start + index * self.period)
        self._queued = kept
        self.emit_ready()

    def _restart(self) -> None:
        """capture() discarded its periods after an xrun and averages again: so do the panels, from the
        periods it keeps from now on (their places on the input grid are new)."""
        self.restarts += 1
        self.accumulator = self._new_accumulator()
        self._first_start, self._pending, self._queued = None, [], 0

    def emit_ready(self) -> None:
        while self._pending:
            start = self._pending[0]
            raw = self.timed.raw_samples(start, start + self.period)
            if raw is None:      # overwritten already (the measurement thread fell far behind): skip it
                self._pending.pop(0)
                continue
            period = self._period(start, raw)
            if period is None:
                return           # the laser's stream does not reach past this period yet
            self._pending.pop(0)
            frame = self.accumulator.add_period(period)
            self.frames += 1
            self.last_frame = frame
            for listener in list(self.listeners):
                try:
                    listener(frame)
                except Exception:      # a broken panel must not end the measurement
                    log.exception("a live listener failed; it gets no more frames")
                    self.listener_errors += 1
                    self.listeners.remove(listener)

    def _period(self, start: int, raw: np.ndarray) -> dict[str, np.ndarray] | None:
        cal = self.timed.calibration
        period = {name: cal.to_si(name, raw[:, channel]) for name, channel in self._inputs.items()}
        if self.displacement_of is not None:
            x = self.displacement_of(start)
            if x is None:
                return None
            period["displacement"] = x
        return {name: period[name] for name in self.accumulator.signals}
