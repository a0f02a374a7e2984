import numpy as np
import pytest

from analysis.effects import parse_effects
from analysis.model.composed import Model
from analysis.recording.format import make_recording
from analysis.spectra import estimate_spectra, period_spectra, pooling_window
from analysis.synthesis import ChannelNoise
from tests.builders import PAPER, multitone, recording

FS, N = 48000, 4096


def _noise_recording(n_periods, sigma=1e-3, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(N * n_periods) / FS
    u = np.sin(2 * np.pi * 11 * FS / N * t)            # one excited line on bin 11
    return make_recording(FS, {"voltage": u + rng.normal(0, sigma, u.size),
                               "current": 0.1 * u + rng.normal(0, sigma, u.size)},
                          period_samples=N, excited_bins=(11,))


def test_a_sine_of_amplitude_a_reads_a_on_its_bin():
    x = 0.7 * np.cos(2 * np.pi * 37 * np.arange(N) / N + 0.3)
    spec = period_spectra(x[None, :])[0]
    assert abs(spec[37]) == pytest.approx(0.7, rel=1e-12)
    assert np.angle(spec[37]) == pytest.approx(0.3, abs=1e-12)
    assert np.max(np.abs(np.delete(spec, 37))) < 1e-12


def test_noise_floor_matches_white_noise_and_falls_with_sqrt_periods():
    sigma = 1e-3
    floors = {}
    for periods in (4, 16):
        sp = estimate_spectra(_noise_recording(periods, sigma))
        floor = sp.channels["voltage"].noise_floor[20:]
        # white noise of RMS sigma leaves 2*sigma/sqrt(N*P) on each averaged line
        assert np.sqrt(np.mean(floor**2)) == pytest.approx(2 * sigma / np.sqrt(N * periods), rel=0.05)
        floors[periods] = np.sqrt(np.mean(floor**2))
    assert floors[4] / floors[16] == pytest.approx(2.0, rel=0.05)


def test_excited_lines_found_in_the_voltage_spectrum_without_sidecar_bins():
    mt = multitone(period_samples=8192)
    rec = recording(mt=mt, noise=ChannelNoise(1e-4, 1e-4, 1e-8), write_excited_bins=False, n_periods=4)
    sp = estimate_spectra(rec)
    np.testing.assert_array_equal(sp.excited_bins, mt.excited_bins)
    assert sp.unexcited_bins.size > 0
    assert np.intersect1d(sp.unexcited_bins, mt.excited_bins).size == 0


def test_noise_free_transfer_functions_equal_the_model():
    mt = multitone(period_samples=8192)
    rec = recording(mt=mt, n_periods=3)
    sp = estimate_spectra(rec)
    model = Model(parse_effects("lr2,creep-log"))
    s = 2j * np.pi * sp.impedance.freqs
    np.testing.assert_allclose(sp.impedance.value, model.impedance(s, PAPER.parameters), rtol=1e-9)
    np.testing.assert_allclose(sp.displacement.value, model.displacement(s, PAPER.parameters), rtol=1e-9)


def test_reported_uncertainty_of_z_and_hx_matches_the_scatter_over_seeds():
    mt = multitone(period_samples=4096, f_min=20, f_max=5000)
    noise = ChannelNoise(voltage=1e-3, current=1e-3, displacement=1e-7)
    zs, hs, zstd, hstd = [], [], [], []
    for seed in range(40):
        sp = estimate_spectra(recording(mt=mt, noise=noise, n_periods=6, seed=seed))
        zs.append(sp.impedance.value), hs.append(sp.displacement.value)
        zstd.append(sp.impedance.std), hstd.append(sp.displacement.std)
    for values, stds in ((np.array(zs), np.array(zstd)), (np.array(hs), np.array(hstd))):
        observed = np.sqrt(np.mean(np.abs(values - values.mean(axis=0)) ** 2, axis=0) * 40 / 39)
        reported = np.sqrt(np.mean(np.array(stds) ** 2, axis=0))
        ratio = np.median(observed / reported)
        assert ratio == pytest.approx(1.0, abs=0.1)


def test_pooling_window_gives_enough_degrees_of_freedom():
    for periods in (2, 3, 4, 8, 16, 64):
        w = pooling_window(periods)
        assert w % 2 == 1
        assert 2 * (periods - 1) * w >= 40
    assert pooling_window(32) == 1
