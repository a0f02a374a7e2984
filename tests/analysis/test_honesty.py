"""The diagnosis is honest: physics no catalogue holds is not explained away, and it is located.

Recordings with odd physics at each of the six sites (tests/odd_physics.py)
are diagnosed from the default model: the verdict must say the catalogue
could not explain them, the site localisation must name the right site, and
no parameter may end further from the truth than the plain fit left it
(twice its error, or 0.5 %). A clean recording needs nothing; a hidden
current delay is explained.
"""
import numpy as np
import pytest

from analysis.derived import parameter_table
from analysis.diagnosis import acceptance
from analysis.diagnosis.candidates import diagnose
from analysis.effects import get_effect, parse_effects
from analysis.fit.least_squares import FitData, FitResult
from analysis.model.composed import Model
from analysis.spectra import estimate_spectra
from tests.builders import PAPER
from tests.odd_physics import ODD, odd_recording

DEFAULT = "lr2,creep-log"
COMPARED = ("RE", "LE", "Bl", "Mms", "Cms", "Kms", "Rms", "fs", "Qms", "Qes", "Qts", "Vas")
SD = 0.0133


def _truth_table() -> dict:
    model = Model(parse_effects(DEFAULT))
    values = dict(PAPER.parameters)
    exact = FitResult(model=model, values=values, stderr={k: 0.0 for k in values}, varying=tuple(values), covar=None,
                      channels={}, chi2=0.0, n_data=1, success=True, message="", nfev=0)
    return parameter_table(exact, SD)


def _diagnosed(pool, site, **kwargs):
    data = FitData.from_spectra(estimate_spectra(odd_recording(site, **kwargs)))
    return diagnose(data, Model(parse_effects(DEFAULT)), executor=pool)


@pytest.mark.parametrize("site", list(ODD))
def test_odd_physics_is_not_explained_away_and_its_site_is_found(pool, site):
    result = _diagnosed(pool, site)
    assert max(result.start.chi2_red_by_channel().values()) > 100          # far from the data to begin with
    assert result.verdict in (acceptance.PARTLY_EXPLAINED, acceptance.UNEXPLAINED), \
        [step.fit.model.effect_ids for step in result.steps]
    assert result.sites[0].key == site, [(s.key, s.delta_bic) for s in result.sites]
    assert result.sites[0].delta_bic < -acceptance.MIN_BIC_GAIN
    truth, plain, final = _truth_table(), parameter_table(result.start, SD), parameter_table(result.final, SD)
    for name in COMPARED:
        true, before, after = truth[name].value, plain[name].value, final[name].value
        allowed = max(2 * abs(before - true), 0.005 * abs(true))
        assert abs(after - true) <= allowed, f"{name}: plain {before:.5g}, final {after:.5g}, truth {true:.5g}"


def test_a_clean_recording_has_nothing_missing(pool):
    result = _diagnosed(pool, None)
    assert result.verdict == acceptance.NOTHING_MISSING
    assert result.final.model.effect_ids == ("lr2", "creep-log") and not result.step_cap_reached
    assert all(s.delta_bic > 0 for s in result.sites)            # no site's correction pays for itself


def test_a_hidden_current_delay_is_explained(pool):
    result = _diagnosed(pool, None, extra=parse_effects("delay-current"), values={"tau_i": -50e-6})
    assert result.verdict == acceptance.EXPLAINED
    assert "delay-current" in result.final.model.effect_ids
    assert result.final.values["tau_i"] == pytest.approx(-50e-6, rel=1e-3)


def test_every_candidate_carries_its_flags_and_a_flagged_one_is_never_taken(pool):
    result = _diagnosed(pool, "mechanical")
    breakup = next(c for c in result.first_candidates if c.effect.id == "breakup")
    assert breakup.delta_bic < -1e5 and breakup.flags          # a great gain in chi^2 ...
    assert {f.code for f in breakup.flags} & {acceptance.AT_BOUND, acceptance.ATYPICAL, acceptance.UNDETERMINED}
    assert not breakup.accepted and breakup.assessment.reason == acceptance.FLAGGED    # ... but not taken
    for step in result.steps:
        if step.chosen is not None:
            assert not [f for f in step.chosen.flags if f.blocking]
    for c in result.first_candidates:
        assert c.assessment is not None
        for f in c.flags:
            assert f.code and f.message and (f.parameter or f.channel)


def test_the_step_cap_is_flagged(pool):
    data = FitData.from_spectra(estimate_spectra(odd_recording(None)))
    result = diagnose(data, Model(()), executor=pool, max_steps=1)
    assert result.step_cap_reached and result.steps[-1].flags[-1].code == acceptance.STEP_CAP


@pytest.mark.parametrize("site", list(ODD))
def test_with_a_hidden_delay_too_the_delay_is_taken_and_the_rest_left_to_its_site(pool, site):
    result = _diagnosed(pool, site, extra=parse_effects("delay-current"), values={"tau_i": 20e-6})
    assert result.verdict == acceptance.PARTLY_EXPLAINED
    effects = result.final.model.effect_ids
    assert effects[:3] == ("lr2", "creep-log", "delay-current")
    # An effect of the catalogue acting at the odd physics' own site may take part of its misfit (with the
    # delay in, damping-power takes 95 % of the mechanical hump's chi^2, which passes the acceptance rule),
    # never one at another site; and the parameters are no worse for it.
    assert all(get_effect(e).site.key == site for e in effects[3:]), effects
    assert result.final.values["tau_i"] == pytest.approx(20e-6, rel=0.05)
    assert result.sites[0].key == site
    truth, final = _truth_table(), parameter_table(result.final, SD)
    plain = parameter_table(result.steps[1].fit, SD)         # the fit with the delay, before anything else
    for name in COMPARED:
        true, before, after = truth[name].value, plain[name].value, final[name].value
        allowed = max(2 * abs(before - true), 0.005 * abs(true))
        assert abs(after - true) <= allowed, f"{name}: with the delay {before:.5g}, final {after:.5g}, truth {true:.5g}"


def test_a_reduced_chi2_far_below_one_is_said_to_be_an_inflated_noise_not_the_noise_floor(pool):
    import dataclasses
    from analysis.diagnosis.words import verdict_text
    data = FitData.from_spectra(estimate_spectra(odd_recording(None)))
    inflated = FitData(*(dataclasses.replace(tf, std=10 * tf.std) for tf in (data.impedance, data.displacement)))
    result = diagnose(inflated, Model(parse_effects(DEFAULT)), executor=pool, locate=False)
    assert result.verdict == acceptance.NOTHING_MISSING
    assert {f.channel for f in result.final_flags if f.code == acceptance.NOISE_INFLATED} == {"impedance",
                                                                                              "displacement"}
    text = verdict_text(result, drift="current: the current changed by 0.4 % during the measurement")
    assert "inflated" in text and "drift" in text and "0.4 %" in text
