"""Repeatability over repeated results: mean, sample standard deviation and percent, as Table I."""
import numpy as np
import pytest

from analysis.derived import ParameterValue
from analysis.repeatability import format_spread, repeatability


def table(**values):
    return {n: ParameterValue(name=n, value=v, std=None if v is None else 0.01 * abs(v),
                              unit="kg" if n == "Mms" else "T*m", display_unit="g" if n == "Mms" else "T*m",
                              display_scale=1e3 if n == "Mms" else 1.0)
            for n, v in values.items()}


def test_mean_std_and_percent_as_the_paper_reports_them():
    bl = [5.20, 5.23, 5.25, 5.24]
    spreads = repeatability([table(Bl=b, Mms=m) for b, m in zip(bl, [11.8e-3, 11.9e-3, 11.9e-3, 11.85e-3])])
    s = spreads["Bl"]
    assert s.n == 4 and s.mean == pytest.approx(np.mean(bl))
    assert s.std == pytest.approx(np.std(bl, ddof=1)) and s.percent == pytest.approx(100 * s.std / s.mean)
    assert s.mean_fit_std == pytest.approx(0.01 * np.mean(bl))
    assert list(spreads) == ["Bl", "Mms"]
    text = format_spread(spreads, 4)
    assert "4 results" in text and any(line.startswith("Mms") and line.endswith("g") for line in text.splitlines())


def test_missing_values_and_single_results():
    spreads = repeatability([table(Bl=5.0, Mms=None), table(Bl=5.2)])
    assert spreads["Bl"].n == 2 and spreads["Mms"].n == 0 and spreads["Mms"].mean is None
    one = repeatability([table(Bl=5.0)])["Bl"]
    assert one.std is None and one.percent is None and one.as_json()["mean"] == 5.0


def test_recordings_repeated_with_fresh_noise_spread_like_their_own_uncertainty():
    from analysis.pipeline import analyze_recording
    from tests.builders import TYPICAL_NOISE, recording
    results = [analyze_recording(recording(noise=TYPICAL_NOISE, n_periods=4, seed=seed)) for seed in range(5)]
    s = repeatability([r.parameters for r in results])["Bl"]
    assert s.n == 5 and 0 < s.std < 4 * s.mean_fit_std
