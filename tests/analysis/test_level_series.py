"""Level series (docs/physics.md section 6, Table II): the parameters drift with the excursion as the paper's did.

The series is measured on the simulated nonlinear driver (the paper's driver,
softening with excursion). Asserted on the trend, not on exact numbers: fs
falls and Cms rises monotonically within the uncertainties from ~0.1 mm to
~8 mm peak, the smallest level is the small-signal driver, and the large
levels are flagged by the validity.
"""
import json
import math
import random

import numpy as np
import pytest

from analysis.derived import ParameterValue, derived_from_values
from analysis.level_series import (TABLE_PARAMETERS, LevelSeriesError, concise, drive_rms, format_series,
                                   level_series, small_signal_reasons)
from analysis.pipeline import analyze_recording
from analysis.validity.result import ResultValidity
from instruments.simulation.level_series import check_levels, simulate_level_series
from tests.builders import PAPER, TYPICAL_NOISE, recording

# ~0.10, 0.51, 1.6, 3.7, 8.5 mm peak.
LEVELS_V = (0.2, 1.0, 3.0, 7.0, 14.0)


@pytest.fixture(scope="module")
def results():
    """The simulated series, analysed (~3 s: the driver takes ~0.5 s a level, the multitone ~1 s once)."""
    return [analyze_recording(r) for r in simulate_level_series(LEVELS_V)]


@pytest.fixture(scope="module")
def series(results):
    shuffled = list(results)
    random.Random(3).shuffle(shuffled)      # the series sorts by excursion, whatever the order given
    return level_series(shuffled)


def test_levels_are_sorted_by_excursion_and_span_the_papers_range(series):
    peaks = series.peaks_m
    assert np.all(np.diff(peaks) > 0)
    assert 0.05e-3 < peaks[0] < 0.2e-3 and 5e-3 < peaks[-1] < 10e-3
    # The drive level is read from the measured voltage.
    assert [level.drive_rms_v for level in series.levels] == pytest.approx(LEVELS_V, rel=1e-3)


def _monotone(values, stds, sign):
    """Each step goes the `sign` way, or back by less than two combined sigma."""
    steps = sign * np.diff(values)
    allowed = 2 * np.hypot(stds[1:], stds[:-1])
    return bool(np.all(steps > -allowed))


def test_fs_falls_and_cms_rises_with_level_as_in_the_paper(series):
    fs, fs_std = series.column("fs")
    cms, cms_std = series.column("Cms")
    assert _monotone(fs, fs_std, -1) and _monotone(cms, cms_std, +1)
    # The paper: fs 70.5 -> 57.1 Hz (-19 %), Cms +50 % at 8.6 mm. The trend, and roughly its size.
    top = series.levels[-1]
    assert -30 < top.drift["fs"].percent < -10
    assert 30 < top.drift["Cms"].percent < 80
    # Kms is 1/Cms: it falls; the drift is significant against its own uncertainty.
    assert top.drift["Kms"].percent < 0 and abs(top.drift["Cms"].percent) > 3 * top.drift["Cms"].std


def test_smallest_level_is_the_small_signal_driver(series):
    expected = {**derived_from_values(PAPER.parameters), **PAPER.parameters}
    first = series.reference
    for name in TABLE_PARAMETERS:
        assert first.value(name) == pytest.approx(expected[name], rel=0.01), name


def test_large_levels_are_flagged_not_small_signal_by_the_validity(series):
    first = series.levels[0]
    assert first.small_signal and first.validity == "green" and first.reasons == ()
    for level in series.levels:
        if level.peak_displacement_m > 1e-3:
            assert not level.small_signal
            assert any(r.startswith("distortion-high") for r in level.reasons), level.reasons


def test_drift_is_relative_to_the_smallest_level_with_propagated_uncertainty(series):
    ref, top = series.levels[0], series.levels[-1]
    assert all(d.percent == 0 for d in ref.drift.values())
    p, p0 = top.parameters["Bl"], ref.parameters["Bl"]
    assert top.drift["Bl"].percent == pytest.approx(100 * (p.value / p0.value - 1))
    assert top.drift["Bl"].std == pytest.approx(
        100 * p.value / p0.value * math.hypot(p.std / p.value, p0.std / p0.value))


