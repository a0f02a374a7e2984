"""Broken recordings and extreme numbers at the command line: a judged result or one line, never a traceback.

The issue's findings 1-3 and 9: a silent voltage (an unplugged lead) crashed seven commands with a
ZeroDivisionError; a huge Sd overflowed; an all-zero displacement gave NaN for every parameter and invalid
JSON; a recording whose current is a copy of its voltage, and a 4.29 GHz sample rate, were green.
"""
from __future__ import annotations

import json
import math
import struct

import numpy as np
import pytest

from analysis.recording.format import make_recording, write_recording
from app.cli import main
from tests.builders import TYPICAL_NOISE, recording


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "Traceback" not in out
    return code, out, err


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("linpar: error: "), err
    return lines[0]


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    folder = tmp_path_factory.mktemp("broken")
    good = recording(noise=TYPICAL_NOISE, n_periods=4, seed=31)

    def write(name, **change):
        data = {c.signal: good.signal(c.signal) for c in good.channels}
        for key, make in change.items():
            data[key] = make(data)
        rec = make_recording(good.sample_rate, data, good.period_samples, good.settle_periods, good.excited_bins,
                             dict(good.driver))
        write_recording(folder / name, rec)
        return folder / name
    return {"good": write("good"),
            "silent-voltage": write("silent-voltage", voltage=lambda d: np.zeros_like(d["voltage"])),
            "silent-x": write("silent-x", displacement=lambda d: np.zeros_like(d["voltage"])),
            "current-is-voltage": write("current-is-voltage", current=lambda d: d["voltage"].copy()),
            "folder": folder}


def sidecar_with(path, change) -> None:
    doc = json.loads(path.with_suffix(".json").read_text())
    change(doc)
    path.with_suffix(".json").write_text(json.dumps(doc))


COMMANDS = {
    "diagnose": ["diagnose", "REC"],
    "stats": ["stats", "GOOD", "REC"],
    "levels": ["levels", "REC", "GOOD"],
    "export driver file": ["export", "REC", "--driver", "OUT/p.wdr"],
}


def test_a_silent_voltage_is_analysed_as_red_with_its_remedy(capsys, recordings):
    code, out, _ = run(capsys, "analyze", recordings["silent-voltage"], "--json")
    assert code == 0
    doc = json.loads(out)                                  # strict JSON: no NaN, no Infinity
    assert doc["validity"]["overall"] == "red" and doc["model"]["not_fitted"]
    voltage = doc["validity"]["channels"]["voltage"]["findings"][0]
    assert voltage["code"] == "no-signal" and "amplifier" in voltage["remedy"]
    assert all(p["value"] is None and "voltage" in p["reason"] for p in doc["parameters"].values())


@pytest.mark.parametrize("command", list(COMMANDS))
def test_a_silent_voltage_is_one_line_for_every_command_that_needs_a_fit(capsys, recordings, tmp_path, command):
    argv = [str(recordings["silent-voltage"]) if a == "REC" else str(recordings["good"]) if a == "GOOD" else
            a.replace("OUT", str(tmp_path)) for a in COMMANDS[command]]
    code, out, err = run(capsys, *argv)
    assert code == 2, (out, err)
    line = one_line(err)
    assert "silent-voltage.wav" in line and "voltage" in line and "no signal" in line
    assert "check that the amplifier is on" in line


def test_a_silent_voltage_is_reported_exported_and_archived_as_judged(capsys, recordings, tmp_path):
    """Judged, not refused: the report, the parameters' files and the archive keep the broken measurement
    with its red light and why (a driver file or a curve, which need a fit, are one line: above)."""
    limits = tmp_path / "limits.json"
    limits.write_text(json.dumps({"format": "linpar-limits/1", "parameters": {
        "RE": {"min": 0.5, "max": 20.0, "unit": "ohm"}}}))
    code, out, _ = run(capsys, "report", recordings["silent-voltage"], "--html", tmp_path / "r.html",
                       "--limits", limits)
    html = (tmp_path / "r.html").read_text(encoding="utf-8")
    assert code == 0 and "QA: INVALID: measure again — measurement invalid: voltage" in out and "[no-signal]" in out
    assert "the unit itself was not judged" in out
    assert "QA: INVALID: measure again</span> measurement invalid" in html and "<b>no-signal</b>" in html
    assert "check that the amplifier is on" in html
    assert "Nothing was fitted" in html
    code, out, _ = run(capsys, "export", recordings["silent-voltage"], "--csv", tmp_path / "p.csv",
                       "--json", tmp_path / "p.json")
    doc = json.loads((tmp_path / "p.json").read_text(encoding="utf-8"))
    assert code == 0 and doc["validity"] == "red"
    assert doc["parameters"]["RE"]["value"] is None and "no signal" in doc["parameters"]["RE"]["reason"]
    code, out, _ = run(capsys, "archive", "store", recordings["silent-voltage"], "--root", tmp_path / "archive")
    assert code == 0
    code, out, _ = run(capsys, "archive", "list", "--root", tmp_path / "archive")
    assert code == 0 and "red" in out


