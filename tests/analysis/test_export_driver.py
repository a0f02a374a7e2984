"""The WinISD .wdr driver file, field by field against the format description in analysis/export/winisd.py."""
import configparser
import json
import math
import re

import pytest

from analysis.archive.results import StoredResult, results_document
from analysis.export import winisd
from analysis.export.winisd import DRIVER_FIELDS, LINPAR_FIELDS, wdr_bytes
from analysis.pipeline import analyze_recording
from tests.builders import TYPICAL_NOISE, recording


def _stored(**kw):
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=7, **kw)
    return StoredResult.from_json(json.loads(json.dumps(results_document(analyze_recording(rec), rec))))


@pytest.fixture(scope="module")
def stored():
    return _stored()


def _documented_table() -> dict[str, str]:
    """key -> unit, parsed from the module docstring's table: the description is what the test holds us to."""
    rows = re.findall(r"^\s*\|\s*(\w+)\s*\|\s*([^|]+?)\s*\|", winisd.__doc__, re.MULTILINE)
    return {key: unit for key, unit in rows if key != "key"}


def _parse(data: bytes) -> configparser.ConfigParser:
    cp = configparser.ConfigParser(interpolation=None)
    cp.optionxform = str                  # WinISD's keys are case-sensitive as written
    cp.read_string(data.decode(winisd.ENCODING))
    return cp


def test_every_field_is_documented_and_every_documented_field_is_written(stored):
    data = wdr_bytes(stored, {"driver": "Acme W6", "serial": "SN1", "operator": "ana"})
    cp = _parse(data)
    documented = _documented_table()
    assert set(cp["Driver"]) == set(documented)      # with the laser and Sd every field is known
    code_units = {key: unit for key, _, unit in DRIVER_FIELDS}
    for key, unit in code_units.items():
        assert documented[key].replace("-", "1") == unit.replace("1", "1"), key


def test_values_are_si_numbers_equal_to_the_results(stored):
    cp = _parse(wdr_bytes(stored, {"driver": "Acme W6"}))["Driver"]
    for key, name, _unit in DRIVER_FIELDS:
        assert float(cp[key]) == stored.parameters[name].value, key
    assert float(cp["Le"]) == pytest.approx(0.132e-3, rel=1e-3)          # H, not mH
    assert float(cp["Mms"]) == pytest.approx(11.87e-3, rel=0.01)         # kg, not g
    assert float(cp["Vas"]) == pytest.approx(stored.parameters["Vas"].value) and float(cp["Vas"]) < 1   # m^3
    assert float(cp["Sd"]) == stored.sd_m2
    assert float(cp["Dia"]) == pytest.approx(math.sqrt(4 * stored.sd_m2 / math.pi))
    assert float(cp["EBP"]) == pytest.approx(float(cp["fs"]) / float(cp["Qes"]))
    assert float(cp["no"]) == pytest.approx(stored.parameters["eta0"].value)      # a fraction, not %
    assert cp["Brand"] == "Acme" and cp["Model"] == "Acme W6"
    for key in cp:
        if key not in ("Brand", "Model", "Comment"):
            assert re.fullmatch(r"-?\d+(\.\d+)?(e-?\d+)?", cp[key]), (key, cp[key])   # '.' decimal point


def test_windows_text_crlf_cp1252(stored):
    data = wdr_bytes(stored, {"driver": "Sëas ≠ W\nx=1", "serial": "ß"})
    assert b"\r\n" in data and b"\n" not in data.replace(b"\r\n", b"")
    assert data.decode("cp1252").splitlines()[0] == "[Driver]"
    cp = _parse(data)["Driver"]
    assert cp["Model"] == "Sëas ? W x=1 ß"                 # one line, '?' for what cp1252 lacks


def test_linpar_section_carries_the_model_beyond_thiele_small():
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=8, effects="lr2,creep-log")
    from analysis.effects import parse_effects
    result = analyze_recording(rec, effects=parse_effects("leach,creep-log"))
    stored = StoredResult.from_json(results_document(result, rec))
    cp = _parse(wdr_bytes(stored))
    section = cp["linpar"]
    assert section["Effects"] == "leach,creep-log"
    assert float(section["K"]) == stored.values["K"] and float(section["n"]) == stored.values["n"]
    assert 0 < float(section["n"]) < 1
    assert float(section["lambda"]) == stored.values["lambda"]
    assert "L2" not in section
    assert {k for k, _, _ in LINPAR_FIELDS} >= {"K", "n", "L2", "R2", "lambda"}


def test_what_was_not_measured_is_left_out_not_zero():
    stored = _stored(displacement=False)
    cp = _parse(wdr_bytes(stored))["Driver"]
    for key in ("Bl", "Mms", "Cms", "Rms", "Vas", "no", "SPL", "USPL"):
        assert key not in cp
    for key in ("Re", "Le", "fs", "Qms", "Qes", "Qts", "EBP", "Sd"):
        assert float(cp[key]) > 0
