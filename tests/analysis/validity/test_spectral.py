"""The spectral checks' own statistics: the quantile against numpy's."""
import warnings

import numpy as np
import pytest

from analysis.validity.spectral import quantile


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
