"""A covariance from the Jacobian where MINPACK gives none, the same as MINPACK's where it does."""
import numpy as np
import pytest

from analysis.effects import parse_effects
from analysis.fit.covariance import jacobian, normal_inverse
from analysis.fit.least_squares import FitData, _residual_vector, channel_sigmas, fit_model
from analysis.model.composed import Model
from analysis.derived import parameter_table
from analysis.spectra import estimate_spectra
from tests.builders import TYPICAL_NOISE, recording
from tests.realistic_drivers import realistic_recording


def test_the_jacobian_covariance_is_minpacks():
    data = FitData.from_spectra(estimate_spectra(recording(noise=TYPICAL_NOISE, seed=2)))
    model = Model(parse_effects("lr2,creep-log"), with_displacement=True)
    fit = fit_model(data, model)
    sigmas = channel_sigmas(data, True)
    specs = {s.name: s for s in model.param_specs}
    J = jacobian(lambda p: _residual_vector(model, p, data, True, sigmas), fit.values, fit.varying, specs)
    ours = normal_inverse(J) * max(1.0, fit.chi2_red)
    assert np.sqrt(np.diag(ours)) == pytest.approx(np.sqrt(np.diag(fit.covar)), rel=0.02)


def test_a_fit_minpack_leaves_without_error_bars_gets_them_from_the_jacobian():
    # The realistic subwoofer, seed 1, over every line (the default analysis fits it over its piston band since
    # issue 29: analysis.fit.bands): MINPACK stops on "tolerance too small" with no covariance.
    data = FitData.from_spectra(estimate_spectra(realistic_recording("subwoofer", 1)))
    fit = fit_model(data, Model(parse_effects("lr2,creep-log"), with_displacement=True))
    assert "error-bars" in fit.message
    table = parameter_table(fit, 0.038)
    for name in ("RE", "Bl", "CMES", "LCES", "RES", "lambda", "Mms", "Kms", "fs"):
        p = table[name]
        assert p.std is not None and 0 < p.std < 0.1 * abs(p.value), name
