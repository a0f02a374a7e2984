"""Whole periods from a stream of input blocks, with the settle and the dropouts handled.

The excitation repeats every ``period`` output samples, so once the driver
has settled every ``period`` consecutive input samples are one period of the
steady state. The collector keeps periods on the grid of the input sample
counter (starts at multiples of ``period``), so every kept period has the
same phase and they can be averaged as they are.

What may be kept starts ``settle`` samples after the later of: the end of the
fade-in, and the first input sample that is not exactly zero. The second
matters on JACK, where the inputs read digital silence until the rig has
connected its ports: the driver only starts settling then.

Dropouts:
- a gap in the sample counter (the callback's queue was full): the samples
  are lost but the output never stopped, so only the period that contains
  the gap is dropped;
- a callback whose status flags report an xrun: the output glitched, the
  driver left its steady state, and the input/output alignment may have
  moved. Every period kept so far is discarded (one restart) and keeping
  starts again ``settle`` samples later.
"""
from __future__ import annotations

import math

import numpy as np

from instruments.audio.stream_core import XRUN_FLAGS, InputBlock


class PeriodCollector:
    def __init__(self, period: int, n_inputs: int, n_periods: int, settle: int, fade: int = 0):
        if period < 1 or n_periods < 1 or settle < 0 or fade < 0:
            raise ValueError("period and n_periods must be >= 1, settle and fade >= 0")
        self.period, self.n_inputs, self.n_periods = int(period), int(n_inputs), int(n_periods)
        self.settle, self.fade = int(settle), int(fade)
        self.kept: list[np.ndarray] = []
        self.kept_start: int | None = None           # input index of the first kept sample
        self._current = np.zeros((self.period, self.n_inputs), dtype=np.float32)
        self._current_start: int | None = None      # grid index of the period being filled
        self._current_fill = 0
        self.valid_from: int | None = None           # None until some input carries signal
        self.expected = 0                            # the next input sample index
        self.first_signal: int | None = None
        self.last_signal_end = 0
        self.samples_received = 0
        self.samples_lost = 0
        self.gaps = 0
        self.xrun_blocks = 0
        self.restarts = 0

    @property
    def done(self) -> bool:
        return len(self.kept) >= self.n_periods

    @property
    def had_signal(self) -> bool:
        return self.first_signal is not None

    @property
    def silent_samples(self) -> int:
        """Samples since the last one that was not exactly zero on any input."""
        return self.expected - self.last_signal_end if self.had_signal else self.expected

    def add(self, block: InputBlock) -> None:
        a, b, x = block.start, block.stop, block.samples
        self.samples_received += b - a
        if a > self.expected:
            self.samples_lost += a - self.expected
            self.gaps += 1
            self._restart_period_at(a)
        self.expected = max(self.expected, b)
        rows = np.flatnonzero(np.any(x != 0, axis=1))
        if rows.size:
            if self.first_signal is None:
                self.first_signal = a + int(rows[0])
                self._move_valid_from(max(self.fade, self.first_signal) + self.settle)
            self.last_signal_end = a + int(rows[-1]) + 1
        if block.flags & XRUN_FLAGS:
            self.xrun_blocks += 1
            if self.kept or self._current_fill:
                self.restarts += 1
            self.kept.clear()
            self._current_fill = 0
            if self.valid_from is not None:
                self._move_valid_from(max(self.valid_from, b + self.settle))
            return
        if self.valid_from is None or self.done:
            return
        i = max(a, self._current_start + self._current_fill)
        while i < b and not self.done:
            take = min(b - i, self.period - self._current_fill)
            self._current[self._current_fill:self._current_fill + take] = x[i - a:i - a + take]
            self._current_fill += take
            i += take
            if self._current_fill == self.period:
                if not self.kept:
                    self.kept_start = self._current_start
                self.kept.append(self._current.copy())
                self._current_start += self.period
                self._current_fill = 0

    def _move_valid_from(self, index: int) -> None:
        self.valid_from = index
        self._current_start = math.ceil(index / self.period) * self.period
        self._current_fill = 0

    def _restart_period_at(self, index: int) -> None:
        """Samples before ``index`` are missing: the period being filled cannot be completed."""
        if self._current_start is not None and self._current_start + self._current_fill < index:
            self._current_start = max(self._current_start, math.ceil(index / self.period) * self.period)
            self._current_fill = 0

    def data(self) -> np.ndarray:
        """The kept periods back to back: (n_kept * period, n_inputs) float32 FS."""
        if not self.kept:
            return np.zeros((0, self.n_inputs), dtype=np.float32)
        return np.concatenate(self.kept[:self.n_periods], axis=0)
