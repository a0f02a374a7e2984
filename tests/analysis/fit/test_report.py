"""FitResult.report(): a report in the form of lmfit's fit_report for our fits, the same in the CLI, the Model lab
and the reports."""
from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

from analysis.archive.results import StoredResult, results_document
from analysis.fit.report import MIN_CORREL, fit_report_json, fit_report_text
from analysis.pipeline import analyze_recording
from analysis.report import build_report
from tests.builders import TYPICAL_NOISE, recording


@pytest.fixture(scope="module")
def analysed():
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=21)
    return rec, analyze_recording(rec)


def test_the_report_has_the_statistics_every_parameter_with_sigma_and_the_strong_correlations(analysed):
    fit = analysed[1].fit
    text = fit.report()
    for heading in ("[[Fit statistics]]", "[[Parameters]]", "[[Correlations]]"):
        assert heading in text
    assert f"data points        = {fit.n_data}" in text and f"variables          = {fit.n_varying}" in text
    assert f"Bayesian info crit = {fit.bic:.6g}" in text
    for name in fit.varying:
        line = next(line for line in text.splitlines() if line.strip().startswith(f"{name} "))
        assert "+/-" in line, line
    # Exactly the pairs with |r| >= 0.5, strongest first, as the covariance says.
    r = fit.correlation()
    expected = {frozenset((a, b)): r[i, j] for i, a in enumerate(fit.varying) for j, b in enumerate(fit.varying)
                if i < j and abs(r[i, j]) >= MIN_CORREL}
    listed = re.findall(r"C\((\S+), (\S+)\) = ([+-][0-9.]+)", text)
    assert {frozenset((a, b)) for a, b, _ in listed} == set(expected) and expected
    assert [abs(float(v)) for *_, v in listed] == sorted((abs(float(v)) for *_, v in listed), reverse=True)
    for a, b, v in listed:
        assert float(v) == pytest.approx(expected[frozenset((a, b))], abs=1e-3)
    assert "[[Notes]]" not in text            # nothing on a bound, a covariance


def test_a_lower_threshold_lists_more_pairs(analysed):
    fit = analysed[1].fit
    assert len(fit_report_json(fit, 0.1)["correlations"]) > len(fit_report_json(fit, 0.5)["correlations"])


def test_a_parameter_on_its_bound_is_a_note_and_held_without_sigma(analysed):
    fit = analysed[1].fit
    spec = fit.model.spec("lambda")
    held = dataclasses.replace(fit, values={**fit.values, "lambda": spec.min}, stderr={**fit.stderr, "lambda": None},
                               varying=tuple(n for n in fit.varying if n != "lambda"), covar=None)
    text = held.report()
    assert "[[Notes]]" in text and "lambda = -0.5 ended on its lower bound" in text
    assert re.search(r"lambda\s+= -0.5 \(held\)", text)
    assert "no covariance: the uncertainties and correlations could not be estimated" in text
    assert "[[Correlations]] (unreported correlations are below 0.5 in absolute value)\n    none" in text


def test_a_fit_that_did_not_converge_says_so(analysed):
    fit = dataclasses.replace(analysed[1].fit, success=False, message="too many function evaluations")
    assert "converged          = NO: too many function evaluations" in fit.report()


def test_the_stored_result_keeps_the_report_and_the_printed_report_shows_it(analysed):
    rec, result = analysed
    doc = results_document(result, rec)
    stored = StoredResult.from_json(doc)
    assert fit_report_text(stored.model_info["report"]) == result.fit.report()        # the same words later
    appendix = dict(build_report(stored, {}, None, None).fit)        # the engineering detail: the appendix
    strongest = fit_report_json(result.fit)["correlations"][0]
    assert f"{strongest['a']}–{strongest['b']} {strongest['r']:+.2f}" in appendix["Correlations (|r| ≥ 0.5)"]
    assert np.isfinite(doc["model"]["report"]["statistics"]["bic"])
