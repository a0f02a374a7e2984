"""Whether a step's displacement repeated from period to period (analysis.large_signal.displacement_repeat).

The recordings are the fault bench's (instruments.simulation.faults): the paper's driver, linear and nonlinear,
with the bench's noise on every channel; the misplaced laser streams are cut from them the way a late time line
misplaces one: part of a period read after the drive stopped, or one period from a stretch a few ms off.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from analysis.excursion import recording_peak_displacement
from analysis.large_signal.displacement_repeat import MAX_DISPLACEMENT_CHANGE, displacement_change
from analysis.large_signal.stepping import StepMeasures, next_level, step_measures, stop_reason
from analysis.large_signal.stepping import StepLimits
from analysis.recording.format import make_recording
from instruments.simulation import faults
from tests.rig_xruns import BUSY_MACHINE

TWO_PERIODS = replace(faults.DEFAULT_BENCH, n_periods=2)       # what the large-signal plan averages


def with_displacement(rec, displacement: np.ndarray):
    signals = {c.signal: rec.signal(c.signal) for c in rec.channels}
    signals["displacement"] = displacement
    return make_recording(rec.sample_rate, signals, rec.period_samples, rec.settle_periods, rec.excited_bins)


def last_period(rec) -> slice:
    return slice(rec.n_samples - rec.period_samples, rec.n_samples)


@pytest.mark.parametrize("make", [faults.clean, faults.clean_nonlinear, faults.nonlinear_range, faults.low_snr],
                         ids=["clean", "nonlinear", "nonlinear-range", "low-snr"])
def test_a_displacement_that_repeats_with_its_drive_is_trusted(make):
    for bench in (faults.DEFAULT_BENCH, TWO_PERIODS):
        change = displacement_change(make(bench))
        assert change is not None and change < 0.1 * MAX_DISPLACEMENT_CHANGE, (make.__name__, change)


def test_a_voice_coil_warming_by_25_kelvin_within_the_step_is_still_trusted():
    """RE +10 % from the first period to the last: the displacement changes with it, by far less than a
    misplaced stream changes it."""
    change = displacement_change(faults.heating_drift(rise=0.1))
    assert 0.005 < change < 0.5 * MAX_DISPLACEMENT_CHANGE


def test_a_constant_laser_delay_is_no_change():
    """A link latency the alignment did not remove delays every period alike: the peak is the same."""
    rec = faults.clean_nonlinear(TWO_PERIODS)
    delayed = np.roll(rec.signal("displacement"), 24)       # 0.5 ms
    assert displacement_change(with_displacement(rec, delayed)) < 0.1 * MAX_DISPLACEMENT_CHANGE


def test_a_period_read_after_the_drive_stopped_is_not_trusted_and_stops_the_plan():
    rec = faults.clean_nonlinear(TWO_PERIODS)
    x = rec.signal("displacement").copy()
    tail = last_period(rec)
    x[tail] = np.random.default_rng(1).normal(0.0, faults.BENCH_NOISE.displacement, rec.period_samples)
    misplaced = with_displacement(rec, x)
    truth = recording_peak_displacement(rec)
    assert recording_peak_displacement(misplaced) < 0.6 * truth          # the peak it would have reported
    change = displacement_change(misplaced)
    assert change > 4 * MAX_DISPLACEMENT_CHANGE
    measured, _ = step_measures(misplaced, 0.3)
    assert measured.displacement_change == pytest.approx(change) and not measured.displacement_repeats
    code, words = stop_reason(measured, StepLimits(), measured.re_per_period[0])
    assert code == "fault" and "displacement" in words and "0.3 V" in words
    assert BUSY_MACHINE in words          # the rig's tests measure again on these words (tests/rig_xruns.py)


def test_one_period_from_a_stretch_a_few_ms_off_is_not_trusted():
    rec = faults.clean_nonlinear(TWO_PERIODS)
    x = rec.signal("displacement").copy()
    tail = last_period(rec)
    x[tail] = np.roll(x, 192)[tail]                         # 4 ms: one late host time stamp's worth
    assert displacement_change(with_displacement(rec, x)) > MAX_DISPLACEMENT_CHANGE


def test_without_a_displacement_nothing_is_judged():
    rec = faults.clean(TWO_PERIODS)
    signals = {c.signal: rec.signal(c.signal) for c in rec.channels if c.signal != "displacement"}
    bare = make_recording(rec.sample_rate, signals, rec.period_samples, rec.settle_periods, rec.excited_bins)
    assert displacement_change(bare) is None
    measured = StepMeasures(0.3, None, -60.0, (3.0, 3.0))
    assert measured.displacement_repeats and stop_reason(measured, StepLimits(), 3.0) is None
    assert next_level(measured, StepLimits(), 1.41)[0] == pytest.approx(0.3 * 1.41)
