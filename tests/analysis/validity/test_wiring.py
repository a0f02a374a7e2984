"""A scaled copy of another channel: found below the limit with its own residual, never near a driver's."""
import numpy as np
import pytest

from analysis.thresholds import DEFAULT_THRESHOLDS as TH
from analysis.validity.wiring import copy_findings


def _exact_residual(x, y):
    gain = np.sum(np.conj(x) * y) / np.sum(np.abs(x) ** 2)
    return float(np.sum(np.abs(y - gain * x) ** 2) / np.sum(np.abs(y) ** 2))


@pytest.mark.parametrize("deviation", [0.0, 1e-7, 1e-4, 3e-3, 9.9e-3, 1.01e-2, 2e-2, 0.3])
def test_a_copy_is_found_exactly_when_its_residual_is_below_the_limit_and_reports_that_residual(deviation):
    rng = np.random.default_rng(11)
    f = np.geomspace(5, 10000, 90)
    u = np.exp(1j * rng.uniform(0, 2 * np.pi, f.size))
    z = 6.3 + 1j * f * 4e-4                         # a resistor and an inductance: the same at every line
    wobble = deviation * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)) / np.sqrt(2)
    i = u / z * (1 + wobble)
    x = u * 1e-3 / (1 + 1j * f / 60.0) ** 2                       # a driver's displacement: no copy of either
    found = copy_findings({"voltage": u, "current": i, "displacement": x}, set(), TH)
    residual = _exact_residual(u, i)
    assert ("current" in found) == (residual < TH.copy_residual_red)
    if "current" in found:
        assert found["current"].value == residual
    assert "displacement" not in found


def test_a_silent_or_nan_channel_is_left_to_the_other_checks():
    u = np.ones(50, dtype=complex)
    lines = {"voltage": u, "current": 0.5 * u, "displacement": np.full(50, np.nan + 0j)}
    found = copy_findings(lines, {"current"}, TH)
    assert found == {}
