"""Capability indices as estimates: their confidence intervals cover the truth as often as they claim, and a
handful of units is not a verdict."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import chi2

from analysis.production.capability import capability
from analysis.production.capability_interval import (MIN_UNITS, centred_interval, spread_interval, too_few,
                                                     _chi2_quantile)


@pytest.mark.parametrize("n", [10, 25, 100])
def test_the_chi_square_quantiles_match_scipys(n):
    for p in (0.025, 0.975):
        assert _chi2_quantile(p, n - 1) == pytest.approx(chi2.ppf(p, n - 1), rel=0.01)


@pytest.mark.parametrize("n", [25, 60])
def test_the_intervals_cover_the_true_index_about_95_percent_of_the_time(n):
    """Units drawn from a process whose Cp is 1.5 and Cpk 1.2: the intervals from each sample of n units."""
    rng = np.random.default_rng(7)
    sigma, low, high = 1.0, -4.5, 4.5                        # Cp = 9 / 6 = 1.5
    mean = high - 3 * 1.2 * sigma                            # Cpk = 1.2
    cover_cpk = cover_cp = 0
    trials = 1500
    for _ in range(trials):
        c = capability(rng.normal(mean, sigma, n), low, high)
        lo, hi = centred_interval(c.ppk, n)
        cover_cpk += lo <= 1.2 <= hi
        lo, hi = spread_interval(c.pp, n)
        cover_cp += lo <= 1.5 <= hi
    assert 0.92 <= cover_cpk / trials <= 0.98
    assert 0.92 <= cover_cp / trials <= 0.98


def test_four_units_give_a_wide_interval_and_a_reason():
    lo, hi = centred_interval(27.6, 4)          # the Re: Cpk 27.6 from 4 units
    assert lo < 10 and hi > 40
    assert "only 4 units" in too_few(4) and str(MIN_UNITS) in too_few(4)
    assert too_few(MIN_UNITS) == "" and centred_interval(None, 30) is None and spread_interval(1.0, 1) is None
