"""Added-mass methods on synthetic curves: exact where the method is exact, honest where noisy."""
import numpy as np
import pytest

from analysis.added_mass import (AddedMassResult, MassCurve, compare_with_laser, joint_added_mass,
                                 model_free_dual_mass, single_added_mass)
from analysis.curves.fitting import CurveFitError
from analysis.derived import ParameterValue
from analysis.effects import parse_effects
from analysis.effects.base import Site
from analysis.model.composed import Model, ModelError
from analysis.spectra import TransferFunction
from tests.builders import electrical

FREQS = np.logspace(1, np.log10(20e3), 385)
# A 6.5" mid-woofer like the SEAS L16RNX.
MECH = dict(RE=5.6, LE=0.05e-3, Mms=15e-3, Cms=0.8e-3, Rms=1.4, Bl=7.0)
EXTRA = {"leach,creep-log-causal": dict(K=0.0085, n=0.68, **{"lambda": 0.25}), "lr2": dict(L2=0.3e-3, R2=9.0)}
M1, M2 = 8e-3, 16e-3


def impedance(effects, mass, freqs=FREQS, noise=0.0, seed=0):
    """Z with `mass` on the cone, built from the mechanical impedance (the suspension is the free-air one)."""
    values = electrical(**MECH, **EXTRA[effects])
    model = Model(parse_effects(effects), with_displacement=True)
    s = 2j * np.pi * freqs
    compliance = np.ones_like(s)
    for e in model.effects:
        if e.site is Site.COMPLIANCE:
            compliance = compliance * e.response(s, values)   # referred to the free-air fs
    zm = s * (MECH["Mms"] + mass) + MECH["Rms"] + 1 / (s * MECH["Cms"] * compliance)
    z = model.blocked_impedance(s, values) + MECH["Bl"] ** 2 / zm
    if noise:
        rng = np.random.default_rng(seed)
        z = z * (1 + noise * (rng.standard_normal(len(z)) + 1j * rng.standard_normal(len(z))) / np.sqrt(2))
    n = len(freqs)
    return TransferFunction("impedance", "ohm", freqs, np.arange(n), z, np.full(n, np.nan), True, False)


def curves(effects, masses=(M1, M2), noise=0.0):
    return [MassCurve(impedance=impedance(effects, 0.0, noise=noise), added_mass_kg=0.0)] + [
        MassCurve(impedance=impedance(effects, m, noise=noise, seed=i + 1), added_mass_kg=m)
        for i, m in enumerate(masses)]


@pytest.mark.parametrize("masses", [(M1, M2), (M1,)])
def test_the_joint_fit_is_exact_on_noise_free_curves(masses):
    effects = "leach,creep-log-causal"
    r = joint_added_mass(curves(effects, masses), effects, sd_m2=0.0104)
    assert r.value("Bl") == pytest.approx(MECH["Bl"], rel=1e-5)
    assert r.value("Mms") == pytest.approx(MECH["Mms"], rel=1e-5)
    assert r.value("Cms") == pytest.approx(MECH["Cms"], rel=1e-5)
    assert r.value("Rms") == pytest.approx(MECH["Rms"], rel=1e-4)
    assert r.value("Vas") == pytest.approx(1.18 * 343.0**2 * 0.0104**2 * MECH["Cms"], rel=1e-5)
    assert set(r.fit.chi2_red_by_channel()) == {"free air", "+8 g"} | ({"+16 g"} if len(masses) == 2 else set())


def test_the_model_free_method_is_exact_when_the_creep_is_the_log_law():
    # Candy and Futtrup's LOG model, 1/(1 - beta ln(jw)), is creep-log-causal with lambda = beta ln 10.
    c = curves("leach,creep-log-causal")
    r = model_free_dual_mass(c[0].impedance, c[1].impedance, M1, c[2].impedance, M2)
    assert r.value("Bl") == pytest.approx(MECH["Bl"], rel=1e-6)
    assert r.value("Mms") == pytest.approx(MECH["Mms"], rel=1e-6)
    assert r.parameters["Bl"].std < 1e-6 * MECH["Bl"]


