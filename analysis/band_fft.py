"""One band of bins of the real FFT of a few rows of samples, every row transformed in a pair.

pocketfft transforms the rows of a 2-D array two at a time with vector
instructions: two rows of 65,536 samples cost 0.82 ms, one alone 0.66, three
1.5 (load ~2). A live period has three rows (voltage, current,
displacement), so the third went alone. Here an odd last row is split into its
even and odd samples, two rows of half the length that go as a pair (0.40 ms),
and its band is put together again:

    X[k] = E[k] + exp(-2 pi i k / N) O[k]        (E, O: the N/2-point FFTs of x[0::2], x[1::2])

E and O hold bins 0 .. N/4, so this is done when the band ends at or below
N/4 (the project's band of 5 Hz .. 10 kHz at 48 kHz); otherwise, or for an odd
N, every row goes whole as before. The sum differs from the whole row's FFT
by float64 rounding only (~3e-16 of the row's largest line).

numpy's FFT writes into kept arrays (out=), scipy's allocates its output
every call; either allocates scratch for a pair of rows (1 MB). Whether such a
block costs its pages' faults every call depends on the state of the C heap:
glibc maps blocks above a threshold that moves as the process frees memory,
and gives the heap's free top back above another. In one state a period paid
~350 page faults (2.2-2.5 ms for the FFT instead of 1.6, measured). So the
first BandFFT asks glibc (mallopt) to serve blocks up to 8 MB from the heap
and to keep up to 32 MB free at its top: the scratch's pages are faulted in
once. Elsewhere than glibc nothing is asked.
"""
from __future__ import annotations

import ctypes
import functools
import sys
from typing import Sequence

import numpy as np

_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3       # glibc's malloc.h
_HEAP_BLOCKS_UP_TO = 8 << 20
_HEAP_KEEPS_FREE = 32 << 20


class BandFFT:
    """Bins lo .. hi-1 of the FFT of `rows` rows of `samples` real samples, times `scale`, in a kept
    (rows, hi - lo) array (the scale applied as the band is copied out, not in a pass of its own)."""

    def __init__(self, rows: int, samples: int, lo: int, hi: int, scale: float = 1.0):
        _keep_scratch_in_heap()
        self.lo, self.hi, self.scale = lo, hi, float(scale)
        self._split = rows % 2 == 1 and samples % 2 == 0 and hi - 1 <= samples // 4
        whole = rows - 1 if self._split else rows
        self._whole = np.empty((whole, samples))       # the whole rows, unless they come as one array
        self._whole_spectra = np.empty((whole, samples // 2 + 1), dtype=np.complex128)
        if self._split:
            self._halves = np.empty((2, samples // 2))
            self._half_spectra = np.empty((2, samples // 4 + 1), dtype=np.complex128)
            self._twiddle = np.exp(-2j * np.pi * np.arange(lo, hi) / samples) * self.scale
        self.band = np.empty((rows, hi - lo), dtype=np.complex128)

    def transform(self, rows: Sequence[np.ndarray] | np.ndarray) -> np.ndarray:
        """The band of each row's FFT times `scale`, written into `band` and returned; the rows are not changed.
        Rows of one C-contiguous float64 array are read where they are; separate rows are copied together."""
        whole = self._whole.shape[0]
        if whole:
            if isinstance(rows, np.ndarray) and rows.dtype == np.float64 and rows.flags.c_contiguous:
                source = rows[:whole]
            else:
                for index in range(whole):
                    self._whole[index] = rows[index]
                source = self._whole
            spectra = np.fft.rfft(source, axis=-1, out=self._whole_spectra)
            np.multiply(spectra[:, self.lo:self.hi], self.scale, out=self.band[:whole])
        if self._split:
            last = rows[whole]
            self._halves[0], self._halves[1] = last[0::2], last[1::2]
            even_odd = np.fft.rfft(self._halves, axis=-1, out=self._half_spectra)
            joined = np.multiply(even_odd[1, self.lo:self.hi], self._twiddle, out=self.band[whole])
            joined += self.scale * even_odd[0, self.lo:self.hi]
        return self.band

    def row_sums(self) -> np.ndarray:
        """Each row's sum of samples, from the last transform's DC bins."""
        whole = self._whole_spectra[:, 0].real
        if not self._split:
            return whole.copy()
        return np.append(whole, self._half_spectra[0, 0].real + self._half_spectra[1, 0].real)


@functools.cache
def _keep_scratch_in_heap() -> bool:
    """Blocks of up to 8 MB from the heap, 32 MB kept free at its top (see the module doc); True if glibc
    took it."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt     # the process's own symbols: libc's, without a library search
    except (OSError, AttributeError):           # a C library without mallopt: nothing to ask
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return bool(mallopt(_M_MMAP_THRESHOLD, _HEAP_BLOCKS_UP_TO)) and bool(mallopt(_M_TRIM_THRESHOLD, _HEAP_KEEPS_FREE))
