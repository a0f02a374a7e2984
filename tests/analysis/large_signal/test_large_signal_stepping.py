"""The large-signal plan's decisions (analysis.large_signal.stepping): what a step measured, when to stop, the next level."""
from __future__ import annotations

import math
from dataclasses import replace

import pytest

from analysis.large_signal.stepping import (COPPER_ALPHA_PER_K, StepLimits, StepMeasures, next_level, step_measures,
                                            stop_reason)
from instruments.simulation import faults

LIMITS = StepLimits(max_excursion_m=4e-3, max_voltage_v=10.0, max_current_distortion_db=-20.0,
                    max_temperature_rise_k=20.0)


def step(level=1.0, peak=1e-3, distortion=-40.0, re=(3.0, 3.0), **changes) -> StepMeasures:
    return replace(StepMeasures(level, peak, distortion, re, drive_rms_v=level), **changes)


def test_a_warming_coil_is_seen_period_by_period():
    """faults.heating_drift: RE rises by 10 % over the recording: ~25 K of copper."""
    bench = replace(faults.DEFAULT_BENCH, n_periods=8)
    cold, lines = step_measures(faults.clean(bench), 0.3)
    warm, _ = step_measures(faults.heating_drift(bench, rise=0.1), 0.3, lines)
    assert cold.temperature_rise_k(cold.re_per_period[0]) == pytest.approx(0.0, abs=0.5)
    rises = [r / cold.re_per_period[0] - 1.0 for r in warm.re_per_period]
    assert all(b > a for a, b in zip(rises, rises[1:]))
    expected = 0.1 * 9 / 9 / COPPER_ALPHA_PER_K         # the last analysed period is the recording's last
    assert warm.temperature_rise_k(cold.re_per_period[0]) == pytest.approx(expected, rel=0.15)
    code, words = stop_reason(warm, LIMITS, cold.re_per_period[0])
    assert code == "temperature" and "K" in words


def test_a_clean_small_step_measures_what_the_validity_would():
    measured, _ = step_measures(faults.clean(), 0.3)
    assert measured.peak_m == pytest.approx(0.15e-3, rel=0.1)
    assert measured.current_distortion_db < -60.0 and measured.voltage_distortion_db < -60.0
    assert measured.drive_rms_v == pytest.approx(0.3, rel=0.01) and measured.clipped == ()
    distorted, _ = step_measures(faults.nonlinear_range(), 10.0)
    assert -50.0 < distorted.current_distortion_db < -15.0
    clipped, _ = step_measures(faults.adc_clipping(), 0.3)
    assert clipped.clipped == ("current",)
    amplifier, _ = step_measures(faults.amplifier_clipping(), 0.3)
    assert amplifier.voltage_distortion_db > -40.0


@pytest.mark.parametrize("changes, code", [
    ({"peak": 3.95e-3}, "excursion"),
    ({"distortion": -19.0}, "distortion"),
    ({"re": (3.0, 3.0 * (1 + 25 * COPPER_ALPHA_PER_K))}, "temperature"),
    ({"level": 9.9}, "voltage"),
    ({"voltage_distortion_db": -30.0}, "voltage"),
    ({"drive_rms_v": 0.7}, "voltage"),
    ({"clipped": ("current",)}, "clipping"),
    ({}, None),
])
def test_each_limit_stops_the_plan(changes, code):
    kwargs = {k: v for k, v in changes.items() if k in ("level", "peak", "distortion", "re")}
    extra = {k: v for k, v in changes.items() if k not in kwargs}
    reason = stop_reason(step(**kwargs, **extra), LIMITS, 3.0)
    assert (reason[0] if reason else None) == code


def test_the_next_level_is_shortened_near_a_limit():
    assert next_level(step(level=1.0, peak=0.5e-3), LIMITS, 1.41)[0] == pytest.approx(1.41)
    level, why = next_level(step(level=4.0, peak=3.5e-3), LIMITS, 1.41)
    assert why == "excursion" and level == pytest.approx(4.0 * 4.0 / 3.5)
    level, why = next_level(step(level=4.0, peak=1e-3, distortion=-24.0), LIMITS, 1.41)
    assert why == "distortion" and level == pytest.approx(4.0 * 10 ** (4.0 / 40.0))
    assert next_level(step(level=8.0, peak=1e-3), LIMITS, 1.41) == (10.0, "voltage")
    assert next_level(step(level=4.0, peak=3.99e-3), LIMITS, 1.41)[0] is None


def test_limits_that_are_not_numbers_in_range_are_refused():
    for bad in ({"max_excursion_m": math.nan}, {"max_voltage_v": -1.0}, {"max_current_distortion_db": 3.0},
                {"max_temperature_rise_k": math.inf}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            StepLimits(**bad)
