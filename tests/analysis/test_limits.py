"""QA limits: parsing with one-line errors naming file, line and key; pass/fail per parameter."""
import json

import pytest

from analysis.derived import ParameterValue
from analysis.limits import LimitsError, judge_result, load_limits
from analysis.validity.result import ResultValidity


def write(tmp_path, doc, name="limits.json"):
    path = tmp_path / name
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc, indent=2))
    return path


def limits_doc(**parameters):
    return {"format": "linpar-limits/1", "name": "test", "parameters": parameters}


def pv(name, value, unit, display_unit, scale, reason=None, rel_std=0.001):
    """A parameter measured to 0.1 % (1 sigma), well inside the tolerances below: its interval decides as its value."""
    return ParameterValue(name=name, value=value, std=None if value is None else rel_std * abs(value), unit=unit,
                          display_unit=display_unit, display_scale=scale, reason=reason)


PARAMS = {"RE": pv("RE", 3.02, "ohm", "ohm", 1.0), "fs": pv("fs", 70.5, "Hz", "Hz", 1.0),
          "Mms": pv("Mms", 11.87e-3, "kg", "g", 1e3), "Cms": pv("Cms", 0.43e-3, "m/N", "mm/N", 1e3),
          "LE": pv("LE", 0.132e-3, "H", "mH", 1e3), "Qts": pv("Qts", 0.46, "1", "-", 1.0),
          "Bl": pv("Bl", None, "T*m", "T*m", 1.0, "not identifiable without displacement")}


def verdicts(tmp_path, validity="green", **parameters):
    doc = judge_result(load_limits(write(tmp_path, limits_doc(**parameters))), PARAMS, validity)
    return doc["verdict"], {p["parameter"]: p["pass"] for p in doc["parameters"]}


def test_nominal_and_percent_or_absolute_tolerance(tmp_path):
    assert verdicts(tmp_path, RE={"nominal": 3.0, "tolerance": "1%", "unit": "ohm"}) == ("pass", {"RE": True})
    assert verdicts(tmp_path, RE={"nominal": 3.0, "tolerance": "0.3%", "unit": "ohm"}) == ("fail", {"RE": False})
    assert verdicts(tmp_path, fs={"nominal": 70, "tolerance": 0.7, "unit": "Hz"})[0] == "pass"
    assert verdicts(tmp_path, fs={"nominal": 70, "tolerance": 0.3, "unit": "Hz"})[0] == "fail"


def test_customary_and_si_units_give_the_same_verdict(tmp_path):
    for unit, lo, hi in (("g", 11.8, 11.9), ("kg", 11.8e-3, 11.9e-3)):
        assert verdicts(tmp_path, Mms={"min": lo, "max": hi, "unit": unit})[0] == "pass"
    assert verdicts(tmp_path, LE={"max": 0.13, "unit": "mH"})[0] == "fail"
    assert verdicts(tmp_path, LE={"max": 0.14e-3, "unit": "H"})[0] == "pass"
    assert verdicts(tmp_path, Cms={"min": 0.4, "unit": "mm/N"})[0] == "pass"
    assert verdicts(tmp_path, Qts={"nominal": 0.46, "tolerance": "5%", "unit": "-"})[0] == "pass"


def test_a_parameter_may_be_named_as_the_window_shows_it(tmp_path):
    # The window's table and the reports say Re and Le; a user copies the name from there.
    assert verdicts(tmp_path, Re={"nominal": 3.0, "tolerance": "1%", "unit": "ohm"}) == ("pass", {"RE": True})
    assert verdicts(tmp_path, Le={"max": 0.13, "unit": "mH"}) == ("fail", {"LE": False})


def test_overall_fails_when_any_fails_and_missing_parameters_fail(tmp_path):
    verdict, each = verdicts(tmp_path, RE={"nominal": 3.0, "tolerance": "5%", "unit": "ohm"},
                             Bl={"min": 5, "unit": "T*m"})
    assert verdict == "fail" and each == {"RE": True, "Bl": False}


def test_a_red_measurement_is_invalid_not_pass_or_fail(tmp_path):
    assert verdicts(tmp_path, "red", RE={"nominal": 3.0, "tolerance": "5%", "unit": "ohm"})[0] == "invalid"
    assert verdicts(tmp_path, "yellow", RE={"nominal": 3.0, "tolerance": "5%", "unit": "ohm"})[0] == "pass"


