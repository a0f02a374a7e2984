"""Pieces of the GUI that need no window: formatting, axes, phases."""
from __future__ import annotations

import numpy as np
import pytest

from analysis.derived import ParameterValue
from app.results.parameter_table import format_value, short_value
from app.widgets.plots import LogFrequencyAxis
from app.results.curves import aligned_phase_deg


@pytest.mark.parametrize("value, std, scale, expected", [
    (3.0200021, 5.02e-6, 1.0, ("3.0200021", "0.0000050")),
    (70.5597, 0.057, 1.0, ("70.560", "0.057")),
    (0.000132, 1.4e-9, 1e3, ("0.1320000", "0.0000014")),
    (12345.6, 230.0, 1.0, ("12346", "230")),
    (2.5, None, 1.0, ("2.5", "–")),
])
def test_format_value_rounds_to_the_sigma(value, std, scale, expected):
    assert format_value(ParameterValue(name="x", value=value, std=std, unit="u", display_unit="u",
                                       display_scale=scale)) == expected


@pytest.mark.parametrize("value, std, expected", [
    (3.0200021, 5.02e-6, ("3.020", "0.000005")),    # the sigma allows more: four digits
    (70.5597, 0.057, ("70.56", "0.057")),
    (70.5597, 2.3, ("70.6", "2.3")),                # the sigma allows three
    (12345.6, 230.0, ("12350", "230")),
    (0.0123456, None, ("0.01235", "–")),            # no sigma: four digits
    (5.0, 40.0, ("5", "40")),                       # the sigma swamps it: one digit
    (9e-9, 1.9, ("0.0", "1.9")),                    # a value on its bound far below its sigma
    (-9e-9, 1.9, ("0.0", "1.9")),
])
def test_short_values_keep_what_the_sigma_supports_at_most_four_digits(value, std, expected):
    shown = ParameterValue(name="x", value=value, std=std, unit="u", display_unit="u", display_scale=1.0)
    assert short_value(shown) == expected


def test_missing_value_formats_empty():
    assert format_value(ParameterValue(name="Bl", value=None, std=None, unit="T*m", display_unit="T*m",
                                       display_scale=1.0, reason="why")) == ("", "")


@pytest.mark.parametrize("freq, text", [(10, "10"), (20, "20"), (50, "50"), (300, ""), (1000, "1k"),
                                        (2000, "2k"), (5, "5"), (10000, "10k"), (7, "")])
def test_frequency_axis_labels_one_two_five(freq, text):
    assert LogFrequencyAxis.frequency_text(np.log10(freq)) == text


def test_frequency_axis_ticks_stay_in_range(qapp):     # an AxisItem needs a QApplication
    axis = LogFrequencyAxis("bottom")
    levels = axis.logTickValues(np.log10(8.0), np.log10(12000.0), 800, [])
    values = [v for _, vs in levels for v in vs]
    assert min(values) >= np.log10(8.0) and max(values) <= np.log10(12000.0)
    assert np.log10(1000.0) in levels[0][1]


def test_phase_is_put_on_the_model_branch():
    freqs = np.geomspace(10, 1000, 50)
    phase = np.linspace(0, -4.0, 50)                       # radians, crosses -pi
    values = np.exp(1j * phase)
    ref = np.degrees(phase) - 360.0                         # the model sits one turn lower
    aligned = aligned_phase_deg(values, freqs, ref, freqs)
    assert aligned == pytest.approx(ref, abs=1e-9)
