"""`linpar analyze --impedance/--hx/--uiv`, `linpar addedmass`, `linpar stats`: output, JSON, exit codes."""
import json
from pathlib import Path

import numpy as np
import pytest

from analysis.effects import parse_effects
from analysis.model.composed import Model
from analysis.recording.format import write_recording
from app.cli import main
from tests.builders import PAPER, TYPICAL_NOISE, recording
from tests.builders import REAL_DATA

REAL = REAL_DATA
SEAS = REAL / "seas_l16rnx"
FREQS = np.logspace(np.log10(5.0), np.log10(20e3), 300)


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def curves(tmp_path_factory):
    """The paper driver as a .zma impedance and an Hx file in mm/V, and as a U/I/V CSV."""
    d = tmp_path_factory.mktemp("curves")
    model, p = Model(parse_effects("lr2,creep-log")), PAPER.parameters
    s = 2j * np.pi * FREQS
    z, hx = model.impedance(s, p), model.displacement(s, p)
    (d / "z.zma").write_text("* Data: Impedance (ohms), Phase (degrees)\n" + "".join(
        f"{f:.9e} {abs(v):.12e} {np.degrees(np.angle(v)):.12e}\n" for f, v in zip(FREQS, z)))
    (d / "hx.frd").write_text("".join(f"{f:.9e} {abs(v) * 1e3:.12e} {np.degrees(np.angle(v)):.12e}\n"
                                      for f, v in zip(FREQS, hx)))
    u = np.full(len(FREQS), 0.5 + 0.1j)
    rows = [f"{f!r},{x.real!r},{x.imag!r},{i.real!r},{i.imag!r},{v.real!r},{v.imag!r}"
            for f, x, i, v in zip(FREQS.tolist(), u.tolist(), (u / z).tolist(), (hx * u * s).tolist())]
    (d / "uiv.csv").write_text("# synthetic\nf_Hz,U_re,U_im,I_re,I_im,V_re,V_im\n" + "\n".join(rows) + "\n")
    return d


