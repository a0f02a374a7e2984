"""Silent and degenerate channels are judged, not crashed on (analysis.validity.fit, analysis.validity.wiring).

A silent voltage or current leaves the impedance nothing to fit: the result keeps its judged channels (red,
with the remedy) and every parameter "not measured" with the reason. A silent displacement is left out and
the electrical parameters are fitted as for a recording without the laser. A channel that copies another is
a wiring fault (red), and a misfit far above the noise is yellow: QA never passes either.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from analysis.limits import judge_result, parse_limits
from analysis.pipeline import NotAnalysable, analyze_recording, require_fit
from analysis.recording.format import make_recording
from analysis.report.qa import qa_section
from analysis.validity.findings import CHANNEL_COPY, MODEL_MISFIT, NO_SIGNAL
from tests.builders import PAPER, TYPICAL_NOISE, recording

LIMITS = parse_limits({"format": "linpar-limits/1", "parameters": {
    "RE": {"min": 0.1, "max": 100, "unit": "ohm"}}}, "", Path("wide.json"))


@pytest.fixture(scope="module")
def good():
    return recording(noise=TYPICAL_NOISE, n_periods=4, seed=21)


def variant(rec, **signals):
    """The recording with some signals replaced (a function of the old signals, or an array)."""
    data = {c.signal: rec.signal(c.signal) for c in rec.channels}
    for name, make in signals.items():
        data[name] = make(data) if callable(make) else make
    return make_recording(rec.sample_rate, data, rec.period_samples, rec.settle_periods, rec.excited_bins,
                          dict(rec.driver))


def codes(result, channel):
    return [f["code"] for f in result.validity.as_json()["channels"][channel]["findings"]]


def finite_json(result) -> dict:
    from analysis.pipeline import result_json
    return json.loads(json.dumps(result_json(result), allow_nan=False))


@pytest.mark.parametrize("silent", ["voltage", "current"])
def test_a_silent_voltage_or_current_is_red_with_its_remedy_and_nothing_is_fitted(good, silent):
    result = analyze_recording(variant(good, **{silent: lambda d: np.zeros_like(d["voltage"])}))
    assert result.fit is None and result.validity.overall == "red"
    finding = result.validity.as_json()["channels"][silent]["findings"][0]
    assert finding["code"] == NO_SIGNAL and finding["remedy"]
    assert all(p.value is None and silent in p.reason and finding["remedy"] in p.reason
               for p in result.parameters.values())
    assert finite_json(result)["model"]["not_fitted"] == result.not_fitted
    with pytest.raises(NotAnalysable, match=f"cannot be reported: the impedance cannot be fitted: {silent}"):
        require_fit(result, "be reported")
    assert judge_result(LIMITS, result.parameters, result.validity)["verdict"] == "invalid"


def test_a_silent_displacement_still_gives_the_electrical_parameters(good):
    result = analyze_recording(variant(good, displacement=lambda d: np.zeros_like(d["voltage"])))
    impedance_only = analyze_recording(make_recording(
        good.sample_rate, {"voltage": good.signal("voltage"), "current": good.signal("current")},
        good.period_samples, good.settle_periods, good.excited_bins, dict(good.driver)))
    assert result.fit is not None and not result.fit.model.with_displacement
    assert NO_SIGNAL in codes(result, "displacement") and result.validity.overall == "red"
    for name in ("RE", "LE", "fs", "Qts", "Qes", "Qms"):       # as for a recording made without the laser
        assert result.parameters[name].value == pytest.approx(impedance_only.parameters[name].value, rel=1e-9)
    for name in ("Bl", "Mms", "Cms", "Vas"):
        assert result.parameters[name].value is None and "displacement: only 0%" in result.parameters[name].reason
    doc = finite_json(result)       # no NaN anywhere (it used to be NaN for every parameter, RE too)
    assert doc["parameters"]["RE"]["value"] == pytest.approx(PAPER.parameters["RE"], rel=1e-3)


@pytest.mark.parametrize("copy, onto", [("current", "voltage"), ("displacement", "current")])
def test_a_channel_that_copies_another_is_a_red_wiring_finding_never_green_never_pass(good, copy, onto):
    result = analyze_recording(variant(good, **{copy: lambda d: -0.37 * d[onto]}))
    assert result.validity.overall == "red"
    (finding,) = [f for f in result.validity.as_json()["channels"][copy]["findings"] if f["code"] == CHANNEL_COPY]
    assert f"a scaled copy of the {onto}" in finding["message"] and "wiring" in finding["remedy"]
    judged = judge_result(LIMITS, result.parameters, result.validity)
    assert judged["verdict"] == "invalid"
    assert qa_section(LIMITS, result.parameters, result.validity).headline == "INVALID: measure again"


def test_current_equal_to_voltage_gives_no_fit_and_no_pass(good):
    """The issue's case: Z = 1 ohm exactly, chi^2_red 2e10, used to be green and pass a limit on RE."""
    result = analyze_recording(variant(good, current=lambda d: d["voltage"].copy()))
    assert result.fit is None and CHANNEL_COPY in codes(result, "current")
    assert "the impedance is 1 Ω at every line" in result.not_fitted
    assert judge_result(LIMITS, result.parameters, result.validity)["verdict"] == "invalid"


