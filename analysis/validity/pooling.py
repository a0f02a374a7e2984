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


def above_pooled_mean(values: np.ndarray, window: int, test: np.ndarray,
                      factor: float) -> tuple[np.ndarray, np.ndarray]:
    """Where test > factor * pooled_mean(values, window), for one row of non-negative values (variances): the
    indices and the pooled means there.

    Only candidates get their window summed: each centred window of 2h + 1 holds a whole aligned block of h
    values (block (k - 1) // h for k >= 1, block 0 for k = 0), so that block's sum over the window's count
    bounds the pooled mean from below, and a value the bound clears cannot clear the mean. Noise puts ~1 %
    of 13,532 lines above 10 x the bound against ~0.01 % above 10 x the mean; a live frame asks this of the
    voltage's unexcited lines every period (the whole pooled mean: 0.1 ms).
    """
    window = max(1, int(window)) | 1
    n = values.shape[-1]
    if window == 1 or n < 2:
        pooled = pooled_mean(values, window)
        index = np.flatnonzero(test > factor * pooled)
        return index, pooled[index]
    half = window // 2
    block_of, scale = _block_bounds(n, window, float(factor))
    bound = np.add.reduceat(values, np.arange(0, n, half))[block_of]
    bound *= scale                  # factor / count, a hair under it: rounding never drops a true candidate
    candidates = np.flatnonzero(test > bound)
    padded = np.concatenate((np.zeros(half), values, np.zeros(half)))
    pooled = padded[candidates[:, None] + np.arange(window)].sum(axis=1) / _window_counts(n, window)[candidates]
    above = test[candidates] > factor * pooled
    return candidates[above], pooled[above]


@functools.lru_cache(maxsize=32)
def _block_bounds(n: int, window: int, factor: float) -> tuple[np.ndarray, np.ndarray]:
    """For each of n values: the aligned block of window // 2 that its window surely holds, and
    factor / (its window's count), lowered by 1e-12 relative."""
    half = window // 2
    block_of = np.maximum((np.arange(n) - 1) // half, 0)
    scale = factor * (1.0 - 1e-12) / _window_counts(n, window)
    block_of.flags.writeable = scale.flags.writeable = False
    return block_of, scale
