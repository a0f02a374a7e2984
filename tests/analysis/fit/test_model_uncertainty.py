"""The model part of the uncertainty: it covers the truth where the model misses physics, and is 0 where not.

The realistic recordings (tests/realistic_drivers.py) have several physics at once, none in any model's
form; their truth is known. Fitted over every line, the statistical uncertainty alone left the truth 2-8
std away on each of them; fitted over the piston band (analysis.fit.bands, issue 29) it leaves it 1.2-2.7
std away, and with the model part the truth of RE, Bl, Mms and Kms lies within 2 reported std.
"""
import math
import threading

import pytest

from analysis.curves.fitting import LINES_PER_DECADE, FitRange, fit_curves
from analysis.effects import parse_effects
from analysis.fit.least_squares import FitCancelled
from analysis.fit.model_uncertainty import alternative_models, describes_the_data, model_uncertainty
from analysis.importers import read_curve, read_uiv
from analysis.model.composed import Model
from analysis.pipeline import analyze_recording
from tests.builders import REAL_DATA, TYPICAL_NOISE, recording
from tests.realistic_drivers import REALISTIC, realistic_recording

LUMPED = ("RE", "Bl", "Mms", "Kms")
AS_THE_CLI_DOES = FitRange(per_decade=LINES_PER_DECADE)      # linpar analyze --uiv / --impedance


def z_score(p, truth):
    return math.inf if not p.std else (p.value - truth) / p.std


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("name", sorted(REALISTIC))
def test_the_truth_lies_within_two_reported_std_on_realistic_recordings(name, seed):
    statistical = analyze_recording(realistic_recording(name, seed))
    truth = REALISTIC[name].truth
    result = model_uncertainty(statistical)
    for k in LUMPED:
        p = result.parameters[k]
        assert p.value == statistical.parameters[k].value, k        # the reported value stays the fit's
        assert abs(p.value - truth[k]) <= 2.0 * p.std, (k, p.value, truth[k], p.std)
        assert p.std_model > 0 and p.std == pytest.approx(math.hypot(p.std_noise or 0.0, p.std_model)), k
        assert p.std_model < 0.15 * truth[k], k          # wide, but still a measurement


def test_a_recording_the_model_describes_gets_no_model_part_and_no_refit(monkeypatch):
    result = analyze_recording(recording(noise=TYPICAL_NOISE, seed=3))
    assert describes_the_data(result.fit)
    monkeypatch.setattr("analysis.fit.model_uncertainty.fit_with", lambda *a, **k: pytest.fail("refitted"))
    after = model_uncertainty(result)
    assert after.parameters == result.parameters          # nothing changes: no model part, the std the noise's


def test_the_alternatives_exchange_the_blocked_impedance_and_the_creep_law():
    models = alternative_models(Model(parse_effects("lr2,creep-log,delay-x")))
    ids = {m.effect_ids for m in models}
    assert len(ids) == 7 and all("delay-x" in i for i in ids)
    assert frozenset({"leach", "creep-log-causal", "delay-x"}) in {frozenset(i) for i in ids}
    assert alternative_models(Model(parse_effects("none"))) == []


def test_the_model_part_on_a_pool_is_the_one_without(pool):
    """The GUI hands the refits to worker processes (app.jobs.background_pool): the same fits, the same numbers."""
    statistical = analyze_recording(realistic_recording("woofer", 0))
    alone, pooled = model_uncertainty(statistical), model_uncertainty(statistical, executor=pool)
    assert alone.model_part.members and pooled.model_part.members == alone.model_part.members
    assert pooled.parameters == alone.parameters


def test_a_cancelled_model_part_stops():
    statistical = analyze_recording(realistic_recording("woofer", 0))
    cancel = threading.Event()
    cancel.set()
    with pytest.raises(FitCancelled):
        model_uncertainty(statistical, cancel)



needs_real = pytest.mark.skipif(not (REAL_DATA / "woofer_uiv_laser").is_dir(),
                                reason="the real data set is not on this machine")


@needs_real
def test_a_real_woofer_by_the_whole_laser_method_covers_the_lecturers_values():
    uiv = read_uiv(REAL_DATA / "woofer_uiv_laser" / "meas_data_UIV_spectra_1Hz-10kHz.csv")
    result = model_uncertainty(fit_curves(uiv.impedance, uiv.displacement, None, None, AS_THE_CLI_DOES))
    p = result.parameters
    assert p["Bl"].value == pytest.approx(10.8, rel=0.02)       # the lecturer's Bl
    for name, reference in (("Bl", 10.8), ("Rms", 2.44)):
        assert abs(p[name].value - reference) <= 2 * p[name].std, name
        assert p[name].std_model > p[name].std_noise, name       # the model misses far more than the noise


@needs_real
def test_a_real_impedance_covers_the_advanced_fit_of_another_tool():
    z = read_curve(REAL_DATA / "seas_l16rnx" / "L16RNX_0g_242_27mV.zma").transfer
    p = model_uncertainty(fit_curves(z, None, None, None, AS_THE_CLI_DOES)).parameters
    # Speakerbench's fit with a semi-inductance and a 3-parameter creep: RE 5.7212 ohm, fs 44.985 Hz. The
    # default model's RE is 10 % above it; its noise part alone says 0.2 %.
    assert abs(p["RE"].value - 5.7212) > 10 * p["RE"].std_noise
    for name, reference in (("RE", 5.7212), ("fs", 44.985)):
        assert abs(p[name].value - reference) <= 2 * p[name].std, name


def test_model_part_is_built_by_keyword_only():
    import dataclasses

    from analysis.fit.model_uncertainty import ModelPart
    assert all(field.kw_only for field in dataclasses.fields(ModelPart))