def test_a_channel_scale_of_5e_324_is_refused_where_it_is_read(capsys, recordings, tmp_path):
    path = tmp_path / "tiny"
    for suffix in (".wav", ".json"):
        path.with_suffix(suffix).write_bytes(recordings["good"].with_suffix(suffix).read_bytes())
    sidecar_with(path, lambda d: d["channels"][0].update(scale=5e-324))
    code, _, err = run(capsys, "analyze", path)
    assert code == 2 and "channels[0].scale of signal 'voltage': found 4.94066e-324" in one_line(err)


@pytest.mark.parametrize("argv_or_sidecar", [["--sd", "1e160"], ["--sd", "inf"], ["--sd", "nan"], ["--sd", "0"],
                                             "sidecar"])
def test_a_huge_sd_is_refused_where_it_enters(capsys, recordings, tmp_path, argv_or_sidecar):
    path = tmp_path / "rec"
    for suffix in (".wav", ".json"):
        path.with_suffix(suffix).write_bytes(recordings["good"].with_suffix(suffix).read_bytes())
    extra = argv_or_sidecar
    if extra == "sidecar":
        sidecar_with(path, lambda d: d["driver"].update(sd_m2=1e300))
        extra = []
    code, out, err = run(capsys, "analyze", path, *extra)
    assert code == 2 and out == ""
    assert "expected an effective radiating area Sd: a number from 0.0001 to 1 m^2" in one_line(err)


@pytest.mark.filterwarnings("error::RuntimeWarning")          # it gave a dozen numpy warnings
def test_an_all_zero_displacement_gives_the_electrical_parameters_and_valid_json(capsys, recordings, tmp_path):
    code, out, err = run(capsys, "analyze", recordings["silent-x"], "--json")
    assert code == 0
    doc = json.loads(out)
    assert math.isfinite(doc["parameters"]["RE"]["value"]) and doc["parameters"]["RE"]["std"] > 0
    assert doc["parameters"]["Bl"]["value"] is None and "laser" in doc["parameters"]["Bl"]["reason"]
    assert doc["validity"]["channels"]["displacement"]["status"] == "red"
    code, out, err = run(capsys, "report", recordings["silent-x"], "--html", tmp_path / "r.html")
    assert code == 0 and (tmp_path / "r.html").is_file()


def test_current_equal_to_voltage_is_never_green_and_never_passes(capsys, recordings, tmp_path):
    limits = tmp_path / "limits.json"
    limits.write_text(json.dumps({"format": "linpar-limits/1", "parameters": {
        "RE": {"min": 0.5, "max": 2.0, "unit": "ohm"}}}))        # Z = 1 ohm "passed" this before
    code, out, _ = run(capsys, "analyze", recordings["current-is-voltage"], "--limits", limits, "--json")
    doc = json.loads(out)
    assert code == 2 and doc["validity"]["overall"] == "red" and doc["limits"]["verdict"] == "invalid"
    current = doc["validity"]["channels"]["current"]["findings"][0]
    assert current["code"] == "channel-copy" and "wiring" in current["remedy"]
    code, out, _ = run(capsys, "analyze", recordings["current-is-voltage"], "--limits", limits)
    assert code == 2 and "QA: INVALID: measure again — measurement invalid: current" in out and "QA: PASS" not in out


def test_a_sample_rate_of_4_29_ghz_is_refused(capsys, recordings, tmp_path):
    path = tmp_path / "fast"
    path.with_suffix(".json").write_bytes(recordings["good"].with_suffix(".json").read_bytes())
    wav = bytearray(recordings["good"].with_suffix(".wav").read_bytes())
    wav[24:28] = struct.pack("<I", 2**32 - 1)           # the 'fmt ' chunk's sample rate
    path.with_suffix(".wav").write_bytes(bytes(wav))
    code, _, err = run(capsys, "analyze", path)
    assert code == 2
    assert "sample rate: found 4294967295, expected a sample rate: a whole number from 1000 to 1e+06 Hz" in \
        one_line(err)


def test_frequencies_near_1e308_in_an_imported_curve_are_refused(capsys, tmp_path):
    """They overflowed (2 pi f is infinite) into an OverflowError traceback."""
    path = tmp_path / "huge.zma"
    path.write_text("10 5 0\n20 6 10\n1e300 7 20\n1e307 8 30\n1.7e308 9 40\n1.79e308 9 40\n")
    code, out, err = run(capsys, "analyze", "--impedance", path, "--json")
    assert code == 2 and out == ""
    assert "huge.zma: line 3: frequency 1e+300: expected a frequency: a number from 0.01 to 1e+06 Hz" in \
        one_line(err)


@pytest.mark.parametrize("command", ["analyze", "report", "diagnose", "stats"])
def test_a_folder_of_recordings_is_named_a_folder_with_what_it_holds(capsys, tmp_path, command):
    """`analyze FOLDER` read it as the stem of FOLDER.wav and said 'FOLDER.json: missing ... next to FOLDER.wav'."""
    write_recording(tmp_path / "rec", recording(noise=TYPICAL_NOISE, n_periods=3, seed=2))
    extra = ("--pdf", tmp_path / "r.pdf") if command == "report" else ()
    code, out, err = run(capsys, command, tmp_path, *extra)
    line = one_line(err)
    assert code == 2 and f"{tmp_path}: a folder, not a recording" in line and "it holds 1 WAV file(s)" in line


def test_diagnose_without_a_path_names_itself_not_analyze(capsys):
    code, out, err = run(capsys, "diagnose")
    assert code == 2 and one_line(err).startswith("linpar: error: diagnose needs a recording path")
