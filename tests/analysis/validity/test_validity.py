"""The validity checks on recordings built for one property each (faults: test_validity_faults.py)."""
import json

import numpy as np
import pytest

from analysis.excursion import peak_excursion, peak_from_spectrum
from analysis.recording.format import make_recording, read_recording, write_recording
from analysis.spectra import estimate_spectra, period_spectra
from analysis.synthesis import ChannelNoise
from analysis.thresholds import DEFAULT_THRESHOLDS, ThresholdsError, ValidityThresholds, load_thresholds
from analysis.validity.assessment import ABSENT, assess
from analysis.validity.capture import CaptureInfo, CaptureInfoError
from tests.builders import TYPICAL_NOISE, multitone, recording

MT = multitone(period_samples=8192)
NOISY = ChannelNoise(voltage=1e-4, current=1e-4, displacement=2e-7)


def _with(rec, **signals):
    """The recording with some signals replaced (same excitation)."""
    data = {c.signal: rec.signal(c.signal) for c in rec.channels}
    data.update(signals)
    return make_recording(rec.sample_rate, data, rec.period_samples, rec.settle_periods, rec.excited_bins,
                          extra=dict(rec.extra))


def test_json_has_exactly_the_documented_shape_and_is_strict_json():
    doc = assess(recording(mt=MT, noise=NOISY, n_periods=6)).as_json()
    assert set(doc) == {"overall", "channels", "peak_displacement_m"}
    assert set(doc["channels"]) == {"voltage", "current", "displacement"}
    for channel in doc["channels"].values():
        assert set(channel) == {"status", "findings"}
    json.dumps(doc, allow_nan=False)


def test_a_clean_measurement_is_green_with_no_findings():
    v = assess(recording(mt=MT, noise=NOISY, n_periods=6))
    assert str(v.overall) == "green"
    assert all(ch.status == "green" and not ch.findings for ch in v.channels.values())
    assert v.channels["current"].measures["snr_db"] > 40


@pytest.mark.parametrize("n_periods", [2, 3, 8])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_noise_alone_never_reads_as_distortion_or_drift(n_periods, seed):
    v = assess(recording(mt=MT, noise=NOISY, n_periods=n_periods, seed=seed))
    for ch in v.channels.values():
        assert ch.measures["distortion_db"] < DEFAULT_THRESHOLDS.distortion_yellow_db - 2
        assert "drift" not in {f.code for f in ch.findings}


def test_a_noise_free_synthetic_recording_is_green_not_infinitely_distorted():
    v = assess(recording(mt=MT, n_periods=3))
    assert str(v.overall) == "green", v.as_json()


def test_without_displacement_the_channel_is_absent_and_does_not_count():
    v = assess(recording(mt=MT, noise=NOISY, displacement=False, n_periods=4))
    assert v.channels["displacement"].status == ABSENT
    assert v.as_json()["channels"]["displacement"] == {"status": "absent", "findings": []}
    assert str(v.overall) == "green"
    assert v.peak_displacement_m is None and v.as_json()["peak_displacement_m"] is None


def test_a_current_input_reading_exact_zeros_has_no_signal():
    rec = recording(mt=MT, noise=NOISY, n_periods=4)
    v = assess(_with(rec, current=np.zeros(rec.n_samples)))
    assert v.codes("current") == {"no-signal"}
    assert v.channels["current"].status == "red" and str(v.overall) == "red"
    finding = v.channels["current"].findings[0]
    assert "wiring" in finding.remedy and finding.value == 0.0


def test_a_weak_current_is_snr_low_with_the_number_in_the_message():
    rec = recording(mt=MT, noise=ChannelNoise(1e-4, 0.1, 2e-7), n_periods=4)
    v = assess(rec)
    (finding,) = [f for f in v.channels["current"].findings if f.code == "snr-low"]
    assert f"{finding.value:.1f} dB" in finding.message
    assert "raise the level" in finding.remedy
    assert str(finding.severity) in ("yellow", "red")


def test_thresholds_decide_the_severity():
    rec = recording(mt=MT, noise=NOISY, n_periods=4)
    strict = DEFAULT_THRESHOLDS.with_overrides({"snr_red_db": 150.0, "snr_yellow_db": 160.0})
    v = assess(rec, thresholds=strict)
    assert "snr-low" in v.codes("voltage") and v.channels["voltage"].status == "red"


def test_threshold_overrides_load_from_json_and_bad_ones_are_refused(tmp_path):
    good = tmp_path / "t.json"
    good.write_text(json.dumps({"x_band_red_hz": 250, "drift_red": 0.05}))
    th = load_thresholds(good)
    assert th.x_band_red_hz == 250 and th.drift_red == 0.05 and th.snr_red_db == DEFAULT_THRESHOLDS.snr_red_db
    for doc, words in (({"snr_red": 1}, "unknown threshold"), ({"snr_red_db": 50}, "must not exceed"),
                       ({"x_lines_red": 2.5}, "whole number"), ([1, 2], "JSON object")):
        bad = tmp_path / "bad.json"
        bad.write_text(json.dumps(doc))
        with pytest.raises(ThresholdsError, match=words):
            load_thresholds(bad)
    with pytest.raises(ThresholdsError):
        ValidityThresholds(snr_quantile=float("nan"))


