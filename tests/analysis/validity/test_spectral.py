"""The spectral checks' own statistics: the quantile and the pooled mean against numpy's."""
import warnings

import numpy as np
import pytest

from analysis.validity.spectral import pooled_mean, quantile


def _values(rng, n, kind):
    x = rng.standard_normal(n) * 10.0 ** rng.uniform(-5, 30)
    if kind == "ties":
        x = np.round(x / np.max(np.abs(x)) * 3)            # few distinct values, many repeated
    elif kind != "plain":
        x[rng.integers(0, n, size=1 + n // 10)] = {"inf": np.inf, "-inf": -np.inf, "nan": np.nan}[kind]
    return x


@pytest.mark.parametrize("kind", ["plain", "ties", "inf", "-inf", "nan"])
def test_the_quantile_is_numpy_s_bit_for_bit(kind):
    rng = np.random.default_rng(["plain", "ties", "inf", "-inf", "nan"].index(kind))
    for _ in range(400):
        n = int(rng.integers(1, 140))
        x = _values(rng, n, kind)
        for q in (0.0, 0.1, 0.5, 0.9, 1.0, float(rng.uniform())):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)   # inf - inf, as numpy's own
                expected = float(np.quantile(x, q))
                got = quantile(x.copy(), q)
            assert got == expected or (np.isnan(got) and np.isnan(expected)), (n, q, got, expected)


def test_the_quantile_leaves_its_input_alone_and_refuses_no_values():
    x = np.array([3.0, 1.0, 2.0])
    assert quantile(x, 0.5) == 2.0
    np.testing.assert_array_equal(x, [3.0, 1.0, 2.0])
    with pytest.raises(ValueError):
        quantile(np.zeros(0), 0.1)


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
