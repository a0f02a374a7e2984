"""Fit quality in words: at the noise, a band it misses (with how much), a misfit spread everywhere."""
from __future__ import annotations

import re
from types import SimpleNamespace

import numpy as np

from analysis.fit.least_squares import ChannelFit
from analysis.fit.words import channel_clause, fit_headline

FREQS = np.geomspace(10, 10000, 200)


def _channel(name: str, relative_error: np.ndarray, noise: float = 1e-3, seed: int = 1) -> ChannelFit:
    rng = np.random.default_rng(seed)
    model = np.full(FREQS.size, 8.0 + 2.0j)
    std = noise * np.abs(model)
    scatter = (rng.normal(size=FREQS.size) + 1j * rng.normal(size=FREQS.size)) * std / np.sqrt(2)
    measured = model * (1 + relative_error) + scatter
    chi2 = float(np.sum(np.abs((measured - model) / (std / np.sqrt(2))) ** 2))
    n = 2 * FREQS.size
    return ChannelFit(name=name, freqs=FREQS, measured=measured, model=model, std=std, chi2=chi2, n_points=n,
                      chi2_red=chi2 / n)


def test_a_fit_at_the_noise_is_said_so():
    ch = _channel("impedance", np.zeros(FREQS.size))
    assert channel_clause(ch) == "explains the impedance down to its noise"


def test_a_band_the_model_misses_is_named_with_its_size():
    band = (FREQS >= 200) & (FREQS <= 800)
    ch = _channel("impedance", np.where(band, 0.12, 0.0))
    text = channel_clause(ch)
    low, high = (float(v) for v in re.fullmatch(r"misses 12 % of the impedance between (\S+) Hz and (\S+) Hz",
                                                  text).groups())
    assert 180 < low <= 200 and 800 <= high < 900           # the band, give or take a line of smoothing


def test_a_misfit_spread_everywhere_says_how_many_times_the_noise():
    ch = _channel("displacement", np.zeros(FREQS.size), seed=2)
    spread = ChannelFit(name=ch.name, freqs=ch.freqs, measured=ch.model + (ch.measured - ch.model) * 2.0,
                        model=ch.model, std=ch.std, chi2=ch.chi2 * 4, n_points=ch.n_points, chi2_red=ch.chi2_red * 4)
    assert channel_clause(spread).startswith("explains the displacement to within 2")


def test_the_headline_joins_the_channels():
    at_noise = SimpleNamespace(channels={"impedance": _channel("impedance", np.zeros(FREQS.size)),
                                         "displacement": _channel("displacement", np.zeros(FREQS.size), seed=4)})
    assert fit_headline(at_noise) == "The model explains the impedance and the displacement down to their noise."
    band = (FREQS >= 200) & (FREQS <= 800)
    mixed = SimpleNamespace(channels={"impedance": _channel("impedance", np.zeros(FREQS.size)),
                                      "displacement": _channel("displacement", np.where(band, -0.05, 0.0))})
    text = fit_headline(mixed)
    assert text.startswith("The model explains the impedance down to its noise and misses 5.2 % of the displacement "
                           "between 1")
