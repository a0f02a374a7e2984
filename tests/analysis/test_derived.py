"""Derived parameters: the paper's Table I, uncertainty propagation, what cannot be identified."""
import dataclasses

import numpy as np
import pytest

from analysis.derived import DERIVED, P_REF, V_283, ParameterValue, derived_from_values, parameter_table
from analysis.effects import parse_effects
from analysis.fit.least_squares import FitData, fit_model
from analysis.model.composed import Model
from analysis.model.lumped import C_SOUND, RHO
from analysis.spectra import estimate_spectra
from tests.builders import PAPER, TYPICAL_NOISE, recording

# docs/physics.md section 7: mean and std of 10 repetitions
TABLE_I = {"fs": (70.5, 0.057, 1.0), "Mms": (11.87, 0.075, 1e3), "Rms": (2.27, 0.013, 1.0),
           "Cms": (0.43, 0.0057, 1e3), "Kms": (2.33, 0.011, 1e-3)}


def test_table_i_electrical_values_give_table_i_mechanical_values():
    derived = derived_from_values(PAPER.parameters)
    # fs, Cms, Kms: within one unit of the last printed digit
    for name, unit in (("fs", 0.1), ("Cms", 0.01), ("Kms", 0.01)):
        mean, _, scale = TABLE_I[name]
        assert abs(derived[name] * scale - mean) <= unit + 1e-12, name
    # Mms and Rms also depend on Bl, printed as 5.23 although Mms/CMES in the same
    # table implies 5.236: means of products are not products of means. They
    # agree within the table's own repeatability.
    for name in ("Mms", "Rms"):
        mean, std, scale = TABLE_I[name]
        assert abs(derived[name] * scale - mean) <= std, name
    # with Bl = sqrt(Mms / CMES) of the table, they agree to the printed digits too
    bl = np.sqrt(11.87e-3 / 433e-6)
    again = derived_from_values({**PAPER.parameters, "Bl": bl})
    assert round(again["Mms"] * 1e3, 2) == 11.87
    assert round(again["Rms"], 2) == 2.27


def _table(displacement=True, sd=0.0133):
    rec = recording(noise=TYPICAL_NOISE, n_periods=8, seed=7, displacement=displacement)
    model = Model(parse_effects("lr2,creep-log"), with_displacement=displacement)
    fit = fit_model(FitData.from_spectra(estimate_spectra(rec)), model)
    return fit, parameter_table(fit, sd)


def test_derived_parameters_have_propagated_uncertainties_consistent_with_truth():
    fit, table = _table()
    truth = derived_from_values(PAPER.parameters, 0.0133)
    for name, value in truth.items():
        p = table[name]
        assert p.std is not None and p.std > 0, name
        assert abs(p.value - value) < 4.5 * p.std, name


def _by_uncertainties_package(fit, sd):
    """The same propagation with exact derivatives: the `uncertainties` package's correlated values."""
    import uncertainties
    from uncertainties import umath
    p = dict(fit.values)
    p.update(zip(fit.varying, uncertainties.correlated_values([fit.values[n] for n in fit.varying], fit.covar)))
    fs = 1 / (2 * np.pi * umath.sqrt(p["CMES"] * p["LCES"]))
    qes, qms = 2 * np.pi * fs * p["CMES"] * p["RE"], 2 * np.pi * fs * p["CMES"] * p["RES"]
    eta0 = RHO * p["Bl"] ** 2 * sd**2 / (2 * np.pi * C_SOUND * p["RE"] * (p["CMES"] * p["Bl"] ** 2) ** 2)
    spl = 10 * umath.log10(RHO * C_SOUND * eta0 / (2 * np.pi * P_REF**2))
    return {"fs": fs, "Mms": p["CMES"] * p["Bl"] ** 2, "Rms": p["Bl"] ** 2 / p["RES"], "Cms": p["LCES"] / p["Bl"] ** 2,
            "Kms": p["Bl"] ** 2 / p["LCES"], "Qes": qes, "Qms": qms, "Qts": qes * qms / (qes + qms),
            "Vas": RHO * C_SOUND**2 * sd**2 * p["LCES"] / p["Bl"] ** 2, "eta0": eta0, "SPL_1W_1m": spl,
            "SPL_2.83V_1m": spl + 10 * umath.log10(V_283**2 / p["RE"])}


