"""Centred moving means of line statistics (noise variances, SNRs), each window summed on its own.

A variance from P periods alone scatters by sqrt(1/(P-1)); the spectral
checks pool each line's with its neighbours' (analysis.validity.spectral,
analysis.validity.unexcited), and the large-signal weights do the same.
"""
from __future__ import annotations

import functools

import numpy as np


def pooled_mean(values: np.ndarray, window: int) -> np.ndarray:
    """Centred moving mean over `window` (made odd) neighbours along the last axis, the window shrinking at
    the ends; each row of a 2-D array on its own (the same values as row by row).

    Each window is a sum of its own values (_window_sums), never a difference of running sums: the values
    span many decades (a line's SNR as a power ratio, 10^2 to 10^30), and a difference of running sums
    would lose every window after a large value to cancellation, or to inf - inf.
    """
    window = max(1, int(window)) | 1
    if window == 1 or values.shape[-1] < 2:
        return values
    values = np.asarray(values, dtype=np.float64)
    return _window_sums(values, window) / _window_counts(values.shape[-1], window)


def _window_sums(values: np.ndarray, window: int) -> np.ndarray:
    """The sum of each centred window of `window` (odd) values along the last axis, zeros beyond the ends.

    Built from blocks whose sizes are the powers of two in `window`: a block of 2s values is two blocks of s
    side by side, so a window of 33 takes 6 additions of the whole array where a convolution takes 33
    multiply-adds per value (the voltage's pool of 33 over ~13,500 unexcited lines: 0.37 -> ~0.05 ms, every
    live period). Only additions of the values themselves: the same rounding as any sum of 33 terms, no
    cancellation.
    """
    half, n = window // 2, values.shape[-1]
    zeros = np.zeros((*values.shape[:-1], half))
    padded = np.concatenate((zeros, values, zeros), axis=-1)
    block, size, offset, sums = padded, 1, 0, None       # block[..., i] = sum(padded[..., i:i + size])
    remaining = window
    while True:
        if remaining & 1:
            part = block[..., offset:offset + n]
            sums = part.copy() if sums is None else np.add(sums, part, out=sums)
            offset += size
        remaining >>= 1
        if not remaining:
            return sums
        block = block[..., :-size] + block[..., size:]
        size *= 2


@functools.lru_cache(maxsize=32)
def _window_counts(n: int, window: int) -> np.ndarray:
    """How many of the n values each centred window holds, counted rather than convolved; kept, since a live
    frame pools arrays of the same few sizes every period."""
    half = window // 2
    index = np.arange(n)
    counts = np.minimum(index + half, n - 1) - np.maximum(index - half, 0) + 1
    counts.flags.writeable = False
    return counts
