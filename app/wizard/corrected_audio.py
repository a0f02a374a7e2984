"""An AudioInterface whose current channel is advanced by the calibration's delay correction. Qt-free.

The current channel lags the voltage channel by tau (app.wizard.calibration).
Advancing a stream in real time is impossible, but the excitation is
periodic: in the steady state, delaying the current by one period less tau,
P - tau * fs samples, is the same as advancing it by tau. So the current is
delayed by that much (a ring of one period, and a windowed-sinc filter for the
fraction of a sample) while the other channels pass untouched: the sample
counter, the laser's alignment to it and the voltage keep their timing.

The first period after the start (or after lost samples) holds the current of
no period: the capture discards it anyway (its settle is at least one
period), and a block after lost samples is flagged as an xrun so the
periods around it are not kept.
"""
from __future__ import annotations

import numpy as np

from instruments.audio.stream_core import INPUT_OVERFLOW, InputBlock

HALF_TAPS = 32          # 65 taps: flat within 1e-4 to 0.4 fs (19 kHz at 48 kHz)
KAISER_BETA = 8.0


def fractional_delay_fir(fraction: float, half: int = HALF_TAPS) -> np.ndarray:
    """Taps that delay by half + fraction samples (|fraction| <= 0.5), unit gain at DC."""
    n = np.arange(2 * half + 1)
    taps = np.sinc(n - half - fraction) * np.kaiser(2 * half + 1, KAISER_BETA)
    return taps / taps.sum()


class DelayCorrectedAudio:
    def __init__(self, audio, delay_s: float):
        self._audio = audio
        self.delay_s = float(delay_s)
        self._channel = audio.channel_map.current
        self._history = np.zeros(0)
        self._next = 0
        self._lag = 0            # whole samples of the delay ahead of the filter
        self._taps = np.ones(1)

    def __getattr__(self, name):
        return getattr(self._audio, name)

    def start(self, excitation) -> None:
        period = excitation.period_samples
        delay = period - self.delay_s * self._audio.sample_rate      # the current's delay, in samples
        whole = int(np.round(delay))
        self._taps = fractional_delay_fir(delay - whole)
        self._lag = whole - HALF_TAPS                                   # the filter adds HALF_TAPS
        if self._lag < 0:
            raise ValueError(f"a current delay correction of {self.delay_s * 1e6:g} µs does not fit in a period "
                             f"of {period} samples")
        self._history = np.zeros(self._lag + 2 * HALF_TAPS)
        self._next = 0
        self._audio.start(excitation)

    def read_blocks(self, timeout: float):
        return tuple(self._corrected(b) for b in self._audio.read_blocks(timeout))

    def _corrected(self, block: InputBlock) -> InputBlock:
        flags = block.flags
        if block.start != self._next:            # lost samples: the ring no longer holds the last period
            self._history[:] = 0.0
            flags |= INPUT_OVERFLOW
        self._next = block.stop
        current = block.samples[:, self._channel].astype(np.float64)
        x = np.concatenate([self._history, current])
        n = current.size
        # y[t] = sum_j taps[j] x[t - lag - j]: the newest n outputs need x from n + lag + 2H back.
        y = np.convolve(x[:n + 2 * HALF_TAPS], self._taps, mode="valid")[:n]
        self._history = x[-self._history.size:] if self._history.size else self._history
        samples = np.array(block.samples, copy=True)
        samples[:, self._channel] = y
        samples.flags.writeable = False
        return InputBlock(block.start, samples, flags)


def corrected_audio(audio, corrections):
    """`audio` with `corrections`' delay applied (its gain goes into the calibration: Corrections.apply)."""
    if corrections is None or corrections.current_delay_s == 0.0:
        return audio
    return DelayCorrectedAudio(audio, corrections.current_delay_s)
