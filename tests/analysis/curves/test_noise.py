"""The noise of imported curves from their local scatter: unbiased on simulated curves with known noise."""
import numpy as np
import pytest

from analysis.curves.fitting import curve_data
from analysis.curves.noise import estimated_std, with_estimated_noise
from analysis.effects import parse_effects
from analysis.model.composed import Model
from analysis.spectra import TransferFunction
from tests.builders import DRIVERS

GRIDS = {
    "zma (386 lines, 10 Hz to 20 kHz, log)": np.geomspace(10.0, 20e3, 386),
    "1 Hz steps to 10 kHz": np.arange(1.0, 10001.0),
    "0.5 Hz steps to 5 kHz": np.arange(1.0, 5000.5, 0.5),
}


def noisy_curve(freqs, channel, relative_noise, driver, phase=True, seed=0):
    """The driver's Z or Hx with complex (or magnitude) Gaussian noise of a known relative size, and that size."""
    model = Model(parse_effects("lr2,creep-log"))
    s = 2j * np.pi * freqs
    clean = model.impedance(s, DRIVERS[driver]) if channel == "impedance" else model.displacement(s, DRIVERS[driver])
    sigma = relative_noise * np.abs(clean)            # sqrt(E|dH|^2)
    rng = np.random.default_rng(seed)
    if phase:
        value = clean + sigma / np.sqrt(2) * (rng.standard_normal(len(freqs)) + 1j * rng.standard_normal(len(freqs)))
        true_std = sigma
    else:
        value = (np.abs(clean) + sigma / np.sqrt(2) * rng.standard_normal(len(freqs))).astype(complex)
        true_std = sigma              # std holds sqrt(2) x the magnitude's sigma, as the fit reads it
    n = len(freqs)
    tf = TransferFunction(channel, "", freqs, np.arange(n), value, np.full(n, np.nan), phase, noise_known=False)
    return tf, true_std


@pytest.mark.parametrize("grid", list(GRIDS))
@pytest.mark.parametrize("driver", ["paper", "fullrange-2in", "woofer-18in"])
@pytest.mark.parametrize("channel", ["impedance", "displacement"])
@pytest.mark.parametrize("phase", [True, False], ids=["complex", "magnitude-only"])
def test_the_estimate_is_unbiased_to_20_percent(grid, driver, channel, phase):
    ratios = []
    for seed, relative_noise in enumerate((1e-3, 3e-3, 1e-2)):
        tf, true_std = noisy_curve(GRIDS[grid], channel, relative_noise, driver, phase, seed)
        ratios.append(estimated_std(tf) / true_std)
    ratio = np.concatenate(ratios)
    assert np.median(ratio) == pytest.approx(1.0, abs=0.2)
    # Lines off by more than a factor 2 (windows on a sharp resonance): a few per cent at most.
    assert np.mean((ratio > 2) | (ratio < 0.5)) < 0.1


def test_a_noise_free_curve_gets_no_noise_but_where_it_bends_sharply():
    tf, _ = noisy_curve(GRIDS["1 Hz steps to 10 kHz"], "impedance", 0.0, "paper")
    relative = estimated_std(tf) / np.abs(tf.value)
    assert np.median(relative) < 1e-9
    # The windows on the resonance (70 Hz, 1 Hz apart) see its curvature as scatter: the known upward bias.
    worst = np.argmax(relative)
    assert 50 < tf.freqs[worst] < 100 and relative[worst] < 2e-3
    known = with_estimated_noise(tf)
    assert known.noise_known and with_estimated_noise(known) is known      # a curve with its own noise keeps it


def test_curve_data_estimates_on_every_line_before_thinning_and_says_so():
    z, true_std = noisy_curve(GRIDS["1 Hz steps to 10 kHz"], "impedance", 3e-3, "paper")
    data, notes = curve_data(z)
    assert data.impedance.noise_known and len(data.impedance.freqs) < 0.05 * len(z.freqs)
    kept = np.isin(z.freqs, data.impedance.freqs)
    assert np.median(data.impedance.std / true_std[kept]) == pytest.approx(1.0, abs=0.2)
    assert any("local scatter" in n for n in notes)


def test_a_coarse_curve_is_said_to_give_an_upper_bound():
    z, _ = noisy_curve(np.geomspace(10.0, 20e3, 100), "impedance", 1e-3, "paper")
    _, notes = curve_data(z)
    assert any("upper bound" in n for n in notes)
