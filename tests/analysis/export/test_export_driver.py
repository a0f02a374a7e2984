"""The WinISD .wdr driver file, field by field against real WinISD files.

The format description below is taken from public files, not from our writer:

- KEYS: the key list, in order, of drivers/sample/john-all-noncalc-fields-manually-entered.wdr
  (written by WinISD 0.7.0.950 itself after every field was typed) and of "drivers/B&C 12PS100.wdr"
  (a driver-database file for WinISD): the same 56 keys, in the same order, in both. Repository
  github.com/Johnlon/openisd.
- UNITS: the unit each key has in the file, from the same repository's
  docs/research/UNIT_BOUNDARY_AUDIT.md section 3 and docs/design/WINISD_SCHEMA.md section 3
  (checked there against WinISD's own display, e.g. Le shown in H, Mms in kg, Vas stored in m^3).
- PARSTATE: the 49 ParState slots, from drivers/sample/README.md ("Confirmed ParState position map",
  one probe file per slot).
- Number spellings: two values as WinISD wrote them in the first file above.
Only key names, units and slot order are kept here, no one's driver data.
"""
import json
import math
import re

import numpy as np
import pytest

from analysis.archive.results import StoredResult, results_document
from analysis.derived import ParameterValue
from analysis.export import winisd
from analysis.export.winisd import wdr_bytes
from analysis.pipeline import analyze_recording
from analysis.validity.result import ResultValidity
from tests.builders import TYPICAL_NOISE, recording

KEYS = ("Brand Model Manufacturer ProvidedBy Comment DateAdded DateModified Qts Znom Fs Pe SPL Re Le fLe KLe "
        "BL Xmax Cms Qms Qes Rms Mms Sd Vas Dia Vd no Dd EBP numVC Hc Hg SPLmax SPLmaxLF USPL alfaVC Rt Ct "
        "gamma Rme Mpow Mcost Gloss VCCon c roo Thick Depth MagDepth Magnet Basket Outer Vcd DVol ParState").split()
UNITS = {"Qts": "1", "Znom": "ohm", "Fs": "Hz", "Pe": "W", "SPL": "dB", "Re": "ohm", "Le": "H", "fLe": "Hz",
         "KLe": "H*Hz^0.5", "BL": "T*m", "Xmax": "m", "Cms": "m/N", "Qms": "1", "Qes": "1", "Rms": "kg/s",
         "Mms": "kg", "Sd": "m^2", "Vas": "m^3", "Dia": "m", "Vd": "m^3", "no": "1", "Dd": "m", "EBP": "Hz",
         "USPL": "dB", "c": "m/s", "roo": "kg/m^3"}
PARSTATE = ("Znom Fs Pe SPL Re Le fLe KLe BL Xmax Xlim Cms Qms Qes Qts Rms Mms Sd Vd Vas Dia Dd no numVC Hc Hg "
            "SPLmax SPLmaxLF USPL alfaVC Rt Ct gamma EBP Rme Mpow Mcost Gloss Thick Depth MagDepth Magnet "
            "Basket Outer Vcd DVol VCCon c roo").split()
WINISD_SPELLINGS = {8.81202645607949e-06: "8.81202645607949E-6", 1.59790990485196e-05: "0.0000159790990485196"}

# Every unit of the file is SI (UNITS): a value read back must equal the SI value written. The guard
# against a customary unit slipping in (mH, g, litres) is the explicit checks of Le, Mms and Vas below.
TO_SI = {unit: 1.0 for unit in ("1", "ohm", "Hz", "H", "kg", "m^3", "m^2", "m", "m/N", "kg/s", "T*m", "dB",
                                "H*Hz^0.5", "m/s", "kg/m^3", "W")}
# WinISD key -> linpar parameter: what the measurement states (E) and what are WinISD formulas of it (C).
STATED = {"Fs": "fs", "Re": "RE", "BL": "Bl", "Cms": "Cms", "Qms": "Qms", "Qes": "Qes", "Rms": "Rms",
          "Mms": "Mms", "Vas": "Vas"}
FORMULAS = {"Qts": "Qts", "no": "eta0", "SPL": "SPL_1W_1m", "USPL": "SPL_2.83V_1m"}
NUMBER = re.compile(r"-?\d+(\.\d+)?(E-?\d+)?")


def _stored(**kw):
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=7, **kw)
    return StoredResult.from_json(json.loads(json.dumps(results_document(analyze_recording(rec), rec))))


@pytest.fixture(scope="module")
def stored():
    return _stored()


def _lines(data: bytes) -> list[str]:
    return data.decode("utf-8").split("\r\n")


def _fields(data: bytes) -> dict[str, str]:
    return dict(line.split("=", 1) for line in _lines(data)[1:] if line)


