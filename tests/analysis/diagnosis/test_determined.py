"""A parameter the data do not fix is held; the others keep their standard errors.

The paper driver's recording (LR-2 and creep-log) fitted with LR-3 and then creep-log leaves LR-3's
second stage with nothing to do (R3 on its bound, L3 unseen): the whole covariance is singular, and no
parameter had a standard error, not even creep-log's lambda, which the data fix to a few parts per million.
"""
import pytest

from analysis.diagnosis.determined import with_undetermined_held
from analysis.effects import parse_effects
from analysis.fit.least_squares import FitData, fit_model
from analysis.model.composed import Model
from analysis.spectra import estimate_spectra
from tests.builders import PAPER, TYPICAL_NOISE, recording


@pytest.fixture(scope="module")
def data(mt):
    return FitData.from_spectra(estimate_spectra(recording(noise=TYPICAL_NOISE, n_periods=8, seed=3, mt=mt)))


def test_the_parameters_the_data_fix_get_their_standard_errors_with_the_others_held(data):
    lr3 = fit_model(data, Model(parse_effects("lr3")))
    fit = fit_model(data, Model(parse_effects("lr3,creep-log")), start=lr3.values)
    assert fit.stderr["lambda"] is None      # what was wrong: one idle parameter took every standard error

    held = with_undetermined_held(data, fit, last=("lambda",))
    assert held.stderr["L3"] is None
    for name, truth in PAPER.parameters.items():
        z = (held.values[name] - truth) / held.stderr[name]
        assert abs(z) < 4, (name, held.values[name], truth, held.stderr[name])
    assert held.values == fit.values and held.chi2 == fit.chi2 and held.varying == fit.varying


def test_a_fit_with_every_standard_error_is_left_as_it_is(data):
    fit = fit_model(data, Model(parse_effects("lr2,creep-log")))
    assert with_undetermined_held(data, fit) is fit
