"""Pooled means: each centred window's own mean, the same for each size the kept windows serve, row by row
on a 2-D array, and a huge or infinite value spoiling only its own windows."""
import numpy as np
import pytest

from analysis.validity.pooling import pooled_mean


def test_the_pooled_mean_gives_the_same_for_each_size_its_kept_windows_serve():
    rng = np.random.default_rng(3)
    for n in (5, 33, 200, 13532):
        values = rng.uniform(size=n) * 10.0 ** rng.uniform(0, 20, size=n)
        first = pooled_mean(values, 33)
        again = pooled_mean(values.copy(), 33)          # the kept kernel and counts, not rebuilt
        np.testing.assert_array_equal(first, again)
        half = 16
        expected = [values[max(0, i - half):i + half + 1].mean() for i in range(n)]
        np.testing.assert_allclose(first, expected, rtol=1e-12)


@pytest.mark.parametrize("window", [3, 5, 33, 65])
def test_a_huge_or_infinite_value_spoils_only_the_windows_that_hold_it(window):
    values = np.full(400, 2.0)
    values[100], values[250] = 1e300, np.inf
    pooled = pooled_mean(values, window)
    half = window // 2
    near = np.zeros(400, dtype=bool)
    for spot in (100, 250):
        near[spot - half:spot + half + 1] = True
    np.testing.assert_array_equal(pooled[~near], 2.0)      # exactly: no cancellation after the huge values
    assert np.all(pooled[250 - half:250 + half + 1] == np.inf)
    np.testing.assert_allclose(pooled[100 - half:100 + half + 1], 1e300 / window, rtol=1e-15)


@pytest.mark.parametrize("n, window", [(1, 5), (3, 33), (113, 9), (13532, 33)])
def test_the_pooled_mean_of_a_2d_array_is_each_row_s_bit_for_bit(n, window):
    # The live checks pool the three channels' noise in one call: the same values as one channel at a time.
    rng = np.random.default_rng(n)
    rows = rng.uniform(size=(3, n)) * 10.0 ** rng.uniform(-10, 20, size=(3, n))
    rows[1, n // 2] = np.inf
    together = pooled_mean(rows, window)
    for row in range(3):
        np.testing.assert_array_equal(together[row], pooled_mean(rows[row].copy(), window))
