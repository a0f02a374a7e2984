"""LineSpectra: the lines gathered once, each channel's variances floored at float64 rounding of its own lines."""
import numpy as np

from analysis.spectra import ChannelSpectrum
from analysis.validity.line_spectra import ROUNDING, LineSpectra


def _band(rng, n=400):
    mean = rng.standard_normal((3, n)) + 1j * rng.standard_normal((3, n))
    var = rng.uniform(1e-6, 1e-3, size=(3, n))
    return mean, var


def test_gathered_from_a_band_or_from_spectra_alike_and_floored_per_channel():
    rng = np.random.default_rng(1)
    mean, var = _band(rng)
    excited = np.arange(0, 400, 7)
    unexcited = np.setdiff1d(np.arange(400), excited)
    mean[1, excited] *= 1e9                         # the current's lines far stronger: its floor is ~1e-6
    var[1, 5] = var[0, 5] = 0.0                     # a zero scatter on both: each raised to its own floor
    signals = ("voltage", "current", "displacement")
    band = LineSpectra.of_band(signals, mean, var, excited, unexcited)
    spectra = LineSpectra.of_spectra({s: ChannelSpectrum(s, "", mean[i], var[i]) for i, s in enumerate(signals)},
                                     excited, unexcited)
    for field in ("lines", "line_var", "other", "other_var", "other_power"):
        np.testing.assert_array_equal(getattr(band, field), getattr(spectra, field))
    at = list(unexcited).index(5)
    for row in (0, 1):
        assert band.other_var[row, at] == (ROUNDING * np.max(np.abs(mean[row, excited]))) ** 2
    assert band.other_var[1, at] > 1e9 * band.other_var[0, at]
    np.testing.assert_array_equal(band.other_var[2], var[2, unexcited])          # nothing below its floor
    other = mean[:, unexcited]
    np.testing.assert_array_equal(band.other_power, other.real**2 + other.imag**2)
    np.testing.assert_array_equal(var[1, 5], 0.0)                                # the caller's arrays untouched


def test_a_silent_channel_keeps_its_variances_and_a_nan_line_makes_them_unknown():
    rng = np.random.default_rng(2)
    mean, var = _band(rng, 50)
    mean[0] = 0.0                                   # no signal at all: no floor
    mean[2, 10] = np.nan                            # an unknown line: its channel's noise is unknown too
    spectra = LineSpectra.of_band(("voltage", "current", "displacement"), mean, var, np.arange(0, 50, 5),
                                  np.setdiff1d(np.arange(50), np.arange(0, 50, 5)))
    np.testing.assert_array_equal(spectra.other_var[0], np.delete(var[0], np.arange(0, 50, 5)))
    assert np.all(np.isnan(spectra.other_var[2])) and np.all(np.isnan(spectra.line_var[2]))
    assert spectra.row("current") == 1
