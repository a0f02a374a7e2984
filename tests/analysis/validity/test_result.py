"""analysis.validity.result: a result's validity, typed; its JSON as before, and stored documents read back."""
from __future__ import annotations

import copy
import dataclasses
import json
import math
import pickle
import re
from pathlib import Path

import pytest

from analysis.pipeline import analyze_recording
from analysis.validity.findings import Severity
from analysis.validity.result import UNKNOWN, ResultValidity, ResultValidityError
from instruments.simulation import faults

ROOT = Path(__file__).resolve().parents[3]


def finding(code: str, severity: str = "yellow", value: float | None = 2.5) -> dict:
    return {"code": code, "severity": severity, "message": f"{code}: measured", "remedy": "do this", "value": value}


# The shapes `linpar analyze --json` printed under "validity" before the type, and the archive stored.
RECORDING = {
    "overall": "yellow",
    "channels": {"voltage": {"status": "green", "findings": []},
                 "current": {"status": "yellow", "findings": [finding("drift"), finding("model-misfit", value=None)]},
                 "displacement": {"status": "absent", "findings": []}},
    "peak_displacement_m": None,
    "fit_error_percent": {"impedance": 0.8},
    "fit_band_hz": {"impedance": [14.6, 9999.0]},
    "heating": {"rise_k": 12.0, "significant": True, "text": "the voice coil warmed by 12 K"},
    "laser_delay": {"delay_s": 0.003, "placed": True},
    "model_part": {"state": "estimated", "seconds": 1.5, "models": [["lr2", "creep-log"], ["lr2", "creep-exp"]]},
}
NOT_FITTED = {"overall": "red",
              "channels": {"voltage": {"status": "green", "findings": []},
                           "current": {"status": "red", "findings": [finding("no-signal", "red", 0.0)]},
                           "displacement": {"status": "green", "findings": []}},
              "peak_displacement_m": 0.00051}
CURVES = {"overall": "unknown", "note": "imported curves: no validity checks", "uncertainties": "from the scatter",
          "rms_relative_residual": {"impedance": 0.01, "displacement": None}, "fit_error_percent": {"impedance": 1.0},
          "magnitude_only": ["impedance"], "ranges_hz": {"impedance": [10.0, 2000.0]}, "notes": ["a note"],
          "model_part": {"state": "not needed", "seconds": 0.0, "models": []}}
NOT_A_DRIVER = {**{k: v for k, v in CURVES.items() if k != "model_part"}, "overall": "red",
                "channels": {"impedance": {"findings": [finding("not-passive", "red")]}}}


@pytest.mark.parametrize("doc", [RECORDING, NOT_FITTED, CURVES, NOT_A_DRIVER],
                         ids=["recording", "not-fitted", "curves", "not-a-driver"])
def test_a_stored_validity_reads_back_and_writes_the_same_json_byte_for_byte(doc):
    validity = ResultValidity.from_json(json.loads(json.dumps(doc)))
    assert json.dumps(validity.as_json()) == json.dumps(doc)


def test_the_fields_read_as_they_mean():
    v = ResultValidity.from_json(RECORDING)
    assert v.overall == Severity.YELLOW and v.fit_error_percent == {"impedance": 0.8}
    assert v.codes("current") == {"drift", "model-misfit"} and v.channels["displacement"].status == "absent"
    assert math.isnan(v.channel_findings("current")[1].value) and v.channel_findings("impedance") == ()
    assert v.heating_words == "the voice coil warmed by 12 K" and v.peak_displacement_m is None
    assert v.imported is None and ResultValidity.from_json(CURVES).imported.magnitude_only == ("impedance",)
    assert ResultValidity.from_json(NOT_A_DRIVER).channels["impedance"].status is None


def test_an_old_document_keeps_what_this_version_does_not_know_and_lacks_what_it_did_not_have():
    old = {"overall": "green", "channels": {"voltage": {"status": "green", "findings": []}},
           "peak_displacement_m": 0.0002, "rms_relative_residual": {"impedance": 0.02}}
    v = ResultValidity.from_json(old)
    assert v.fit_error_percent is None and v.model_part is None and v.imported is None
    assert v.other == {"rms_relative_residual": {"impedance": 0.02}}
    assert v.as_json() == old
    assert ResultValidity.from_json({}).overall == UNKNOWN and ResultValidity.from_json(None).as_json()["overall"] \
        == UNKNOWN


@pytest.mark.parametrize("doc, key", [
    ([], "validity: expected an object"),
    ({"overall": 3}, "validity.overall"),
    ({"channels": []}, "validity.channels: expected an object"),
    ({"channels": {"current": {"findings": {}}}}, "validity.channels.current.findings: expected a list"),
    ({"channels": {"current": {"findings": [{"severity": "purple"}]}}}, r"channels.current.findings\[0\].severity"),
    ({"channels": {"current": {"findings": [{"severity": "red", "value": "x"}]}}}, r"findings\[0\].value"),
    ({"peak_displacement_m": "1 mm"}, "validity.peak_displacement_m"),
    ({"note": "x", "notes": "y"}, "validity.notes: expected a list"),
])
def test_a_validity_that_cannot_be_read_says_which_key(doc, key):
    with pytest.raises(ResultValidityError, match=key) as err:
        ResultValidity.from_json(doc)
    assert "\n" not in str(err.value)


def test_it_is_frozen_and_keyword_only():
    v = ResultValidity.from_json(RECORDING)
    with pytest.raises(dataclasses.FrozenInstanceError):
        v.overall = "green"
    with pytest.raises(TypeError):
        v.fit_error_percent["impedance"] = 1.0
    with pytest.raises(TypeError):
        v.fit_band_hz["impedance"][0] = 1.0
    with pytest.raises(TypeError):
        ResultValidity("green")
    v.as_json()["fit_error_percent"]["impedance"] = 99.0          # its JSON is the caller's own copy
    assert v.fit_error_percent["impedance"] == 0.8


@pytest.mark.parametrize("fault", [faults.current_disconnected, faults.clean])
def test_an_analysis_validity_survives_the_archive_s_round_trip(fault):
    validity = analyze_recording(fault()).validity
    doc = json.loads(json.dumps(validity.as_json()))
    assert ResultValidity.from_json(doc) == validity.replace(channels={
        name: dataclasses.replace(ch, measures={}) for name, ch in validity.channels.items()})
    assert ResultValidity.from_json(doc).as_json() == doc


def test_a_result_with_its_validity_can_still_be_pickled_and_copied():
    result = analyze_recording(faults.clean())
    again = pickle.loads(pickle.dumps(result))
    assert again.validity == result.validity and again.validity.channels["current"].measures["snr_db"] > 0
    assert copy.deepcopy(ResultValidity.from_json(CURVES)) == ResultValidity.from_json(CURVES)
    assert pickle.loads(pickle.dumps(ResultValidity.from_json(NOT_A_DRIVER))).as_json() == NOT_A_DRIVER


# A validity read by string key (`validity.get("overall")`, `result.validity["channels"]`): the typed fields instead.
STRING_KEY_READ = re.compile(r"validity(\s*or\s*\{\}\))?\s*(\.get\(|\[(?!u\]))")


def test_no_product_code_reads_a_validity_by_string_key():
    found = []
    for package in ("analysis", "app", "instruments"):
        for path in sorted((ROOT / package).rglob("*.py")):
            for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                if STRING_KEY_READ.search(line) and "population.validity" not in line:
                    found.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert not found, "\n".join(found)