def test_analyze_imported_curves_json_has_the_recording_shape(capsys, curves):
    code, out, err = run(capsys, "analyze", "--impedance", curves / "z.zma", "--hx", curves / "hx.frd",
                         "--mm-per-volt", "--hx-fmax", "1e5", "--sd", "0.0133", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert set(doc) == {"parameters", "model", "validity"}
    assert doc["parameters"]["Bl"]["value"] == pytest.approx(PAPER.parameters["Bl"], rel=1e-4)
    assert doc["parameters"]["Bl"]["unit"] == "T*m" and doc["parameters"]["Vas"]["value"] > 0
    assert doc["model"]["effects"] == ["lr2", "creep-log"]
    assert doc["validity"]["overall"] == "unknown" and "no per-line noise" in doc["validity"]["note"]


def test_analyze_uiv_prints_a_table_with_the_notes(capsys, curves):
    code, out, err = run(capsys, "analyze", "--uiv", curves / "uiv.csv", "--hx-fmax", "1e5")
    assert code == 0, err
    bl = next(line for line in out.splitlines() if line.startswith("Bl "))
    assert float(bl.split()[1]) == pytest.approx(PAPER.parameters["Bl"], rel=1e-3)
    assert "local scatter" in out and "velocity" in out


def test_analyze_impedance_alone_reports_why_bl_is_missing(capsys, curves):
    code, out, _ = run(capsys, "analyze", "--impedance", curves / "z.zma", "--json")
    doc = json.loads(out)
    assert code == 0 and doc["parameters"]["Bl"]["value"] is None
    assert "added-mass" in doc["parameters"]["Bl"]["reason"]


@pytest.mark.parametrize("argv, words", [
    (["analyze"], "needs a recording path"),
    (["analyze", "x.wav", "--impedance", "z.zma"], "not both"),
    (["analyze", "x.wav", "--fmax", "100"], "--fmax: for imported curves only"),
    (["analyze", "--hx", "hx.frd"], "--hx needs --impedance"),
    (["analyze", "--uiv", "uiv.csv", "--impedance", "z.zma"], "--uiv carries both"),
    (["analyze", "--impedance", "bad.zma"], "bad.zma: line 3: "),
    (["analyze", "--impedance", "z.zma", "--phase", "rad"], "out of range for radians"),
    (["analyze", "--impedance", "z.zma", "--fmin", "100", "--fmax", "101"], "lines between"),
    (["analyze", "--impedance", "z.zma", "--model", "nonsense"], "unknown effect"),
    (["addedmass", "z.zma", "--mass", "-8", "z.zma"], "--mass"),
])
def test_errors_are_one_line_and_exit_2(capsys, curves, argv, words):
    (curves / "bad.zma").write_text("10 7 1\n20 8 2\n30 x 3\n")
    argv = [str(curves / a) if a.endswith((".zma", ".frd", ".csv", ".wav")) else a for a in argv]
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and words in err, err


@pytest.mark.skipif(not SEAS.is_dir(), reason="the real data set is not on this machine")
def test_addedmass_on_the_seas_set(capsys):
    code, out, err = run(capsys, "addedmass", SEAS / "L16RNX_0g_242_27mV.zma",
                         "--mass", "8.017", SEAS / "L16RNX_8_017g_242_27mV.zma",
                         "--mass", "16.048", SEAS / "L16RNX_16_048g_242_27mV.zma", "--sd", "0.0103869", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["method"] == "joint fit of 3 curves" and doc["added_masses_kg"] == [0.008017, 0.016048]
    assert doc["parameters"]["Bl"]["value"] == pytest.approx(7.007, rel=0.01)
    assert doc["parameters"]["Mms"]["value"] == pytest.approx(15.05e-3, rel=0.01)
    methods = [c["method"] for c in doc["cross_checks"]]
    assert methods[0].startswith("model-free") and methods.count("single added mass (classical)") == 2
    assert any(line.startswith("Rms ") and "model-free" in line for line in doc["disagreements"])
    code, out, _ = run(capsys, "addedmass", SEAS / "L16RNX_0g_242_27mV.zma",
                       "--mass", "8.017", SEAS / "L16RNX_8_017g_242_27mV.zma")
    assert code == 0 and "joint fit of 2 curves" in out and "Mms" in out
    assert out.count("The methods disagree:") <= 1


def test_stats_over_repeated_recordings(capsys, tmp_path):
    paths = []
    for seed in range(3):
        path = tmp_path / f"rep{seed}"
        write_recording(path, recording(noise=TYPICAL_NOISE, n_periods=4, seed=seed))
        paths.append(str(path) + ".wav")
    code, out, err = run(capsys, "stats", *paths, "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["n_results"] == 3
    bl = doc["parameters"]["Bl"]
    assert bl["n"] == 3 and bl["mean"] == pytest.approx(PAPER.parameters["Bl"], rel=1e-2) and bl["percent"] < 1
    code, out, _ = run(capsys, "stats", *paths)
    assert code == 0 and "3 results" in out


def test_an_empty_model_option_is_refused_by_every_command_none_is_the_textbook_model(capsys, tmp_path):
    """`--model ""` (an unset shell variable) named the default model in stats, levels, measure and addedmass, and
    silently the textbook model in analyze."""
    path = tmp_path / "rep"
    write_recording(path, recording(noise=TYPICAL_NOISE, n_periods=4, seed=0))
    for command in ("stats", "analyze"):
        for empty in ("", " , "):
            code, out, err = run(capsys, command, str(path) + ".wav", "--model", empty)
            assert code == 2 and "--model: empty" in err and "'none' for the textbook model" in err, (command, err)
    code, out, err = run(capsys, "analyze", str(path) + ".wav", "--json", "--model", "none")
    assert code == 0, err
    assert "lambda" not in json.loads(out)["parameters"]


def test_stats_leave_a_red_recording_out_and_say_so(capsys, tmp_path):
    """A broken measurement (its laser mounted the wrong way round: red) is no repeat: averaged in, its numbers
    read as a spread of tens of percent."""
    paths = []
    for seed, bl_sign in ((0, 1), (1, 1), (2, -1)):
        path = tmp_path / f"rep{seed}"
        values = {**PAPER.parameters, "Bl": bl_sign * PAPER.parameters["Bl"]}
        write_recording(path, recording(values, noise=TYPICAL_NOISE, n_periods=4, seed=seed))
        paths.append(str(path) + ".wav")
    code, out, err = run(capsys, "stats", *paths, "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["n_results"] == 2 and doc["files"] == paths[:2]
    (left_out,) = doc["left_out"]
    assert left_out["file"] == paths[2] and "validity red" in left_out["why"] and "laser-sign" in left_out["why"]
    assert f"{paths[2]} left out: validity red" in err and "measure it again" in err
    bl = doc["parameters"]["Bl"]
    assert bl["n"] == 2 and bl["mean"] == pytest.approx(PAPER.parameters["Bl"], rel=1e-2) and bl["percent"] < 1
    code, out, _ = run(capsys, "stats", *paths)
    assert code == 0 and "2 results" in out and f"left out (red): 1 of 3: {paths[2]}" in out
    code, _, err = run(capsys, "stats", paths[2])
    assert code == 2 and "none of the 1 recordings is valid" in err
