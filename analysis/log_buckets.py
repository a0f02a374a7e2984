"""Log-spaced buckets of a spectrum's bins, each shown as the power mean of its bins.

A live panel about 1000 pixels wide cannot show the ~13,500 bins of a
65,536-sample period; drawing them all cost ~100 ms a repaint. So the noise
floor and the noise + distortion are reduced to a few hundred log-spaced
buckets, each the power mean of its bins: what the validity check compares
band by band (analysis.validity.unexcited). Noise alone puts the two on top
of each other; one product 30 dB over the floor among ten bins still stands
20 dB out. The grouping depends on the frequencies only, so it is worked out
once per measurement and each frame costs one sum per bucket.
"""
from __future__ import annotations

import numpy as np

# A power at or below this is "nothing" (an exact zero is DB_FLOOR = -400 dB): left out of its bucket's mean.
NOTHING_DB = -399.0
_NOTHING_POWER = 10.0 ** (NOTHING_DB / 10.0)


class LogBuckets:
    """Sorted frequencies grouped into log-spaced buckets: starts of the groups and their centre frequencies."""

    def __init__(self, freqs: np.ndarray, n_buckets: int):
        log_f = np.log10(freqs)
        edges = np.linspace(log_f[0], log_f[-1], n_buckets + 1)
        index = np.clip(np.searchsorted(edges, log_f, side="right") - 1, 0, n_buckets - 1)
        self.starts = np.flatnonzero(np.r_[True, index[1:] != index[:-1]])
        self._sizes = np.diff(np.r_[self.starts, freqs.size])
        self.freqs = 10.0 ** (np.add.reduceat(log_f, self.starts) / self._sizes)
        self.freqs.flags.writeable = False

    def power_mean_db(self, power: np.ndarray) -> np.ndarray:
        """10 log10 of the mean of each bucket's powers above nothing (last axis); NaN for a bucket without any
        (NaN powers, unknown, are left out too)."""
        if power.size and power.min() > _NOTHING_POWER:
            # The usual frame: every bin counts (a NaN makes the minimum NaN, so it takes the other path); the
            # buckets' sizes are known, none is empty: no mask, no counts.
            db = np.log10(np.add.reduceat(power, self.starts, axis=-1) / self._sizes)
            db *= 10.0
            return db
        shown = power > _NOTHING_POWER
        sums = np.add.reduceat(np.where(shown, power, 0.0), self.starts, axis=-1)
        counts = np.add.reduceat(shown.astype(np.int64), self.starts, axis=-1)
        with np.errstate(invalid="ignore", divide="ignore"):
            db = 10.0 * np.log10(sums / counts)
        db[counts == 0] = np.nan
        return db