def test_capture_info_in_the_sidecar_is_read_back_and_judged(tmp_path):
    capture = CaptureInfo(full_scale_fraction={"voltage": 0.95, "current": 0.4}, clipped_samples={"current": 3},
                          laser_samples=1000, laser_error_counts={262076: 2, 262078: 5})
    rec = recording(mt=MT, noise=NOISY, n_periods=4)
    rec = make_recording(rec.sample_rate, {c.signal: rec.signal(c.signal) for c in rec.channels},
                         rec.period_samples, rec.settle_periods, rec.excited_bins,
                         extra={"capture": capture.as_json()})
    write_recording(tmp_path / "r", rec)
    v = assess(read_recording(tmp_path / "r"))
    assert v.codes("voltage") == {"headroom-low"} and v.channels["voltage"].status == "yellow"
    assert v.codes("current") == {"clipping"} and v.channels["current"].status == "red"
    assert v.codes("displacement") == {"laser-errors", "laser-out-of-range"}
    by_code = {f.code: f for f in v.channels["displacement"].findings}
    assert str(by_code["laser-errors"].severity) == "yellow" and by_code["laser-errors"].value == pytest.approx(0.002)
    assert str(by_code["laser-out-of-range"].severity) == "red"


def test_a_capture_given_directly_overrides_nothing_but_adds_its_findings():
    rec = recording(mt=MT, noise=NOISY, n_periods=4)
    v = assess(rec, capture=CaptureInfo(dropouts={"displacement": 2}, xruns=1))
    assert v.codes("voltage") == {"dropouts"} == v.codes("current") == v.codes("displacement")
    assert v.channels["displacement"].findings[0].value == 2


@pytest.mark.parametrize("doc, words", [
    ({"xruns": -1}, "xruns"), ({"clipped_samples": {"current": 1.5}}, "whole number"),
    ({"laser_error_counts": {"abc": 1}}, "error code"), ({"bogus": 1}, "unknown"), ([], "object")])
def test_a_malformed_capture_object_is_refused_by_key(doc, words):
    with pytest.raises(CaptureInfoError, match=words):
        CaptureInfo.from_json(doc)


def test_peak_excursion_is_the_peak_of_the_coherent_mean():
    n, amplitude = 4096, 0.3e-3
    t = np.arange(n)
    x = amplitude * np.cos(2 * np.pi * 5 * t / n) + 1.7e-3               # a laser's offset too
    rng = np.random.default_rng(0)
    periods = x + rng.normal(0, 0.1e-3, (400, n))                        # noise 1/3 of the signal per sample
    assert peak_excursion(periods) == pytest.approx(amplitude, rel=0.08)
    assert np.max(np.abs(periods[0] - periods[0].mean())) > 1.5 * amplitude   # one period alone: inflated
    spectrum = period_spectra(periods).mean(axis=0)
    assert peak_from_spectrum(spectrum, n) == pytest.approx(peak_excursion(periods), rel=1e-9)


def test_the_reported_peak_is_that_of_the_recording():
    rec = recording(mt=MT, noise=TYPICAL_NOISE, n_periods=4)
    sp = estimate_spectra(rec)
    v = assess(rec, sp)
    x = rec.periods("displacement").mean(axis=0)
    assert v.peak_displacement_m == pytest.approx(np.max(np.abs(x - x.mean())), rel=1e-12)
    assert v.as_json()["peak_displacement_m"] == pytest.approx(v.peak_displacement_m)


def test_lines_without_any_noise_do_not_blind_the_laser_band_estimate():
    # A laser whose held samples repeat exactly gives lines of infinite SNR (seen on the serial laser's live
    # path); the pooled running sum must not turn every later line into NaN and cut the band short there.
    from analysis.validity.spectral import _band_findings
    freqs = np.geomspace(5.0, 10_000.0, 80)
    snr = np.full(freqs.size, 60.0)
    snr[40:45] = np.inf
    measures = {}
    with np.errstate(all="raise"):
        findings = _band_findings(snr, freqs, DEFAULT_THRESHOLDS, measures)
    assert measures["x_band_hz"] == freqs[-1]
    assert measures["x_lines"] == freqs.size
    assert not findings


@pytest.mark.parametrize("n, window", [(1, 5), (2, 5), (3, 5), (4, 33), (40, 5), (40, 33), (200, 4)])
def test_the_pooled_mean_is_each_centred_window_s_mean_even_around_huge_values(n, window):
    from analysis.validity.pooling import pooled_mean
    rng = np.random.default_rng(n)
    values = rng.uniform(1.0, 2.0, n)
    values[n // 2] = 1e30                    # a line far above the rest must not spoil the others
    half = (window | 1) // 2
    expected = [values[max(0, i - half):i + half + 1].mean() for i in range(n)]
    np.testing.assert_allclose(pooled_mean(values, window), expected, rtol=1e-12)
