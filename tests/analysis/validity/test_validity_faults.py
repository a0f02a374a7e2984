"""Each fault of instruments.simulation.faults is judged on the right channel with the right code."""
import pytest

from analysis.validity.assessment import assess
from instruments.simulation import faults

CHANNELS = ("voltage", "current", "displacement")


def _judged(recording):
    v = assess(recording)
    return v, {name: {f.code: str(f.severity) for f in v.channels[name].findings} for name in CHANNELS}


def test_a_clean_small_signal_measurement_is_green_on_every_channel():
    v, found = _judged(faults.clean())
    assert str(v.overall) == "green", found
    assert v.peak_displacement_m < 0.5e-3


def test_the_nonlinear_driver_at_a_small_level_is_green_too():
    v, found = _judged(faults.clean_nonlinear(faults.Bench(level_rms=0.1)))
    assert str(v.overall) == "green", found


# fault, its channel, its code, its severity; the other channels must not carry that code.
CASES = [
    ("current_disconnected", "current", "no-signal", "red"),
    ("laser_disconnected", "displacement", "no-signal", "red"),
    ("amplifier_clipping", "voltage", "distortion-high", "red"),
    ("low_snr", "current", "snr-low", "red"),
    ("nonlinear_range", "current", "distortion-high", "red"),
    ("laser_bandwidth_low", "displacement", "x-band-low", "red"),
    ("laser_out_of_range", "displacement", "laser-out-of-range", "red"),
    ("laser_errors", "displacement", "laser-errors", "red"),
    ("adc_clipping", "current", "clipping", "red"),
    ("dropouts", "voltage", "dropouts", "red"),
    ("heating_drift", "current", "drift", "red"),
]


@pytest.mark.parametrize("fault, channel, code, severity", CASES, ids=[c[0] for c in CASES])
def test_each_fault_is_caught_on_its_channel(fault, channel, code, severity):
    v, found = _judged(getattr(faults, fault)())
    assert found[channel].get(code) == severity, found
    assert v.channels[channel].status == severity
    assert str(v.overall) == severity
    finding = next(f for f in v.channels[channel].findings if f.code == code)
    assert finding.message and finding.remedy


def test_a_clipping_amplifier_is_blamed_on_the_voltage_not_on_the_driver():
    _, found = _judged(faults.amplifier_clipping())
    assert "distortion-high" not in found["current"] and "distortion-high" not in found["displacement"], found


def test_a_disconnected_current_or_laser_leaves_the_other_channels_alone():
    for fault, broken in (("current_disconnected", "current"), ("laser_disconnected", "displacement")):
        v, found = _judged(getattr(faults, fault)())
        assert set(found[broken]) == {"no-signal"}
        assert all(v.channels[name].status == "green" for name in CHANNELS if name != broken), found


def test_the_driver_leaving_its_linear_range_shows_in_displacement_too_with_lower_the_level():
    v, found = _judged(faults.nonlinear_range())
    assert found["displacement"].get("distortion-high") == "red"
    assert found["voltage"] == {}
    finding = next(f for f in v.channels["displacement"].findings if f.code == "distortion-high")
    assert "lower the level" in finding.remedy
    assert v.peak_displacement_m > 3e-3


def test_a_laser_too_slow_for_the_resonance_reports_its_band_edge():
    v, _ = _judged(faults.laser_bandwidth_low())
    band = v.channels["displacement"].measures["x_band_hz"]
    assert 100 < band < 300
    finding = next(f for f in v.channels["displacement"].findings if f.code == "x-band-low")
    assert f"{band:.0f} Hz" in finding.message


def test_a_small_share_of_laser_errors_is_only_yellow():
    _, found = _judged(faults.laser_errors(share=0.001))
    assert found["displacement"].get("laser-errors") == "yellow"


def test_a_slow_drift_is_yellow():
    _, found = _judged(faults.heating_drift(rise=0.04))
    assert found["current"].get("drift") == "yellow"


def test_the_drift_check_reuses_the_spectra_transform_and_finds_the_same(monkeypatch):
    """drift_findings reads the per-period spectra estimate_spectra kept, and gets what transforming the periods
    again gives: a spectra object without them (built elsewhere) takes the old path."""
    import dataclasses

    from analysis.spectra import estimate_spectra
    from analysis.thresholds import DEFAULT_THRESHOLDS
    from analysis.validity import drift

    recording = faults.heating_drift(rise=0.04)
    spectra = estimate_spectra(recording)
    assert set(spectra.excited_per_period) == set(spectra.channels)
    again = drift.drift_findings(recording, dataclasses.replace(spectra, excited_per_period={}), DEFAULT_THRESHOLDS)

    def no_second_transform(_periods):
        raise AssertionError("the periods were transformed again")

    monkeypatch.setattr(drift, "period_spectra", no_second_transform)
    kept = drift.drift_findings(recording, spectra, DEFAULT_THRESHOLDS)
    assert kept.keys() == again.keys()
    for name in kept:
        assert kept[name][1] == pytest.approx(again[name][1], rel=1e-12, nan_ok=True)
        assert [f.code for f in kept[name][0]] == [f.code for f in again[name][0]]
    assert kept["current"][0] and kept["current"][1] > 0.01        # the injected 4 % rise is found
