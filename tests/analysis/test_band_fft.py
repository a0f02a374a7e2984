"""A band of the rows' FFT, an odd last row put together from its even and odd samples: the whole FFT's values."""
import sys

import numpy as np
import pytest

from analysis.band_fft import BandFFT


@pytest.mark.parametrize("rows, samples, lo, hi", [
    (3, 65536, 7, 13654),       # the project's period: the third row split
    (3, 4096, 1, 1025),         # the band up to N/4 exactly
    (3, 4096, 3, 1500),         # beyond N/4: every row whole
    (1, 4096, 2, 900),          # one row alone, split
    (2, 4096, 2, 900),          # a pair: nothing split
    (3, 4095, 2, 900),          # odd N: nothing split
])
def test_the_band_is_the_whole_fft_s_and_the_rows_are_left_as_they_were(rows, samples, lo, hi):
    rng = np.random.default_rng(samples + rows)
    t = np.arange(samples)
    data = rng.standard_normal((rows, samples)) * [[1.0], [1e-3], [5e-4]][:rows]
    data += np.cos(2 * np.pi * 13 * t / samples)[None, :] * np.arange(1, rows + 1)[:, None] + 0.3   # a line, an offset
    before = data.copy()
    fft = BandFFT(rows, samples, lo, hi, scale=2.0 / samples)
    for source in (list(data), data):                   # separate rows, one array; the kept buffers reused
        got = fft.transform(source)
    expected = np.fft.rfft(before, axis=-1)[:, lo:hi] * (2.0 / samples)
    for row in range(rows):
        scale = np.max(np.abs(expected[row]))
        np.testing.assert_allclose(got[row], expected[row], rtol=0, atol=1e-13 * scale)
    np.testing.assert_array_equal(data, before)
    np.testing.assert_allclose(fft.row_sums(), before.sum(axis=-1), rtol=1e-12)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="page faults per thread are counted on Linux only")
def test_a_period_s_transform_faults_no_fresh_pages_in():
    # pocketfft allocates 1 MB of scratch for a pair of rows every call; mapped afresh each time, that is ~256
    # page faults a call (~350 a live period measured). BandFFT keeps such blocks in the heap.
    import resource
    rows = np.random.default_rng(5).standard_normal((3, 65536))
    fft = BandFFT(3, 65536, 7, 13654)
    for _ in range(3):
        fft.transform(rows)
        fft.transform(list(rows))
    before = resource.getrusage(resource.RUSAGE_THREAD).ru_minflt
    for _ in range(5):
        fft.transform(rows)
        fft.transform(list(rows))
    assert resource.getrusage(resource.RUSAGE_THREAD).ru_minflt - before < 64