BAD = [
    ('{"format": "linpar-limits/1", "parameters": {\n  "RE": {"nominal": 3,}\n}}', r"line 2 column \d+: .*expected JSON"),
    (limits_doc(), r"parameters: expected an object"),
    ({"format": "other", "parameters": {}}, r"line 2: format: found 'other', expected 'linpar-limits/1'"),
    (limits_doc(XYZ={"min": 1, "unit": "ohm"}), r"line \d+: parameters.XYZ: unknown parameter"),
    (limits_doc(RE={"min": 1}), r"parameters.RE.unit: found None, expected 'ohm'$"),
    (limits_doc(RE={"min": 1, "unit": "mohm"}), r"parameters.RE.unit: found 'mohm', expected 'ohm'$"),
    (limits_doc(RE={"min": 1, "unit": "ohm"}, Re={"min": 2, "unit": "ohm"}),
     r"parameters.Re: the same parameter as 'RE': give its limits once"),
    (limits_doc(Mms={"min": 1, "unit": "lb"}), r"parameters.Mms.unit: found 'lb', expected 'kg' \(SI\) or 'g'"),
    (limits_doc(RE={"nominal": 3, "unit": "ohm"}), r"parameters.RE.tolerance: missing"),
    (limits_doc(RE={"nominal": 3, "tolerance": "five", "unit": "ohm"}), r"parameters.RE.tolerance: found 'five'"),
    (limits_doc(RE={"nominal": 3, "tolerance": -1, "unit": "ohm"}), r"parameters.RE.tolerance: found -1"),
    (limits_doc(RE={"nominal": "3", "tolerance": 1, "unit": "ohm"}), r"parameters.RE.nominal: found '3', expected a number"),
    (limits_doc(RE={"min": 4, "max": 3, "unit": "ohm"}), r"parameters.RE: min 4 is above max 3"),
    (limits_doc(RE={"unit": "ohm"}), r"parameters.RE: expected nominal and tolerance, or min and/or max"),
    (limits_doc(RE={"nominal": 3, "tolerance": 1, "min": 2, "unit": "ohm"}), r"not both"),
    (limits_doc(RE={"min": 2, "unit": "ohm", "tol": 1}), r"parameters.RE.tol: unknown key"),
    (limits_doc(RE=[1, 2]), r"parameters.RE: expected an object"),
    ('{"format": "linpar-limits/1", "parameters": {"RE": {"min": NaN, "unit": "ohm"}}}', r"NaN is not a number"),
    ("[1, 2]", r"\(top level\): expected a JSON object"),
]


@pytest.mark.parametrize("doc, message", BAD)
def test_a_bad_limits_file_gives_one_line_naming_file_line_and_key(tmp_path, doc, message):
    path = write(tmp_path, doc)
    with pytest.raises(LimitsError, match=message) as err:
        load_limits(path)
    text = str(err.value)
    assert text.startswith(str(path)) and "\n" not in text


def test_unreadable_file(tmp_path):
    with pytest.raises(LimitsError, match="missing, expected a JSON limits file"):
        load_limits(tmp_path / "missing.json")
    with pytest.raises(LimitsError, match="a folder, not a regular file"):
        load_limits(tmp_path)
    path = tmp_path / "latin.json"
    path.write_bytes(b'{"name": "\xe9"}')
    with pytest.raises(LimitsError, match="not UTF-8"):
        load_limits(path)


def test_margin_is_the_distance_to_the_nearest_bound_signed_inside_positive(tmp_path):
    limits = load_limits(write(tmp_path, limits_doc(fs={"min": 60, "max": 72, "unit": "Hz"},
                                                    Mms={"max": 11, "unit": "g"},
                                                    LE={"min": 0.1, "unit": "mH"},
                                                    Bl={"min": 5, "unit": "T*m"})))
    fs, mms, le, bl = limits.judge(PARAMS)
    assert fs.margin() == pytest.approx((1.5, "max")) and fs.tolerance_used() == pytest.approx(4.5 / 6)
    assert mms.margin()[1] == "max" and mms.margin()[0] == pytest.approx(-0.87e-3)       # 11.87 g > 11 g: outside
    assert le.margin() == pytest.approx((0.032e-3, "min")) and le.tolerance_used() is None
    assert bl.margin() is None and bl.tolerance_used() is None                            # not measured


# --- the interval rule (value +- 2 std) and the fit-error tolerance --------------------------------------------

def judged_re(tmp_path, value, std, validity="green", **extra):
    """The verdict of an RE of `value` +- `std` ohm against 3.0 ohm +- 5 % (2.85 .. 3.15)."""
    doc = limits_doc(RE={"nominal": 3.0, "tolerance": "5%", "unit": "ohm"})
    doc.update(extra)
    params = {"RE": ParameterValue(name="RE", value=value, std=std, unit="ohm", display_unit="ohm", display_scale=1.0)}
    # A validity as a stored results document holds it (or its overall light alone).
    validity = validity if isinstance(validity, str) else ResultValidity.from_json(validity)
    return judge_result(load_limits(write(tmp_path, doc)), params, validity)


