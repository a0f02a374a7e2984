"""Band-limited interpolation of a uniformly sampled stream at arbitrary positions.

The laser's samples (uniform on its own clock) are evaluated at the audio
sample instants, which fall anywhere between them. The interpolator is a
Kaiser-windowed sinc of ``2 * HALF_TAPS`` taps with its cutoff at
``CUTOFF`` of the laser's rate: flat (ripple ~1e-5, -100 dB stopband) up to
``PASSBAND`` of the laser's rate, and nothing at or above its Nyquist
frequency, where the samples say nothing. ``PASSBAND`` is thus the highest
frequency at which the resampled displacement may be used (the recording's
"displacement_max_hz").

The kernel is tabulated at TABLE_STEPS points per sample and read with
linear interpolation (error ~1e-7 of a tap), so no Bessel function is
evaluated per output sample.
"""
from __future__ import annotations

import numpy as np

HALF_TAPS = 64
CUTOFF = 0.47          # of the sampling rate
PASSBAND = 0.44        # of the sampling rate: flat to ~1e-5 below it
KAISER_BETA = 10.0
TABLE_STEPS = 1024
_CHUNK = 1 << 16


def _kernel_table() -> np.ndarray:
    d = np.arange(-HALF_TAPS * TABLE_STEPS, HALF_TAPS * TABLE_STEPS + 1) / TABLE_STEPS
    window = np.i0(KAISER_BETA * np.sqrt(np.clip(1.0 - (d / HALF_TAPS) ** 2, 0.0, 1.0))) / np.i0(KAISER_BETA)
    return 2.0 * CUTOFF * np.sinc(2.0 * CUTOFF * d) * window


_TABLE = _kernel_table()


def covered(positions: np.ndarray, n_samples: int) -> np.ndarray:
    """Whether every tap of the interpolation at each position lies within samples 0 .. n_samples-1."""
    positions = np.asarray(positions, dtype=np.float64)
    first = np.floor(positions) - HALF_TAPS + 1
    return (first >= 0) & (first + 2 * HALF_TAPS - 1 <= n_samples - 1)


def interpolate(samples: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """The band-limited signal through ``samples`` (finite, uniform) at fractional sample ``positions``.

    Every position must be ``covered`` (ValueError otherwise): a signal
    guessed beyond its ends would be worse than none. Tap by tap over all
    positions: where in the kernel table each position falls is worked out
    once, the same for every tap.
    """
    samples = np.asarray(samples, dtype=np.float64)
    positions = np.asarray(positions, dtype=np.float64)
    if not np.all(covered(positions, samples.size)):
        raise ValueError("positions too close to the ends of the stream to interpolate")
    out = np.empty(positions.size)
    for lo in range(0, positions.size, _CHUNK):
        u = positions[lo:lo + _CHUNK]
        whole = np.floor(u)
        first = whole.astype(np.int64) - HALF_TAPS + 1
        step = (u - whole) * TABLE_STEPS             # tap t sits at distance frac + HALF_TAPS - 1 - t
        fine = np.floor(step)
        frac = step - fine
        base = fine.astype(np.int64)
        acc = np.zeros(u.size)
        for t in range(2 * HALF_TAPS):
            row = base + (2 * HALF_TAPS - 1 - t) * TABLE_STEPS
            acc += samples[first + t] * (_TABLE[row] + frac * (_TABLE[row + 1] - _TABLE[row]))
        out[lo:lo + _CHUNK] = acc
    return out
