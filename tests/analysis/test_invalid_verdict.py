"""INVALID is its own verdict (issue 32): a broken measurement reads "INVALID: measure again" in its own word and
colour in the JSON, the report and the archive; never a PASS, never a FAIL, never in a yield."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from analysis.archive import Archive
from analysis.archive.population import Population
from analysis.archive.results import StoredResult, results_document
from analysis.limits import judge_result, parse_limits
from analysis.pipeline import analyze_recording
from analysis.production import production_stats
from analysis.recording import make_recording
from analysis.report import build_report
from analysis.report.html import render_html
from analysis.report.qa import VERDICT_COLOURS
from analysis.validity.fit import FAIL, INVALID, VERDICT_HEADLINES
from tests.builders import TYPICAL_NOISE, recording

LIMITS_DOC = {"format": "linpar-limits/1", "name": "woofer QA", "parameters": {
    "RE": {"nominal": 3.0, "tolerance": "5%", "unit": "ohm"}}}
LIMITS = parse_limits(LIMITS_DOC, "", Path("woofer.json"))


@pytest.fixture(scope="module")
def broken():
    """A current lead that reads nothing: red, nothing fitted."""
    rec = recording(noise=TYPICAL_NOISE, n_periods=4, seed=31)
    signals = {c.signal: rec.signal(c.signal) for c in rec.channels}
    signals["current"] = np.zeros_like(signals["current"])
    rec = make_recording(rec.sample_rate, signals, rec.period_samples, rec.settle_periods, rec.excited_bins,
                         dict(rec.driver))
    return rec, analyze_recording(rec)


def test_the_json_verdict_is_invalid_with_what_to_do(broken):
    _, result = broken
    judged = judge_result(LIMITS, result.parameters, result.validity)
    assert judged["verdict"] == INVALID and "measure again" in judged["why"]
    assert all(not p["pass"] for p in judged["parameters"])
    assert VERDICT_HEADLINES[INVALID] == "INVALID: measure again"


def test_the_report_says_invalid_in_its_own_colour_not_fails_red(broken):
    _, result = broken
    stored = StoredResult.from_json(results_document(result))
    page = render_html(build_report(stored, {}, None, {}, LIMITS))
    assert "QA: INVALID: measure again" in page and "QA: FAIL" not in page
    assert VERDICT_COLOURS[INVALID] != VERDICT_COLOURS[FAIL]
    assert f"background:{VERDICT_COLOURS[INVALID][0]}" in page and f"background:{VERDICT_COLOURS[FAIL][0]}" not in page


def test_the_archive_stores_invalid_never_fail(tmp_path, broken):
    rec, result = broken
    archive = Archive(tmp_path / "archive")
    archive.store_limits(LIMITS_DOC)
    good = analyze_recording(recording(noise=TYPICAL_NOISE, n_periods=4, seed=32))
    ids = {archive.store(rec, result, {"serial": "broken"}): "broken",
           archive.store(recording(noise=TYPICAL_NOISE, n_periods=4, seed=32), good, {"serial": "good"}): "good"}
    verdicts = {e.serial: e.verdict for e in archive.list()}
    assert verdicts == {"broken": INVALID, "good": "pass"}, ids


def test_production_yield_leaves_invalid_units_out_and_says_so():
    n = 6
    verdicts = ("pass", "pass", "fail", INVALID, INVALID, "pass")
    validity = ("green", "green", "green", "red", "red", "green")
    population = Population(tuple(f"20240501-{i:06d}-abcdef" for i in range(n)),
                            tuple(f"2024-05-01T00:00:{i:02d}Z" for i in range(n)), ("QA1",) * n, ("W6",) * n,
                            tuple(f"SN{i}" for i in range(n)), ("ana",) * n, validity, verdicts, (1,) * n,
                            {"RE": (3.0,) * n}, {"RE": (0.01,) * n})
    stats = production_stats(population)
    assert stats.first_pass_yield == pytest.approx(3 / 4)         # 3 pass of 4 judged; the 2 invalid not failed
    assert stats.verdicts[INVALID] == 2
    assert sum(stats.excluded.values()) == 2 and any("invalid" in reason for reason in stats.excluded)


def test_a_unit_whose_first_test_was_invalid_is_counted_by_its_first_judged_test():
    """SN1: broken lead (invalid), then fail; SN2: invalid, then pass; SN3: pass. The invalid tests say nothing of
    their units: first-pass yield 2 of 3, where the first tests alone counted SN3 only (1 of 1)."""
    verdicts = (INVALID, "fail", INVALID, "pass", "pass", "pass")
    serials = ("SN1", "SN1", "SN2", "SN2", "SN3", "SN1")
    validity = ("red", "green", "red", "green", "green", "green")
    n = len(verdicts)
    population = Population(tuple(f"20240501-{i:06d}-abcdef" for i in range(n)),
                            tuple(f"2024-05-01T00:00:{i:02d}Z" for i in range(n)), ("QA1",) * n, ("W6",) * n,
                            serials, ("ana",) * n, validity, verdicts, (1,) * n,
                            {"RE": (3.0,) * n}, {"RE": (0.01,) * n})
    assert production_stats(population).first_tests == (2, 3)    # SN1's fail, SN2's and SN3's pass; SN1's retest not
