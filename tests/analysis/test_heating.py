"""Voice-coil heating during the measurement: RE per period, the rise in kelvin, the honest noise, the words."""
import numpy as np
import pytest

from analysis.diagnosis import acceptance
from analysis.diagnosis.candidates import diagnose
from analysis.diagnosis.words import drift_from_validity, verdict_text
from analysis.effects import parse_effects
from analysis.fit.least_squares import FitData, fit_model
from analysis.heating import COPPER_PER_K, coil_heating
from analysis.model.composed import Model
from analysis.pipeline import analyze_recording
from analysis.spectra import estimate_spectra
from analysis.synthesis import synthesize_recording
from tests.builders import PAPER, TYPICAL_NOISE, multitone

RISE_K = 15.0           # over the whole recording, its settle period included
PERIODS, SETTLE = 8, 1
RE0 = PAPER.parameters["RE"]


def _re(k: int) -> float:
    """RE(T) = RE(T0)*(1 + 0.393 %/K * dT), the coil warming steadily from period to period."""
    return RE0 * (1.0 + COPPER_PER_K * RISE_K * k / (PERIODS + SETTLE - 1))


@pytest.fixture(scope="module")
def hot():
    mt = multitone()
    return synthesize_recording(Model(parse_effects("lr2,creep-log")), PAPER.parameters, mt.waveform,
                                mt.excited_bins, mt.sample_rate, PERIODS, SETTLE, TYPICAL_NOISE, seed=21,
                                drift=lambda k: {"RE": _re(k)}, driver={"name": "hot", "sd_m2": 0.0133})


def test_re_per_period_and_the_temperature_rise_are_recovered(hot):
    spectra = estimate_spectra(hot)
    fit = fit_model(FitData.from_spectra(spectra), Model(parse_effects("lr2,creep-log")))
    heating = coil_heating(hot, spectra, fit.values["RE"])
    true = np.array([_re(k) for k in range(SETTLE, SETTLE + PERIODS)])
    np.testing.assert_allclose(heating.re_periods, true, rtol=3e-4)
    assert heating.re_first == pytest.approx(true[0], rel=3e-4) and heating.re_last == pytest.approx(true[-1], rel=3e-4)
    analysed_rise = (true[-1] / true[0] - 1) / COPPER_PER_K          # 13.1 K over the analysed periods
    assert heating.rise_k == pytest.approx(analysed_rise, rel=0.03)
    assert heating.significant and "warmed by 13" in heating.words()


def test_without_the_correction_the_drift_inflates_the_noise(hot):
    fit = fit_model(FitData.from_spectra(estimate_spectra(hot)), Model(parse_effects("lr2,creep-log")))
    assert fit.chi2_red_by_channel()["impedance"] < acceptance.NOISE_INFLATED_CHI2


def test_the_analysis_takes_the_drift_out_of_the_noise_and_says_it_with_the_validity(hot):
    result = analyze_recording(hot)
    findings = result.validity.as_json()["channels"]["current"]["findings"]
    assert any(f["code"] == "drift" for f in findings)
    assert result.validity.heating["significant"]
    for channel, chi2 in result.fit.chi2_red_by_channel().items():
        assert 0.6 < chi2 < 1.5, channel            # an honest noise estimate again
    true_mean_re = np.mean([_re(k) for k in range(SETTLE, SETTLE + PERIODS)])
    values = result.fit.values
    assert values["RE"] == pytest.approx(true_mean_re, rel=1e-3)      # the coil at its mean temperature
    assert values["Bl"] == pytest.approx(PAPER.parameters["Bl"], rel=0.01)
    mms = values["CMES"] * values["Bl"] ** 2
    assert mms == pytest.approx(PAPER.parameters["CMES"] * PAPER.parameters["Bl"] ** 2, rel=0.01)
    assert "voice coil warmed by" in drift_from_validity(result.validity)


def test_the_diagnosis_finds_nothing_missing_and_says_the_coil_warmed(hot):
    result = analyze_recording(hot)
    diagnosis = diagnose(FitData.from_spectra(result.spectra), result.fit.model, start_fit=result.fit, locate=False)
    assert diagnosis.verdict == acceptance.NOTHING_MISSING
    assert not [f for f in diagnosis.final_flags if f.code == acceptance.NOISE_INFLATED]
    assert "the voice coil warmed by" in verdict_text(diagnosis, drift_from_validity(result.validity))


def test_a_steady_coil_is_left_alone():
    mt = multitone()
    steady = synthesize_recording(Model(parse_effects("lr2,creep-log")), PAPER.parameters, mt.waveform,
                                  mt.excited_bins, mt.sample_rate, PERIODS, SETTLE, TYPICAL_NOISE, seed=21)
    result = analyze_recording(steady)
    assert result.validity.heating is None
    spectra = estimate_spectra(steady)
    heating = coil_heating(steady, spectra, result.fit.values["RE"])
    assert not heating.significant and abs(heating.rise_k) < 0.2
