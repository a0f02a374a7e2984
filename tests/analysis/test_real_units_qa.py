"""QA judges real units: a driver with physics the default model lacks, whose fit error is a few %, is judged.

The recording has four physics the default model (lr2, creep-log) does not:
a semi-inductance (leach) in place of LR-2, a fractional creep law, damping
that rises with frequency, and eddy currents that take 5 % of Bl above
2 kHz. The default fit then misses |Z| by about 3 % and Hx by about 4 % (a
reduced chi^2 of ~1e6 with the tests' noise): what a real driver measured
well looks like (LPM sheets print 1.5-3 %). Before, such a unit was "not
judged" whatever its limits; now it is judged, by each parameter's interval.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from analysis.effects import parse_effects
from analysis.limits import judge_result, parse_limits
from analysis.model import Model
from analysis.pipeline import analyze_recording
from analysis.report.qa import qa_section
from analysis.synthesis import synthesize_recording
from analysis.validity.findings import MODEL_MISFIT
from tests.builders import PAPER, REAL_DATA, TYPICAL_NOISE, multitone

TRUTH = {**{k: v for k, v in PAPER.parameters.items() if k not in ("L2", "R2", "lambda")},
         "K": 0.002, "n": 0.7, "beta": 0.06, "r_v": 0.3, "n_v": 0.5, "dBl": 0.05, "f_Bl": 2000.0}
PHYSICS = "leach,creep-fractional,damping-power,bl-eddy"


def truth_of(name: str) -> float:
    bl = TRUTH["Bl"]
    return {"RE": TRUTH["RE"], "Bl": bl, "Mms": TRUTH["CMES"] * bl ** 2, "Kms": bl ** 2 / TRUTH["LCES"]}[name]


def limits_around_truth(percent: float):
    units = {"RE": "ohm", "Bl": "T*m", "Mms": "kg", "Kms": "N/m"}
    return parse_limits({"format": "linpar-limits/1", "name": f"truth ± {percent:g} %", "parameters": {
        name: {"nominal": truth_of(name), "tolerance": f"{percent:g}%", "unit": unit}
        for name, unit in units.items()}}, "", Path(f"truth-{percent:g}.json"))


@pytest.fixture(scope="module")
def real_unit():
    mt = multitone()
    rec = synthesize_recording(Model(parse_effects(PHYSICS)), TRUTH, mt.waveform, mt.excited_bins, mt.sample_rate,
                               8, 1, TYPICAL_NOISE, seed=5, driver={"name": "synthetic, several physics",
                                                                    "sd_m2": 0.0133})
    return analyze_recording(rec)


def test_the_fit_error_of_the_unit_is_a_few_percent_though_its_reduced_chi2_is_huge(real_unit):
    errors = real_unit.validity.fit_error_percent
    assert 1.5 < errors["impedance"] < 5 and 1.5 < errors["displacement"] < 10
    assert min(real_unit.fit.chi2_red_by_channel().values()) > 1e4
    findings = [f["code"] for ch in real_unit.validity.as_json()["channels"].values() for f in ch.get("findings") or ()]
    assert MODEL_MISFIT in findings            # the reduced chi^2 stays in the details, as a yellow finding


def test_limits_at_the_truth_plus_minus_15_percent_pass(real_unit):
    judged = judge_result(limits_around_truth(15), real_unit.parameters, real_unit.validity)
    assert judged["verdict"] == "pass", judged["why"]
    assert all(p["outcome"] == "pass" for p in judged["parameters"])
    section = qa_section(limits_around_truth(15), real_unit.parameters, real_unit.validity)
    assert section.headline == "PASS" and "impedance" in section.fit_error


def test_no_false_fail_limits_the_truth_is_inside_never_fail(real_unit):
    """Tighter limits around the truth: the unit is a good one, so a verdict may be uncertain, never FAIL."""
    for percent in (10, 5, 3):
        judged = judge_result(limits_around_truth(percent), real_unit.parameters, real_unit.validity)
        assert judged["verdict"] in ("pass", "uncertain"), (percent, judged["why"])


def test_a_tolerance_below_the_fit_error_makes_it_not_judged_with_the_reason(real_unit):
    limits = parse_limits({"format": "linpar-limits/1", "fit_error_percent": {"impedance": 1.0},
                           "parameters": {"RE": {"nominal": TRUTH["RE"], "tolerance": "15%", "unit": "ohm"}}},
                          "", Path("strict.json"))
    judged = judge_result(limits, real_unit.parameters, real_unit.validity)
    assert judged["verdict"] == "not judged" and "misses the impedance by" in judged["why"]
    assert "tolerance 1 %" in judged["why"]


SEAS_FREE_AIR = REAL_DATA / "seas_l16rnx" / "L16RNX_0g_242_27mV.zma"


@pytest.mark.skipif(not SEAS_FREE_AIR.exists(), reason=f"the real SEAS L16RNX data set is not at {SEAS_FREE_AIR}")
def test_a_real_driver_measured_to_10_khz_is_judged_and_passes_limits_around_its_reference():
    """SEAS L16RNX free air, |Z| and phase to 10 kHz (a multitone recording's band): the default model misses it by
    about 4 %, under the 5 % tolerance; against Speakerbench's Re 5.72 ohm and fs 44.985 Hz +- 15 % it passes."""
    from analysis.curves.fitting import FitRange, fit_curves
    from analysis.importers import read_curve
    result = fit_curves(read_curve(SEAS_FREE_AIR).transfer, None, None, None, FitRange(f_max=10_000.0))
    assert 2.0 < result.validity.fit_error_percent["impedance"] < 5.0
    limits = parse_limits({"format": "linpar-limits/1", "parameters": {
        "RE": {"nominal": 5.7212, "tolerance": "15%", "unit": "ohm"},
        "fs": {"nominal": 44.985, "tolerance": "15%", "unit": "Hz"}}}, "", Path("seas.json"))
    assert judge_result(limits, result.parameters, result.validity)["verdict"] == "pass"
