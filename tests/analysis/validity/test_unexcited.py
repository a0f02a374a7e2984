"""Noise + distortion on the unexcited lines: what the voltage explains comes off the current and the
displacement; what it does not stays, on every judged channel at once."""
import numpy as np

from analysis.thresholds import DEFAULT_THRESHOLDS as TH
from analysis.validity.line_spectra import LineSpectra
from analysis.validity.unexcited import distortion_bands, unexcited_measures

SIGNALS = ("voltage", "current", "displacement")
NOISE_VAR = 1e-10


def _spectra(seed, x_own_distortion):
    """A 5 Hz grid from 20 Hz, every 7th bin excited; the amplifier distorts on every 50th unexcited bin.
    The current follows the voltage through Z (H = 1/Z); the displacement through Hx, plus its own
    distortion on the same bins when asked."""
    rng = np.random.default_rng(seed)
    freqs = 20.0 + 5.0 * np.arange(2000)
    excited = np.arange(0, freqs.size, 7)
    unexcited = np.setdiff1d(np.arange(freqs.size), excited)
    h_current = 0.125 / (1 + 1j * freqs / 2000.0)
    h_x = 0.05 / (1 + 1j * freqs / 300.0)
    u = np.sqrt(NOISE_VAR / 2) * (rng.standard_normal(freqs.size) + 1j * rng.standard_normal(freqs.size))
    u[excited] = 1.0
    distorted = unexcited[::50]
    u[distorted] = 1e-2 * np.exp(1j * rng.uniform(0, 2 * np.pi, distorted.size))
    noise = lambda: np.sqrt(NOISE_VAR / 2) * (rng.standard_normal(freqs.size) + 1j * rng.standard_normal(freqs.size))
    mean = np.stack([u, h_current * u + noise(), h_x * u + noise()])
    mean[:, excited] = np.stack([u, h_current * u, h_x * u])[:, excited]
    mean[2, distorted] += x_own_distortion
    var = np.full((3, freqs.size), NOISE_VAR)
    spectra = LineSpectra.of_band(SIGNALS, mean, var, excited, unexcited)
    other_freqs = freqs[unexcited]
    bands = distortion_bands(other_freqs, TH.distortion_band_octaves, TH.distortion_min_bins)
    return spectra, freqs[excited], other_freqs, bands


def test_the_voltage_s_part_comes_off_the_current_and_the_displacement_s_own_distortion_stays():
    spectra, line_freqs, other_freqs, bands = _spectra(1, x_own_distortion=1e-3)
    measured = unexcited_measures(spectra, list(SIGNALS), line_freqs, other_freqs, bands)
    assert measured["voltage"].distortion_db > TH.distortion_red_db           # the amplifier, where it is
    assert measured["current"].distortion_db < TH.distortion_yellow_db        # explained by the voltage
    assert measured["displacement"].distortion_db > TH.distortion_red_db      # its own, not the voltage's


def test_without_the_voltage_judged_nothing_comes_off():
    spectra, line_freqs, other_freqs, bands = _spectra(2, x_own_distortion=0.0)
    both = unexcited_measures(spectra, list(SIGNALS), line_freqs, other_freqs, bands)
    alone = unexcited_measures(spectra, ["current", "displacement"], line_freqs, other_freqs, bands)
    assert set(alone) == {"current", "displacement"}
    for name in alone:
        assert both[name].distortion_db < TH.distortion_yellow_db
        assert alone[name].distortion_db > TH.distortion_red_db               # the voltage's lines, seen through H