@pytest.fixture(scope="module")
def misfit():
    """A current sense that lags by 5.2 us, which the default model lacks: reduced chi^2 ~ 1e6 on Z."""
    values = {**PAPER.parameters, "tau_i": 5.2e-6}
    return analyze_recording(recording(values, "lr2,creep-log,delay-current", noise=TYPICAL_NOISE, n_periods=4,
                                       seed=22))


def test_a_misfit_of_1e6_is_yellow_and_qa_does_not_judge_it(misfit):
    chi2 = misfit.fit.chi2_red_by_channel()["impedance"]
    assert 2e5 < chi2 < 5e6
    assert misfit.validity.overall in ("yellow", "red")
    (finding,) = [f for f in misfit.validity.as_json()["channels"]["current"]["findings"] if f["code"] == MODEL_MISFIT]
    assert finding["severity"] == "yellow" and "does not describe this measurement" in finding["message"]
    assert "Model lab" in finding["remedy"] and finding["value"] == pytest.approx(chi2)
    judged = judge_result(LIMITS, misfit.parameters, misfit.validity)
    assert judged["verdict"] == "not judged" and "does not describe" in judged["why"]
    section = qa_section(LIMITS, misfit.parameters, misfit.validity)
    assert section.verdict == "not judged" and all(row.outcome == "not judged" for row in section.rows)


def test_a_model_that_fits_leaves_the_measurement_green(good):
    result = analyze_recording(good)
    assert result.validity.overall == "green"
    assert max(result.fit.chi2_red_by_channel().values()) < 2
    assert judge_result(LIMITS, result.parameters, result.validity)["verdict"] == "pass"


def test_every_parameter_of_a_result_is_finite_or_null_with_a_reason(good):
    for rec in (variant(good, displacement=lambda d: np.zeros_like(d["voltage"])),
                variant(good, voltage=lambda d: np.zeros_like(d["voltage"]))):
        for p in analyze_recording(rec).parameters.values():
            assert (p.value is None and p.reason) or math.isfinite(p.value)


def test_a_refit_that_fits_takes_the_misfit_finding_away(misfit):
    """The Model lab's versions: the validity goes with the fit, not with the model first fitted."""
    from analysis.effects import parse_effects
    from analysis.fit.least_squares import FitData, fit_model
    from analysis.model.composed import Model
    from analysis.validity.fit import qa_blocker, rejudged
    better = fit_model(FitData.from_spectra(misfit.spectra), Model(parse_effects("lr2,creep-log,delay-current")))
    assert max(better.chi2_red_by_channel().values()) < 2
    validity = rejudged(misfit.validity, better)
    assert validity.overall == "green" and qa_blocker(validity) is None
    assert rejudged(validity, misfit.fit).overall == "yellow"          # and back
