"""One band of bins of the real FFT of a few rows of samples, every row transformed in a pair.

scipy's FFT (pocketfft) transforms the rows of a 2-D array two at a time with
vector instructions: two rows of 65,536 samples cost 0.82 ms, one alone
0.66, three 1.5 (load ~2). A live period has three rows (voltage, current,
displacement), so the third went alone. Here an odd last row is split into its
even and odd samples, two rows of half the length that go as a pair (0.40 ms),
and its band is put together again:

    X[k] = E[k] + exp(-2 pi i k / N) O[k]        (E, O: the N/2-point FFTs of x[0::2], x[1::2])

E and O hold bins 0 .. N/4, so this is done when the band ends at or below
N/4 (the project's band of 5 Hz .. 10 kHz at 48 kHz); otherwise, or for an odd
N, every row goes whole as before. The sum differs from the whole row's FFT
by float64 rounding only (~3e-16 of the row's largest line).
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import scipy.fft


class BandFFT:
    """Bins lo .. hi-1 of the FFT of `rows` rows of `samples` real samples, in a kept (rows, hi - lo) array."""

    def __init__(self, rows: int, samples: int, lo: int, hi: int):
        self.lo, self.hi = lo, hi
        self._split = rows % 2 == 1 and samples % 2 == 0 and hi - 1 <= samples // 4
        self._whole = np.empty((rows - 1 if self._split else rows, samples))   # the FFT works in it
        if self._split:
            self._halves = np.empty((2, samples // 2))
            self._twiddle = np.exp(-2j * np.pi * np.arange(lo, hi) / samples)
        self.band = np.empty((rows, hi - lo), dtype=np.complex128)

    def transform(self, rows: Sequence[np.ndarray]) -> np.ndarray:
        """The band of each row's FFT (unscaled), written into `band` and returned; the rows are not changed
        (they are copied into kept buffers, which the FFT overwrites)."""
        whole = self._whole.shape[0]
        for index in range(whole):
            self._whole[index] = rows[index]
        if whole:
            spectra = scipy.fft.rfft(self._whole, axis=-1, overwrite_x=True, workers=1)
            self.band[:whole] = spectra[:, self.lo:self.hi]
        if self._split:
            last = rows[whole]
            self._halves[0], self._halves[1] = last[0::2], last[1::2]
            even_odd = scipy.fft.rfft(self._halves, axis=-1, overwrite_x=True, workers=1)
            joined = np.multiply(even_odd[1, self.lo:self.hi], self._twiddle, out=self.band[whole])
            joined += even_odd[0, self.lo:self.hi]
        return self.band
