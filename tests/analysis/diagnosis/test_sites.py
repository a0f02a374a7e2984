"""The six sites: the force-factor site's equations, the site corrections' fit, and what cannot be told apart."""
from dataclasses import dataclass

import numpy as np
import pytest
from scipy.optimize._numdiff import approx_derivative

from analysis.diagnosis.site_correction import site_correction
from analysis.diagnosis.sites import SITES, _band, _log_shares_left, _SiteProblem, localise
from analysis.diagnosis.words import tied_sites
from analysis.effects import parse_effects
from analysis.effects.base import Effect, Site
from analysis.fit.least_squares import FitData, fit_model
from analysis.model.composed import Model
from analysis.spectra import estimate_spectra
from tests.builders import PAPER
from tests.odd_physics import odd_recording


@dataclass(frozen=True)
class ConstantG(Effect):
    def response(self, s, p):
        return np.full_like(s, p["g"])


def test_every_site_has_its_name_both_ways():
    assert [s.key for s in SITES] == ["electrical", "force-factor", "mechanical", "compliance", "current",
                                      "displacement"]
    assert all(Site.from_key(s.key) is s for s in SITES)
    with pytest.raises(KeyError, match="the sites are"):
        Site.from_key("magnet")


def test_a_force_factor_multiplies_bl_in_the_force_and_the_back_emf_alike():
    """docs/physics.md section 8: Z = Ze + (g Bl)^2 / Zm and Hx = g Bl / (s Zm Z), for a complex g(s)."""
    from analysis.effects.base import ParamSpec
    g_effect = ConstantG("g", "test-g", "g", Site.FORCE_FACTOR, (ParamSpec("g", "1", "-", 1, 0, 2, 1, "g"),),
                         "", "", "", "")
    model = Model(parse_effects("lr2") + (g_effect,))
    p = {**PAPER.parameters, "g": 0.9 + 0.05j}
    s = 2j * np.pi * np.geomspace(10.0, 10e3, 50)
    base = Model(parse_effects("lr2"))
    Ze = base.blocked_impedance(s, p)
    Zm = PAPER.parameters["Bl"] ** 2 / base.motional_impedance(s, p)      # ZR = Bl^2 / Zm
    g, Bl = p["g"], p["Bl"]
    Z = Ze + (g * Bl) ** 2 / Zm
    assert np.allclose(model.impedance(s, p), Z, rtol=1e-12)
    assert np.allclose(model.displacement(s, p), g * Bl / (s * Zm * Z), rtol=1e-12)
    # g = 1 is the textbook model, exactly.
    assert np.array_equal(Model(parse_effects("lr2") + (g_effect,)).impedance(s, {**p, "g": 1.0}),
                          base.impedance(s, p))


@pytest.fixture(scope="module")
def odd_mechanical():
    data = FitData.from_spectra(estimate_spectra(odd_recording("mechanical")))
    return data, fit_model(data, Model(parse_effects("lr2,creep-log")))


@pytest.mark.parametrize("site", SITES, ids=[s.key for s in SITES])
def test_the_coefficients_jacobian_from_one_shifted_evaluation_is_the_numerical_one(odd_mechanical, site):
    data, fit = odd_mechanical
    problem = _SiteProblem(data, fit, site_correction(site, *_band(data), 1.0))
    x = np.random.default_rng(1).normal(0, 1e-3, problem.k + 2 * problem.n_basis)
    analytic = problem.jacobian(x)
    numeric = approx_derivative(problem.residual, x, method="3-point")
    scale = np.abs(numeric).max(axis=0) + 1e-12
    assert np.max(np.abs(analytic - numeric).max(axis=0) / scale) < 1e-3


def test_with_the_impedance_alone_no_site_can_be_told_from_another():
    data = FitData.from_spectra(estimate_spectra(odd_recording("electrical")))
    z_only = FitData(data.impedance)
    fit = fit_model(z_only, Model(parse_effects("lr2,creep-log"), with_displacement=False))
    sites = localise(z_only, fit)
    assert {s.site for s in sites} == set(SITES) - {Site.DISPLACEMENT}
    assert len(tied_sites(sites)) == len(sites) - 1
    assert all(s.delta_bic < -1000 for s in sites[:5])       # each of them can make Z anything


@dataclass(frozen=True)
class _Chi2:
    chi2: float


@dataclass(frozen=True)
class _Current:
    channels: dict


def test_a_sense_site_counts_its_own_channel_no_more_than_the_other_unless_the_other_meets_the_noise():
    """A factor on the laser takes Hx to its noise whatever the physics: what it leaves of Z is what counts."""
    current = _Current({"impedance": _Chi2(8.3e7), "displacement": _Chi2(2.3e8)})
    z_left = {"impedance": (2.0e7, 180), "displacement": (1128.0, 180)}
    shares = {name: share for name, share, _ in _log_shares_left(Site.DISPLACEMENT, current, z_left)}
    assert shares["displacement"] == pytest.approx(np.log(2.0e7 / 8.3e7))
    assert shares["impedance"] == pytest.approx(np.log(2.0e7 / 8.3e7))
    # The mechanical site acts on both channels: each counts by its own share.
    shares = {name: share for name, share, _ in _log_shares_left(Site.MECHANICAL, current, z_left)}
    assert shares["displacement"] == pytest.approx(np.log(1128.0 / 2.3e8))
    # Z left within chance of its noise: the laser alone explains the recording, and gets its full share.
    z_met = {"impedance": (190.0, 180), "displacement": (1128.0, 180)}
    shares = {name: share for name, share, _ in _log_shares_left(Site.DISPLACEMENT, current, z_met)}
    assert shares["displacement"] == pytest.approx(np.log(1128.0 / 2.3e8))