@pytest.mark.parametrize("effects", ["lr2,creep-log", "none", "lr3,creep-log-causal-fs"])
def test_the_propagation_is_the_uncertainties_packages_to_its_last_digits(effects):
    """Central differences (analysis.derived.STEP) against exact derivatives: values and std to 1e-7."""
    rec = recording(noise=TYPICAL_NOISE, n_periods=8, seed=3)
    fit = fit_model(FitData.from_spectra(estimate_spectra(rec)), Model(parse_effects(effects)))
    table = parameter_table(fit, 0.0133)
    exact = _by_uncertainties_package(fit, 0.0133)
    assert set(exact) == {d.name for d in DERIVED}
    for name, x in exact.items():
        assert table[name].value == pytest.approx(x.nominal_value, rel=1e-12), name
        assert table[name].std == pytest.approx(x.std_dev, rel=1e-7), name


def test_the_propagation_is_the_packages_on_a_real_like_woofer_too():
    """Six physics at once, none in the catalogue's form (tests/real_like.py), fitted with the default model: a fit
    far from the noise, its covariance wide and strongly correlated. Whether the total uncertainty covers the
    truth is the model part's matter (analysis.fit.model_uncertainty); this one is the noise's, and it must be
    the package's."""
    from tests.real_like import SD, real_like_recording
    data = FitData.from_spectra(estimate_spectra(real_like_recording()))
    fit = fit_model(data, Model(parse_effects("lr2,creep-log")))
    table, exact = parameter_table(fit, SD), _by_uncertainties_package(fit, SD)
    for name, x in exact.items():
        assert table[name].std == pytest.approx(x.std_dev, rel=1e-7), name


def test_a_covariance_that_is_not_a_matrix_of_numbers_leaves_values_without_uncertainty():
    fit, _ = _table()
    broken = dataclasses.replace(fit, covar=np.full_like(fit.covar, np.nan))
    table = parameter_table(broken, 0.0133)
    assert table["fs"].value == pytest.approx(derived_from_values(fit.values)["fs"]) and table["fs"].std is None


def test_fs_is_better_known_than_cmes_and_lces_thanks_to_their_correlation():
    fit, table = _table()
    rel = lambda n: table[n].std / table[n].value
    assert rel("fs") < 0.5 * max(rel("CMES"), rel("LCES"))


def test_without_displacement_mechanical_parameters_are_not_identifiable_and_say_why():
    _, table = _table(displacement=False)
    for name in ("Bl", "Mms", "Rms", "Cms", "Kms", "Vas"):
        assert table[name].value is None
        assert "displacement" in table[name].reason
    for name in ("RE", "fs", "Qes", "Qms", "Qts"):
        assert table[name].value is not None and table[name].std > 0


def test_vas_and_sensitivity_need_sd():
    _, table = _table(sd=None)
    assert table["Vas"].value is None and "Sd" in table["Vas"].reason
    assert table["Mms"].value is not None


def test_sensitivity_matches_the_efficiency_formula():
    d = derived_from_values(PAPER.parameters, 0.0133)
    # 1 acoustic watt in half space at 1 m: 10*log10(rho*c / (2*pi) / p0^2) = 112.07 dB
    assert d["SPL_1W_1m"] == pytest.approx(112.07 + 10 * np.log10(d["eta0"]), abs=0.01)
    assert d["SPL_2.83V_1m"] - d["SPL_1W_1m"] == pytest.approx(10 * np.log10(2.83**2 / 3.02), abs=1e-9)
    # eta0 = 4 pi^2 fs^3 Vas / (c^3 Qes): the textbook form agrees
    assert d["eta0"] == pytest.approx(4 * np.pi**2 * d["fs"] ** 3 * d["Vas"] / (343.0**3 * d["Qes"]), rel=1e-9)


def test_a_parameter_value_is_built_by_keyword_only():
    """value, std and the display scale are all numbers: by position they are easy to swap unseen."""
    assert all(field.kw_only for field in dataclasses.fields(ParameterValue))
    with pytest.raises(TypeError):
        ParameterValue("RE", 3.0, 0.01, "ohm", "ohm", 1.0)      # noqa: the positional form, refused