def _marks(fields: dict[str, str]) -> dict[str, str]:
    return dict(zip(PARSTATE, fields["ParState"]))


def _known(values: dict[str, tuple[float, str]], sd_m2: float, model: dict[str, float]) -> StoredResult:
    """A result with chosen SI values and the textbook model (RE + s LE)."""
    params = {n: ParameterValue(name=n, value=v, std=None, unit=u, display_unit=u, display_scale=1.0)
              for n, (v, u) in values.items()}
    return StoredResult(parameters=params, effects=(), with_displacement=True, values=model, model_info={},
                        validity=ResultValidity(overall="ok"), sd_m2=sd_m2, settings={})


KNOWN = {"RE": (6.4, "ohm"), "LE": (0.8e-3, "H"), "fs": (38.0, "Hz"), "Qms": (6.2, "1"), "Qes": (0.38, "1"),
         "Qts": (0.358, "1"), "Bl": (8.5, "T*m"), "Mms": (0.025, "kg"), "Cms": (7.0e-4, "m/N"),
         "Rms": (0.8, "kg/s"), "Vas": (0.045, "m^3"), "eta0": (2.5e-3, "1"), "SPL_1W_1m": (86.1, "dB"),
         "SPL_2.83V_1m": (87.0, "dB")}


def test_one_driver_section_with_winisds_keys_in_winisds_order(stored):
    lines = _lines(wdr_bytes(stored, {"driver": "Acme W6", "serial": "SN1", "operator": "ana"}))
    assert lines[0] == "[Driver]" and lines[-1] == ""
    body = lines[1:-1]
    assert not any(line.startswith("[") for line in body)                # no second section
    assert [line.split("=", 1)[0] for line in body] == KEYS              # 56 keys, ParState last
    assert all(re.fullmatch(r"[A-Za-z]+=[^\r\n]*", line) for line in body)   # Key=Value, no spaces
    fields = _fields(wdr_bytes(stored))
    assert "BL" in fields and "Bl" not in fields and "Fs" in fields and "fs" not in fields


def test_known_values_read_back_in_the_documented_units():
    sd = 0.0216
    result = _known(KNOWN, sd, {"RE": 6.4, "LE": 0.8e-3})
    fields = _fields(wdr_bytes(result))
    for key, name in {**STATED, **FORMULAS}.items():
        si = float(fields[key]) * TO_SI[UNITS[key]]
        assert si == KNOWN[name][0], key
    assert float(fields["Le"]) * TO_SI[UNITS["Le"]] == 0.8e-3          # H: 0.0008, not 0.8 (mH)
    assert float(fields["Mms"]) == 0.025 and float(fields["Vas"]) == 0.045 and float(fields["Sd"]) == sd
    assert float(fields["Dd"]) == pytest.approx(2 * math.sqrt(sd / math.pi), rel=1e-15)
    assert float(fields["no"]) == 2.5e-3                                   # a fraction, not %
    # The textbook coil is WinISD's plain Le: the semi-inductance stays off.
    assert fields["fLe"] == "0" and fields["KLe"] == "0"
    assert _marks(fields)["fLe"] == "N" and _marks(fields)["KLe"] == "N"


def test_measured_values_are_the_results(stored):
    fields = _fields(wdr_bytes(stored, {"driver": "Acme W6"}))
    for key, name in {**STATED, **FORMULAS}.items():
        assert float(fields[key]) == stored.parameters[name].value, key
    assert float(fields["Sd"]) == stored.sd_m2
    assert float(fields["EBP"]) == pytest.approx(float(fields["Fs"]) / float(fields["Qes"]), rel=1e-15)


def test_parstate_marks_what_was_measured_calculated_and_not_set(stored):
    fields = _fields(wdr_bytes(stored))
    assert len(fields["ParState"]) == 49 and set(fields["ParState"]) <= set("ECN")
    marks = _marks(fields)
    for key in [*STATED, "Sd", "Le", "fLe", "c", "roo", "numVC"]:
        assert marks[key] == "E", key
    for key in [*FORMULAS, "Dd", "EBP", "KLe"]:
        assert marks[key] == "C", key
    for key in ("Znom", "Pe", "Xmax", "Xlim", "Vd", "Dia", "Hc", "Hg", "SPLmax", "SPLmaxLF", "gamma", "Rme",
                "Mpow", "Mcost", "Gloss", "alfaVC", "Rt", "Ct", "Thick", "DVol", "VCCon"):
        assert marks[key] == "N", key
        if key != "Xlim":
            assert fields[key] == ("1" if key == "VCCon" else "0"), key


