"""The site fit's start (analysis.diagnosis.site_algebra.linearised_start): a start nearer the answer than all
zeros, and a site fit from it that ends where one from zero ends, to the fit's tolerance."""
import numpy as np
import pytest

from analysis.diagnosis import site_algebra, sites
from analysis.diagnosis.site_correction import site_correction
from analysis.diagnosis.sites import SITES, _band, _SiteProblem, fit_site
from analysis.effects import parse_effects
from analysis.fit.least_squares import FitData, fit_model
from analysis.model.composed import Model
from analysis.spectra import estimate_spectra
from tests.odd_physics import odd_recording


@pytest.fixture(scope="module")
def odd_mechanical():
    """Odd physics at the mechanical site (not in the catalogue's form), fitted with the default model."""
    data = FitData.from_spectra(estimate_spectra(odd_recording("mechanical")))
    return data, fit_model(data, Model(parse_effects("lr2,creep-log")))


def _chi2(problem, x) -> float:
    r = problem.residual(x)
    return float(r @ r)


@pytest.mark.parametrize("site", SITES, ids=[s.key for s in SITES])
def test_the_start_is_never_worse_than_zero_and_moves_only_the_coefficients(odd_mechanical, site):
    data, fit = odd_mechanical
    problem = _SiteProblem(data, fit, site_correction(site, *_band(data)))
    x = site_algebra.linearised_start(problem)
    zero = np.zeros_like(x)
    assert np.all(x[: problem.k] == 0.0)
    assert _chi2(problem, x) <= _chi2(problem, zero)


def test_where_the_misfit_is_at_the_site_the_start_takes_most_of_it(odd_mechanical):
    data, fit = odd_mechanical
    problem = _SiteProblem(data, fit, site_correction(sites.Site.MECHANICAL, *_band(data)))
    x = site_algebra.linearised_start(problem)
    assert _chi2(problem, x) < 0.5 * _chi2(problem, np.zeros_like(x))


@pytest.mark.parametrize("site", SITES, ids=[s.key for s in SITES])
def test_a_site_fit_from_the_start_ends_where_one_from_zero_ends(odd_mechanical, site, monkeypatch):
    data, fit = odd_mechanical
    ours = fit_site(data, fit, site)
    monkeypatch.setattr(sites, "linearised_start", lambda problem: np.zeros(problem.k + 2 * problem.n_basis))
    from_zero = fit_site(data, fit, site)
    # Levenberg-Marquardt stops when chi^2 changes by less than TOLERANCE (relative) in a step, which from zero
    # can be short of the minimum (the current site here: 0.5 % more chi^2 than from the start): ours ends no
    # higher, and within a few per cent; the effective parameters within one (the score's ln n each).
    assert from_zero.chi2 * (1 - 0.02) <= ours.chi2 <= from_zero.chi2 * (1 + 20 * sites.TOLERANCE)
    assert ours.edf == pytest.approx(from_zero.edf, abs=1.0)