def test_fig14_data_and_json(series):
    curve = series.fs_curve()
    assert curve["peak_displacement_m"] == pytest.approx(list(series.peaks_m))
    assert curve["fs_hz"][0] > curve["fs_hz"][-1]
    assert curve["small_signal"][0] and not curve["small_signal"][-1]
    doc = json.loads(json.dumps(series.as_json(), allow_nan=False))
    assert doc["n_levels"] == len(LEVELS_V) and doc["fs_vs_peak"]["fs_hz"] == curve["fs_hz"]
    assert doc["levels"][-1]["parameters"]["Cms"]["unit"] == "m/N"
    assert set(doc["levels"][0]["drift"]) == set(TABLE_PARAMETERS)


def test_text_table_has_a_row_per_level(series):
    text = format_series(series)
    assert f"{len(LEVELS_V)} levels" in text and "[mm/N]" in text
    ends = [[f"{level.drive_rms_v:.3g}", f"{level.peak_displacement_m * 1e3:.3f}"]
            for level in (series.levels[0], series.levels[-1])]
    rows = [line for line in text.splitlines() if line.split()[:2] in ends]
    assert len(rows) == 4          # the table and the drift table, first and last level
    assert "not small-signal:" in text and "distortion-high on current" in text


def test_results_paths_and_recordings_mix(tmp_path, results):
    from analysis.recording.format import write_recording
    rec = recording(noise=TYPICAL_NOISE, n_periods=4, seed=5)       # linear, 1 V RMS
    wav, _ = write_recording(tmp_path / "linear", rec)
    s = level_series([results[0], wav, rec])
    assert len(s.levels) == 3 and s.levels[-1].drive_rms_v == pytest.approx(1.0, rel=1e-3)
    assert [str(wav)] == [level.source for level in s.levels if level.source]


def test_a_recording_without_laser_cannot_join_a_series():
    rec = recording(noise=TYPICAL_NOISE, n_periods=4, displacement=False)
    with pytest.raises(LevelSeriesError, match="no displacement channel"):
        level_series([rec])
    with pytest.raises(LevelSeriesError):
        level_series([])


def test_drive_rms_is_the_voltage_rms():
    rec = recording(noise=TYPICAL_NOISE, n_periods=4)
    assert drive_rms(analyze_recording(rec)) == pytest.approx(np.std(rec.periods("voltage")), rel=1e-3)


def test_small_signal_reasons():
    def finding(code, severity="red"):
        return {"code": code, "severity": severity}
    def reasons(doc):
        return small_signal_reasons(ResultValidity.from_json(doc))
    green = {"overall": "green", "channels": {"current": {"findings": []}}}
    assert reasons(green) == ()
    distorted = {"overall": "yellow", "channels": {"current": {"findings": [finding("distortion-high", "yellow")]}}}
    assert reasons(distorted) == ("distortion-high on current (yellow)",)
    noisy = {"overall": "yellow", "channels": {"current": {"findings": [finding("snr-low", "yellow")]}}}
    assert reasons(noisy) == ("validity yellow: snr-low",)
    assert reasons({"overall": "unknown"}) == ("validity unknown",)


@pytest.mark.parametrize("value, std, text", [
    (70.55519, 0.00073, "70.55519(73)"), (0.4296, 0.0021, "0.4296(21)"), (1234.5, 12.0, "1234(12)"),
    (5.2, None, "5.2"), (None, None, "n/a"), (-17.73, 0.89, "-17.73(89)"), (3.0, 0.0, "3")])
def test_concise_notation(value, std, text):
    assert concise(value, std) == text


def test_simulated_levels_are_checked():
    with pytest.raises(ValueError, match="at most"):
        check_levels((1.0, 30.0))
    with pytest.raises(ValueError, match="no levels"):
        check_levels(())


def test_parameter_values_keep_their_units(series):
    p = series.levels[0].parameters["Cms"]
    assert isinstance(p, ParameterValue) and p.unit == "m/N" and p.display_unit == "mm/N"


def test_level_is_built_by_keyword_only():
    import dataclasses

    from analysis.level_series import Level
    assert all(field.kw_only for field in dataclasses.fields(Level))
