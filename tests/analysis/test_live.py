"""LiveAccumulator: Welford's running spectra equal the batch ones, and frames carry the per-frame lights."""
import numpy as np
import pytest

from analysis.live import DB_FLOOR, DISPLAY_BUCKETS, UNKNOWN, LiveAccumulator
from analysis.spectra import estimate_spectra
from analysis.synthesis import ChannelNoise
from tests.builders import multitone, recording

MT = multitone(period_samples=8192)
NOISE = ChannelNoise(voltage=1e-4, current=1e-4, displacement=2e-7)
SIGNALS = ("voltage", "current", "displacement")


def _periods(rec, p):
    return {s: rec.periods(s)[p] for s in SIGNALS}


def test_after_the_last_period_mean_and_variance_equal_estimate_spectra():
    rec = recording(mt=MT, noise=NOISE, n_periods=6)
    acc = LiveAccumulator(rec.sample_rate, rec.period_samples, MT.excited_bins)
    for p in range(rec.n_periods):
        acc.add_period(_periods(rec, p))
    batch = estimate_spectra(rec)
    lo = MT.excited_bins[0]
    for name, live in acc.channel_spectra().items():
        ref = batch.channels[name]
        band = slice(lo, lo + live.mean.size)
        np.testing.assert_allclose(live.mean, ref.mean[band], rtol=0, atol=1e-13 * np.max(np.abs(ref.mean)))
        np.testing.assert_allclose(live.var_mean, ref.var_mean[band], rtol=1e-8)


def test_the_first_frame_has_levels_but_no_noise_and_unknown_lights():
    rec = recording(mt=MT, noise=NOISE, n_periods=3)
    acc = LiveAccumulator(rec.sample_rate, rec.period_samples, MT.excited_bins)
    frame = acc.add_period(_periods(rec, 0))
    assert frame.n_periods == 1 and frame.status == UNKNOWN
    voltage = frame.channels["voltage"]
    assert voltage.status == UNKNOWN and np.all(np.isnan(voltage.noise_db))
    expected = 20 * np.log10(np.abs(np.fft.rfft(rec.periods("voltage")[0])[MT.excited_bins]) * 2 / MT.period_samples)
    np.testing.assert_allclose(voltage.line_db, expected, atol=1e-9)
    np.testing.assert_allclose(frame.line_freqs, MT.frequencies)


def test_frames_turn_green_and_the_noise_floor_falls_with_periods():
    rec = recording(mt=MT, noise=NOISE, n_periods=16)
    acc = LiveAccumulator(rec.sample_rate, rec.period_samples, MT.excited_bins)
    frames = [acc.add_period(_periods(rec, p)) for p in range(rec.n_periods)]
    assert all(f.status == "green" for f in frames[1:])
    floor = [np.mean(f.channels["current"].noise_db) for f in (frames[3], frames[15])]
    assert floor[0] - floor[1] == pytest.approx(10 * np.log10(16 / 4), abs=1.0)   # sqrt(P) in amplitude
    last = frames[-1]
    assert last.peak_displacement_m == pytest.approx(
        np.ptp(rec.periods("displacement").mean(axis=0)) / 2, rel=0.05)
    assert last.other_freqs.size == last.channels["voltage"].other_db.size > 0
    assert last.noise_freqs.size == last.channels["voltage"].noise_db.size > 0
    for ch in last.channels.values():
        for array in (ch.line_db, ch.other_db, ch.noise_db):
            assert not array.flags.writeable


def test_the_noise_floor_buckets_stand_at_the_injected_white_noise():
    """White noise of rms s per sample gives every bin of the peak-amplitude spectrum a variance of the mean
    4 s^2 / (N P) after P periods; the buckets, power means of their bins, stand there across the band, and
    the noise + distortion buckets (|mean|^2 at the unexcited bins: noise alone) with them."""
    periods = 16
    rec = recording(mt=MT, noise=NOISE, n_periods=periods)
    acc = LiveAccumulator(rec.sample_rate, rec.period_samples, MT.excited_bins)
    frame = [acc.add_period(_periods(rec, p)) for p in range(periods)][-1]
    assert frame.noise_freqs[0] >= MT.frequencies[0] and frame.noise_freqs[-1] <= MT.frequencies[-1]
    assert np.all(np.diff(frame.noise_freqs) > 0) and np.all(np.diff(frame.other_freqs) > 0)
    for name in SIGNALS:
        rms = getattr(NOISE, name)
        expected = 10 * np.log10(4 * rms**2 / (MT.period_samples * periods))
        ch = frame.channels[name]
        # A bucket of one bin scatters by ~1 dB (a variance from 16 periods); the many-bin buckets far less.
        assert np.median(ch.noise_db) == pytest.approx(expected, abs=0.5)
        assert np.median(ch.other_db) == pytest.approx(expected, abs=1.0)


def test_a_disconnected_current_turns_its_light_red_per_frame():
    rec = recording(mt=MT, noise=NOISE, n_periods=3)
    acc = LiveAccumulator(rec.sample_rate, rec.period_samples, MT.excited_bins)
    for p in range(3):
        period = _periods(rec, p)
        period["current"] = np.zeros(MT.period_samples)
        frame = acc.add_period(period)
    assert frame.channels["current"].status == "red" and frame.status == "red"
    assert {f.code for f in frame.channels["current"].findings} == {"no-signal"}
    assert np.all(frame.channels["current"].line_db == DB_FLOOR)
    assert frame.channels["voltage"].status == "green"