def test_winisds_relations_between_fields_hold(stored):
    """WinISD recomputes a field from these relations (WINISD_SCHEMA.md section 4): ours must agree."""
    v = {k: float(x) for k, x in _fields(wdr_bytes(stored)).items() if NUMBER.fullmatch(x)}
    rel = dict(rel=1e-9)
    assert v["Qts"] == pytest.approx(v["Qms"] * v["Qes"] / (v["Qms"] + v["Qes"]), **rel)          # 5
    assert v["Sd"] == pytest.approx(math.pi * v["Dd"] ** 2 / 4, **rel)                            # 6
    assert v["Vas"] == pytest.approx(v["roo"] * v["c"] ** 2 * v["Sd"] ** 2 * v["Cms"], **rel)     # 10
    assert v["Fs"] == pytest.approx(1 / (2 * math.pi * math.sqrt(v["Mms"] * v["Cms"])), **rel)   # 11
    assert v["no"] == pytest.approx(4 * math.pi**2 / v["c"] ** 3 * v["Fs"] ** 3 * v["Vas"] / v["Qes"], **rel)   # 14
    assert v["no"] == pytest.approx(v["roo"] / (2 * math.pi * v["c"]) * v["BL"] ** 2 * v["Sd"] ** 2
                                    / (v["Mms"] ** 2 * v["Re"]), **rel)                          # 15
    assert v["SPL"] == pytest.approx(10 * math.log10(v["roo"] * v["c"] / (2 * math.pi * 20e-6**2) * v["no"]), **rel)
    assert v["USPL"] == pytest.approx(v["SPL"] + 10 * math.log10(8 / v["Re"]), abs=0.01)        # 17: 2.83^2 vs 8
    assert v["KLe"] == pytest.approx(v["Le"] * math.sqrt(2 * math.pi * v["fLe"]), **rel)         # 24


def test_the_lossy_coil_is_written_as_winisds_semi_inductance(stored):
    """Default model (LR-2): Le is the coil's inductance at 1 kHz, and KLe the n = 1/2 semi-inductance."""
    assert "lr2" in stored.effects
    fields = _fields(wdr_bytes(stored))
    p, w = stored.values, 2 * np.pi * 1000.0
    ze = p["RE"] + 1j * w * p["LE"] + 1j * w * p["L2"] * p["R2"] / (p["R2"] + 1j * w * p["L2"])
    assert float(fields["fLe"]) == 1000.0
    assert float(fields["Le"]) == pytest.approx(ze.imag / w, rel=1e-12)
    assert p["LE"] < float(fields["Le"]) < p["LE"] + p["L2"]               # H; part of L2 still acts at 1 kHz
    assert float(fields["KLe"]) == pytest.approx(float(fields["Le"]) * math.sqrt(w), rel=1e-12)


def test_utf8_crlf_one_line_names_and_winisds_number_spelling(stored):
    data = wdr_bytes(stored, {"driver": "Sëas ≠ W\nx=1", "serial": "ß", "measured_at": "2024-05-01T10:00:00Z"})
    assert b"\r\n" in data and b"\n" not in data.replace(b"\r\n", b"")
    fields = _fields(data)
    assert fields["Brand"] == "Sëas" and fields["Model"] == "≠ W x=1 ß"
    assert fields["DateAdded"] == fields["DateModified"] == "20240501"
    for key, unit in UNITS.items():
        assert NUMBER.fullmatch(fields[key]), (key, fields[key])          # '.' decimal, WinISD's 'E'
    for value, spelling in WINISD_SPELLINGS.items():
        assert winisd._number(value) == spelling and float(spelling) == value


def test_what_was_not_measured_is_zero_and_not_set():
    fields = _fields(wdr_bytes(_stored(displacement=False)))
    marks = _marks(fields)
    for key in ("BL", "Mms", "Cms", "Rms", "Vas", "no", "SPL", "USPL"):
        assert fields[key] == "0" and marks[key] == "N", key
    for key in ("Re", "Le", "Fs", "Qms", "Qes", "Qts", "EBP", "Sd", "Dd"):
        assert float(fields[key]) > 0 and marks[key] in "EC", key


def test_the_module_documents_the_same_keys_and_units():
    rows = re.findall(r"^\s*\|\s*(\w+)\s*\|\s*([^|]+?)\s*\|", winisd.__doc__, re.MULTILINE)
    documented = {key: unit for key, unit in rows if key != "key"}
    assert set(documented) <= set(KEYS)
    for key, unit in documented.items():
        if key in UNITS:
            assert unit == UNITS[key], key
    assert [k for k, _ in winisd.DRIVER_KEYS] == KEYS
    assert [s or "Xlim" for s in winisd.PARSTATE_SLOTS] == PARSTATE