def test_a_parameter_is_judged_by_its_interval_pass_fail_or_uncertain_across_a_limit(tmp_path):
    assert judged_re(tmp_path, 3.10, 0.02)["verdict"] == "pass"           # 3.06 .. 3.14 inside
    across = judged_re(tmp_path, 3.10, 0.04)                               # 3.02 .. 3.18 straddles 3.15
    assert across["verdict"] == "uncertain" and across["parameters"][0]["outcome"] == "uncertain"
    assert "measure again" in across["why"] and "RE 3.02 .. 3.18" in across["why"]
    assert across["parameters"][0]["interval"] == pytest.approx([3.02, 3.18]) and across["interval_k"] == 2
    assert judged_re(tmp_path, 3.20, 0.04)["verdict"] == "uncertain"      # value outside, interval 3.12 .. 3.28
    failed = judged_re(tmp_path, 3.30, 0.04)                               # 3.22 .. 3.38 wholly above
    assert failed["verdict"] == "fail" and "RE 0.15 Ω above max" in failed["why"]
    assert judged_re(tmp_path, 2.80, 0.01)["verdict"] == "fail"
    alone = judged_re(tmp_path, 3.14, None)          # no std: no interval, so inside is not a pass
    assert alone["verdict"] == "uncertain" and "no uncertainty" in alone["parameters"][0]["note"]
    outside_alone = judged_re(tmp_path, 9.0, None)   # ... but a value outside the limits fails on its own
    assert outside_alone["verdict"] == "fail"


def test_one_failing_parameter_fails_the_unit_whatever_the_others_uncertainty(tmp_path):
    doc = limits_doc(RE={"nominal": 3.0, "tolerance": "5%", "unit": "ohm"}, fs={"min": 80, "unit": "Hz"})
    params = {"RE": ParameterValue(name="RE", value=3.14, std=0.02, unit="ohm", display_unit="ohm",      # straddles
                                   display_scale=1.0),
              "fs": ParameterValue(name="fs", value=70.0, std=0.5, unit="Hz", display_unit="Hz",         # below 80
                                   display_scale=1.0)}
    judged = judge_result(load_limits(write(tmp_path, doc)), params, "green")
    assert judged["verdict"] == "fail" and "fs 10 Hz below min" in judged["why"] and "RE" not in judged["why"]


def misfit_validity(impedance, displacement=None):
    """A yellow measurement with a model-misfit finding (reduced chi^2 1e5) and the curves' fit errors in %."""
    errors = {"impedance": impedance, **({"displacement": displacement} if displacement is not None else {})}
    finding = {"code": "model-misfit", "severity": "yellow", "message": "impedance: reduced chi^2 1e+05",
               "remedy": "find the effect", "value": 1e5}
    return {"overall": "yellow", "fit_error_percent": errors,
            "channels": {"current": {"status": "yellow", "findings": [finding]}}}


def test_a_fit_error_of_a_few_percent_is_judged_whatever_the_reduced_chi2(tmp_path):
    judged = judged_re(tmp_path, 3.05, 0.02, misfit_validity(2.5, 6.0))
    assert judged["verdict"] == "pass" and judged["fit_error_percent"] == {"impedance": 2.5, "displacement": 6.0}
    assert judged["fit_error_tolerance_percent"] == {"impedance": 5.0, "displacement": 10.0}


def test_only_a_fit_error_above_the_tolerance_is_not_judged_with_that_reason(tmp_path):
    over = judged_re(tmp_path, 3.05, 0.02, misfit_validity(7.3))
    assert over["verdict"] == "not judged"
    assert "misses the impedance by 7.3 % rms (tolerance 5 %)" in over["why"]
    strict = judged_re(tmp_path, 3.05, 0.02, misfit_validity(2.5, 6.0),
                       fit_error_percent={"impedance": 2, "displacement": 10})
    assert strict["verdict"] == "not judged" and "tolerance 2 %" in strict["why"]
    loose = judged_re(tmp_path, 3.05, 0.02, misfit_validity(7.3), fit_error_percent={"impedance": 8})
    assert loose["verdict"] == "pass"


def test_a_result_stored_without_fit_errors_is_judged_by_its_misfit_finding_as_before(tmp_path):
    old = misfit_validity(2.0)
    del old["fit_error_percent"]
    assert judged_re(tmp_path, 3.05, 0.02, old)["verdict"] == "not judged"


@pytest.mark.parametrize("entry, message", [
    ([3, 10], r"fit_error_percent: expected an object"),
    ({"voltage": 3}, r"fit_error_percent: 'voltage': unknown curve: expected impedance or displacement"),
    ({"impedance": 0}, r"fit_error_percent.impedance: found '0', expected a positive number of %"),
    ({"impedance": "3%"}, r"fit_error_percent.impedance: found '3%'"),
])
def test_a_bad_fit_error_tolerance_gives_one_line(tmp_path, entry, message):
    doc = limits_doc(RE={"nominal": 3.0, "tolerance": "5%", "unit": "ohm"})
    doc["fit_error_percent"] = entry
    path = write(tmp_path, doc)
    with pytest.raises(LimitsError, match=message) as err:
        load_limits(path)
    assert str(err.value).startswith(str(path)) and "\n" not in str(err.value)
