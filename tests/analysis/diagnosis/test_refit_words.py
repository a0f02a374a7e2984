"""A refit in the model lab says when chi^2 rose or a parameter ended on a bound, with what to try."""
from __future__ import annotations

import dataclasses

import pytest

from analysis.effects import parse_effects
from analysis.fit import FitData, fit_model
from analysis.model import Model
from analysis.diagnosis.refit_words import chi2_rose, refit_sentences, refit_text
from analysis.spectra import estimate_spectra
from tests.builders import TYPICAL_NOISE, recording


@pytest.fixture(scope="module")
def fitted():
    data = FitData.from_spectra(estimate_spectra(recording(noise=TYPICAL_NOISE, seed=3)))
    return data, fit_model(data, Model(parse_effects("lr2,creep-log")))


def test_a_refit_that_lowers_the_misfit_says_only_the_change(fitted):
    data, fit = fitted
    start = fit_model(data, Model(parse_effects("lr2")))
    assert not chi2_rose(start, fit)
    sentences = refit_sentences(start, fit)
    assert len(sentences) == 1 and sentences[0].startswith("Refitted: reduced χ² Z ")


def test_a_refit_whose_chi2_rose_says_so_with_what_to_try(fitted):
    data, fit = fitted
    # The same model from a start 20 % off, its budget ended after one step: a worse minimum than before.
    off = {name: value * 1.2 for name, value in fit.values.items()}
    worse = fit_model(data, fit.model, start=off, per_parameter=1)
    assert worse.chi2 > fit.chi2 * 2
    text = refit_text(fit, worse)
    assert "The misfit rose" in text and "Try other start values" in text


def test_a_parameter_on_its_bound_is_named_with_what_to_try(fitted):
    data, fit = fitted
    lr2, creep = parse_effects("lr2,creep-log")
    # Creep's lambda allowed no more than half the recording's: the data push it onto that bound.
    narrow = tuple(dataclasses.replace(spec, max=0.5 * fit.values[spec.name], default=0.25 * fit.values[spec.name])
                   if spec.name == "lambda" else spec for spec in creep.params)
    model = Model((lr2, dataclasses.replace(creep, params=narrow)))
    pinned = fit_model(data, model, start=fit.values)
    # The bound transform (analysis.fit.bounded_leastsq) leaves it a hair inside (2e-5 of itself): the words are
    # tested on it held there.
    assert pinned.values["lambda"] > 0.99 * model.spec("lambda").max
    pinned = dataclasses.replace(pinned, values={**pinned.values, "lambda": model.spec("lambda").max})
    text = refit_text(fit, pinned)
    assert "lambda = " in text and "upper bound" in text and "Try widening that bound" in text