def test_rows_in_signal_order_and_reset():
    rec = recording(mt=MT, noise=NOISE, n_periods=2, displacement=False)
    acc = LiveAccumulator(rec.sample_rate, rec.period_samples, MT.excited_bins, signals=("voltage", "current"))
    frame = acc.add_period(np.stack([rec.periods("voltage")[0], rec.periods("current")[0]]))
    assert set(frame.channels) == {"voltage", "current"} and frame.peak_displacement_m is None
    acc.reset()
    assert acc.n_periods == 0
    with pytest.raises(ValueError, match="samples"):
        acc.add_period(np.zeros((2, 100)))
    with pytest.raises(ValueError, match="lacks"):
        acc.add_period({"voltage": np.zeros(MT.period_samples)})


@pytest.mark.parametrize("fault, channel, code", [("amplifier_clipping", "voltage", "distortion-high"),
                                                  ("nonlinear_range", "current", "distortion-high"),
                                                  ("current_disconnected", "current", "no-signal")])
def test_every_frame_judges_as_the_whole_recording_s_checks_on_the_same_spectra(fault, channel, code):
    # A frame gathers its band's lines itself and runs the checks on all channels at once; the whole
    # recording's path gathers them from each channel's spectrum. Same spectra, same findings and numbers.
    from analysis.validity.spectral import spectral_checks
    from analysis.thresholds import DEFAULT_THRESHOLDS
    from instruments.simulation import faults
    rec = getattr(faults, fault)()
    excited = np.asarray(rec.excited_bins)
    lo = int(excited[0])
    acc = LiveAccumulator(rec.sample_rate, rec.period_samples, excited)
    band_excited = excited - lo
    band_unexcited = np.setdiff1d(np.arange(excited[-1] - lo + 1), band_excited)
    seen = set()
    for p in range(rec.n_periods):
        frame = acc.add_period(_periods(rec, p))
        if p == 0:
            continue
        checks = spectral_checks(acc.channel_spectra(), band_excited, band_unexcited,
                                 rec.sample_rate / rec.period_samples, DEFAULT_THRESHOLDS, first_bin=lo)
        for name, live in frame.channels.items():
            findings, measures = checks[name]
            assert live.findings == tuple(findings), (p, name)
            assert dict(live.measures) == measures, (p, name)
            seen |= {(name, f.code) for f in live.findings}
    assert (channel, code) in seen              # the fault is judged, not only two empty lists compared


@pytest.mark.parametrize("fault", ["clean", "amplifier_clipping", "low_snr", "laser_bandwidth_low"])
def test_every_frame_says_what_the_float64_batch_path_says_on_the_same_periods(fault):
    # The live path takes its shortcuts (the third row's FFT from its even and odd samples, Welford's
    # running update, the excursion's centre from the DC bins); the batch path averages each period's whole
    # FFT. Same lights, same findings word for word; numbers within 1e-6 relative, drawn dB within 1e-6 dB.
    from analysis.excursion import peak_excursion
    from analysis.log_buckets import LogBuckets
    from analysis.recording.format import UNITS
    from analysis.spectra import ChannelSpectrum, period_spectra
    from analysis.thresholds import DEFAULT_THRESHOLDS
    from analysis.validity.findings import worst
    from analysis.validity.spectral import spectral_checks
    from instruments.simulation import faults
    rec = getattr(faults, fault)()
    excited = np.asarray(rec.excited_bins)
    lo, hi = int(excited[0]), int(excited[-1]) + 1
    band_excited = excited - lo
    band_unexcited = np.setdiff1d(np.arange(hi - lo), band_excited)
    acc = LiveAccumulator(rec.sample_rate, rec.period_samples, excited)
    spectra = {s: period_spectra(rec.periods(s))[:, lo:hi] for s in SIGNALS}
    bin_width = rec.sample_rate / rec.period_samples
    noise_buckets = LogBuckets(np.arange(lo, hi) * bin_width, DISPLAY_BUCKETS)
    judged = set()
    for p in range(rec.n_periods):
        frame = acc.add_period(_periods(rec, p))
        assert frame.peak_displacement_m == pytest.approx(peak_excursion(rec.periods("displacement")[:p + 1]),
                                                          rel=1e-9)
        if p == 0:
            continue
        reference = {}
        for s in SIGNALS:
            mean = spectra[s][:p + 1].mean(axis=0)
            dev = spectra[s][:p + 1] - mean
            var_mean = (dev.real**2 + dev.imag**2).sum(axis=0) / (p * (p + 1))
            reference[s] = ChannelSpectrum(s, UNITS[s], mean, var_mean)
        checks = spectral_checks(reference, band_excited, band_unexcited, bin_width, DEFAULT_THRESHOLDS,
                                 first_bin=lo)
        assert frame.status == str(worst(f.severity for findings, _ in checks.values() for f in findings))
        for name, live in frame.channels.items():
            findings, measures = checks[name]
            assert [(f.code, f.severity, f.message, f.remedy) for f in live.findings] == \
                [(f.code, f.severity, f.message, f.remedy) for f in findings], (p, name)
            np.testing.assert_allclose([f.value for f in live.findings], [f.value for f in findings], rtol=1e-6)
            assert live.measures.keys() == measures.keys()
            np.testing.assert_allclose(list(live.measures.values()), list(measures.values()),
                                       rtol=1e-6, atol=1e-6)
            ref = reference[name]
            np.testing.assert_allclose(live.line_db, 10 * np.log10(np.abs(ref.mean[band_excited]) ** 2), atol=1e-6)
            np.testing.assert_allclose(live.noise_db, noise_buckets.power_mean_db(ref.var_mean), atol=1e-6)
            judged |= {(name, f.code) for f in live.findings}
    assert judged or fault == "clean"           # a fault is judged, not only empty lists compared
