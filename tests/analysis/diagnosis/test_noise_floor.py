"""The noise floor's shortcut: a model with nothing to find ends the path without refitting candidates.

Both rules are checked on a clean recording's fit and its sites' corrections, and against what they
must not pass: a channel's chi^2 above chance, a site's correction that removes more than noise would.
(That the full ranking finds nothing on a model the rule passes is in test_diagnosis.py.)
"""
import dataclasses
import math

import pytest

from analysis.diagnosis import noise_floor
from analysis.diagnosis.sites import localise
from analysis.effects import parse_effects
from analysis.fit.least_squares import FitData, fit_model
from analysis.model.composed import Model
from analysis.spectra import estimate_spectra
from tests.builders import TYPICAL_NOISE, recording


@pytest.fixture(scope="module")
def clean(mt):
    data = FitData.from_spectra(estimate_spectra(recording(noise=TYPICAL_NOISE, n_periods=8, seed=22, mt=mt)))
    fit = fit_model(data, Model(parse_effects("lr2,creep-log")))
    return fit, {s.site: s for s in localise(data, fit)}


def test_chance_is_three_sigma_of_chi2_above_its_mean():
    assert noise_floor.within_chance(100.0 + 3 * math.sqrt(200.0) - 0.01, 100)
    assert not noise_floor.within_chance(100.0 + 3 * math.sqrt(200.0) + 0.01, 100)


def test_a_clean_recordings_fit_has_nothing_to_find(clean):
    fit, sites = clean
    assert len(sites) == 6
    assert noise_floor.nothing_to_find(fit, sites)


def test_a_channel_above_chance_is_not_the_noise_floor(clean):
    fit, sites = clean
    name, channel = next(iter(fit.channels.items()))
    worse = dataclasses.replace(channel, chi2=channel.n_points + 3.1 * math.sqrt(2.0 * channel.n_points))
    assert not noise_floor.nothing_to_find(dataclasses.replace(fit, channels={**fit.channels, name: worse}), sites)


def test_a_site_whose_correction_removes_more_than_noise_leaves_something_to_find(clean):
    fit, sites = clean
    site, result = next(iter(sites.items()))
    structure = result.edf + 3.1 * math.sqrt(2.0 * result.edf)
    found = dataclasses.replace(result, chi2=fit.chi2 - structure)
    assert not noise_floor.nothing_to_find(fit, {**sites, site: found})


def test_a_model_with_an_undetermined_parameter_is_not_the_end(clean):
    # An effect whose parameter the data do not fix may be superfluous: the path ranks the candidates once
    # more, so that the swap for a simpler effect of its category (LR-3 for LR-2) can be taken.
    fit, sites = clean
    idle = dataclasses.replace(fit, stderr={**fit.stderr, "L2": None})
    assert noise_floor.superfluous_parameters(idle) == ["L2"]
    assert not noise_floor.nothing_to_find(idle, sites)