def test_the_model_free_method_takes_curves_on_another_grid():
    c = curves("lr2")
    other = impedance("lr2", M2, freqs=np.logspace(0.9, 4.4, 500))
    r = model_free_dual_mass(c[0].impedance, c[1].impedance, M1, other, M2)
    assert r.value("Bl") == pytest.approx(MECH["Bl"], rel=2e-3)


def test_the_classical_single_mass_is_exact_without_creep():
    c = curves("lr2", (M1,))
    r = single_added_mass(c[0].impedance, c[1].impedance, M1, "lr2", sd_m2=0.0104)
    for name in ("Bl", "Mms", "Cms", "Rms"):
        assert r.value(name) == pytest.approx(MECH[name], rel=1e-5), name
    assert r.value("RE") == pytest.approx(MECH["RE"], rel=1e-6)


def test_noisy_curves_give_estimates_within_their_uncertainty():
    effects = "leach,creep-log-causal"
    r = joint_added_mass(curves(effects, noise=0.01), effects)
    for name in ("Bl", "Mms", "Cms"):
        p = r.parameters[name]
        assert abs(p.value - MECH[name]) < 4 * p.std, (name, p.value, p.std)
    assert r.fit.chi2_red == pytest.approx(1.0, abs=0.2)


def test_refusals():
    c = curves("lr2")
    with pytest.raises(CurveFitError, match="free-air"):
        joint_added_mass(c[1:], "lr2")
    with pytest.raises(ModelError, match="displacement channel"):
        joint_added_mass(c, "lr2,delay-x")
    with pytest.raises(CurveFitError, match="positive"):
        single_added_mass(c[0].impedance, c[1].impedance, 0.0, "lr2")
    with pytest.raises(CurveFitError, match="did not fall"):
        single_added_mass(c[1].impedance, c[0].impedance, M1, "lr2")
    magnitude = TransferFunction("impedance", "ohm", FREQS, np.arange(len(FREQS)), np.abs(c[1].impedance.value),
                                 np.full(len(FREQS), np.nan), False, False)
    with pytest.raises(CurveFitError, match="phase"):
        model_free_dual_mass(c[0].impedance, magnitude, M1, c[2].impedance, M2)


def _result(**values_and_stds) -> AddedMassResult:
    units = {"Bl": ("T*m", 1.0), "Mms": ("kg", 1e3), "Cms": ("m/N", 1e3)}
    params = {n: ParameterValue(name=n, value=v, std=s, unit=units[n][0], display_unit=units[n][0],
                                display_scale=units[n][1]) for n, (v, s) in values_and_stds.items()}
    return AddedMassResult(method="test", parameters=params, masses_kg=(M1,))


@pytest.mark.parametrize("added, laser, severity", [
    ((7.00, 0.02), (7.05, 0.02), "green"),      # 0.7 %: within 2 %
    ((7.00, 0.20), (7.40, 0.20), "green"),      # 5.4 % but 1.4 sigma: consistent
    ((7.00, 0.01), (7.25, 0.01), "yellow"),     # 3.4 %, many sigmas
    ((7.00, 0.01), (7.60, 0.01), "red"),        # 7.9 %, many sigmas
    ((7.00, None), (7.60, None), "red"),        # no sigma known: the percentages decide
])
def test_agreement_with_the_laser_is_graded(added, laser, severity):
    findings = compare_with_laser(_result(Bl=added), {"Bl": ParameterValue(name="Bl", value=laser[0], std=laser[1],
                                                                           unit="T*m", display_unit="T*m",
                                                                           display_scale=1.0)})
    assert [f.code for f in findings] == ["added-mass-disagrees"]
    assert findings[0].severity == severity and findings[0].parameter == "Bl"
    assert "%" in findings[0].message


def test_laser_values_may_be_plain_numbers_and_missing_ones_are_skipped():
    findings = compare_with_laser(_result(Bl=(7.0, 0.02), Mms=(15e-3, 1e-4)), {"Mms": (15.3e-3, 0.1e-3), "Bl": None})
    assert [f.parameter for f in findings] == ["Mms"] and findings[0].as_json()["severity"] == "green"


def test_added_mass_result_is_built_by_keyword_only():
    import dataclasses

    from analysis.added_mass import AddedMassResult
    assert all(field.kw_only for field in dataclasses.fields(AddedMassResult))
