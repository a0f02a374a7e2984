"""The `linpar` command line: output, JSON shape, exit codes, one-line errors."""
import json
import re
import subprocess
import sys

import pytest

from analysis.recording.format import write_recording
from app.cli import main
from tests.builders import PAPER, TYPICAL_NOISE, recording
from tests.pace import paced

PARAMETER_NAMES = "RE LE L2 R2 CMES LCES RES fs Mms Rms Cms Kms Bl lambda Qes Qms Qts Vas".split()


@pytest.fixture(scope="module")
def rec_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("rec") / "paper"
    write_recording(path, recording(noise=TYPICAL_NOISE, n_periods=4, seed=11))
    return path


@pytest.fixture(scope="module")
def z_only_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("rec") / "zonly"
    write_recording(path, recording(noise=TYPICAL_NOISE, n_periods=4, seed=12, displacement=False))
    return path


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_analyze_json_has_every_parameter_in_si_with_its_std(capsys, rec_path):
    code, out, err = run(capsys, "analyze", str(rec_path) + ".wav", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert set(doc) == {"parameters", "model", "validity"}
    for name in PARAMETER_NAMES:
        assert doc["parameters"][name]["value"] is not None, name
        assert doc["parameters"][name]["std"] > 0, name
    assert doc["parameters"]["RE"]["unit"] == "ohm"
    assert doc["parameters"]["Bl"]["value"] == pytest.approx(PAPER.parameters["Bl"], rel=1e-3)
    assert doc["model"]["effects"] == ["lr2", "creep-log"]
    assert set(doc["model"]["chi2_red"]) == {"impedance", "displacement"}
    assert doc["model"]["bic"] > doc["model"]["aic"] > 0
    assert "overall" in doc["validity"]


def test_analyze_table_shows_customary_units(capsys, rec_path):
    code, out, _ = run(capsys, "analyze", str(rec_path), "--model", "lr2,creep-log")
    assert code == 0
    mms_line = next(line for line in out.splitlines() if line.startswith("Mms"))
    assert mms_line.split()[-1] == "g" and float(mms_line.split()[1]) == pytest.approx(11.84, abs=0.05)
    assert "reduced chi^2" in out
    # the fit's own report below (FitResult.report): statistics, sigmas, the strong correlations
    assert "[[Fit statistics]]" in out and "[[Correlations]] (unreported correlations are below 0.5" in out
    assert re.search(r"C\(\w+, \w+\) = [+-]0\.\d{3}", out)


def test_without_displacement_mechanical_parameters_are_null_with_a_reason(capsys, z_only_path):
    code, out, _ = run(capsys, "analyze", str(z_only_path) + ".json", "--json")
    assert code == 0
    doc = json.loads(out)
    for name in ("Bl", "Mms", "Cms"):
        assert doc["parameters"][name]["value"] is None
        assert "displacement" in doc["parameters"][name]["reason"]
    assert doc["parameters"]["Qts"]["value"] is not None
    assert list(doc["model"]["chi2_red"]) == ["impedance"]


def test_textbook_model_on_request(capsys, rec_path):
    code, out, _ = run(capsys, "analyze", str(rec_path), "--model", "none", "--json")
    doc = json.loads(out)
    assert doc["model"]["effects"] == []
    assert "L2" not in doc["parameters"]


@pytest.mark.parametrize("argv, words", [
    (["analyze", "/nonexistent/rec"], "rec"),
    (["analyze"], "path"),
    (["analyze", "REC", "--model", "nonsense"], "nonsense"),
    (["analyze", "REC", "--sd", "-1"], "an effective radiating area Sd"),
    (["frobnicate"], "frobnicate"),
])
def test_bad_use_exits_2_with_one_line(capsys, rec_path, argv, words):
    argv = [str(rec_path) if a == "REC" else a for a in argv]
    code, out, err = run(capsys, *argv)
    assert code == 2
    assert out == ""
    assert len(err.strip().splitlines()) == 1 and words in err and "Traceback" not in err


def test_a_bad_recording_is_refused_with_exit_2(capsys, tmp_path, rec_path):
    (tmp_path / "bad.wav").write_bytes((rec_path.parent / "paper.wav").read_bytes()[:1000])
    (tmp_path / "bad.json").write_text((rec_path.parent / "paper.json").read_text())
    code, _, err = run(capsys, "analyze", str(tmp_path / "bad"))
    assert code == 2 and "bad.wav" in err and len(err.strip().splitlines()) == 1


def test_the_installed_command_runs_as_a_process(rec_path):
    proc = subprocess.run([sys.executable, "-m", "app.cli", "analyze", str(rec_path), "--json"],
                          capture_output=True, text=True, timeout=paced(120))
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["parameters"]["fs"]["value"] == pytest.approx(70.56, rel=1e-3)


def test_diagnose_json_finds_the_missing_creep(capsys, rec_path):
    code, out, err = run(capsys, "diagnose", str(rec_path), "--from", "lr2", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["start"]["effects"] == ["lr2"]
    assert doc["candidates"][0]["category"] == "creep"
    assert doc["candidates"][0]["delta_bic"] < -10
    assert doc["final"]["effects"][:1] == ["lr2"] and any("creep" in e for e in doc["final"]["effects"])
    assert doc["final"]["chi2_red"]["displacement"] < 2
    assert len(doc["steps"]) >= 2
    assert doc["verdict"] == "explained" and doc["step_cap_reached"] is False
    assert doc["final"]["residual"] == [] and isinstance(doc["final"]["flags"], list)
    assert doc["steps"][0]["chosen"] == doc["candidates"][0]["effect"] and doc["candidates"][0]["accepted"]
    assert [s["site"] for s in doc["sites"]] and all(s["delta_bic"] > 0 for s in doc["sites"])


@pytest.fixture(scope="module")
def odd_mechanical_path(tmp_path_factory):
    from tests.odd_physics import odd_recording
    path = tmp_path_factory.mktemp("rec") / "odd-mechanical"
    write_recording(path, odd_recording("mechanical"))
    return path


def test_diagnose_json_says_what_it_cannot_explain_and_where(capsys, odd_mechanical_path):
    code, out, err = run(capsys, "diagnose", str(odd_mechanical_path), "--from", "lr2,creep-log", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["verdict"] == "unexplained" and "mechanical site" in doc["verdict_text"]
    assert doc["final"]["effects"] == ["lr2", "creep-log"] and doc["steps"][0]["chosen"] is None
    first = doc["final"]["residual"][0]
    assert set(first) == {"channel", "f_lo", "f_hi", "kind", "sign", "size_sigma", "share"}
    assert first["size_sigma"] > 100 and 0 < first["share"] <= 1 and first["f_lo"] < first["f_hi"]
    sites = doc["sites"]
    assert sites[0]["site"] == "mechanical" and len(sites) == 6
    assert [s["score"] for s in sites] == sorted(s["score"] for s in sites)      # ranked on both channels (issue 30)
    correction = sites[0]["correction"]
    assert len(correction["f"]) == len(correction["magnitude"]) == len(correction["phase_deg"]) > 50
    assert max(sites[0]["chi2_red"].values()) < 2 < min(doc["final"]["chi2_red"].values())
    flagged = [c for c in doc["candidates"] if c["flags"]]
    assert flagged and all(not c["accepted"] for c in doc["candidates"])
    assert doc["stopped"]["reason"] == "none-acceptable" and doc["steps"][0]["candidates"] == doc["candidates"]
    assert {"code", "parameter", "channel", "message"} <= set(flagged[0]["flags"][0])


def test_diagnose_text_states_the_verdict_and_the_site(capsys, odd_mechanical_path):
    code, out, _ = run(capsys, "diagnose", str(odd_mechanical_path), "--from", "lr2,creep-log")
    assert code == 0
    assert out.splitlines()[0] == "verdict: Unexplained"
    assert "mechanical site" in out and "effect of your own" in out
    assert "site" in out and "delta BIC" in out
    assert "\nstopped: none of the " in out and " taken " not in out


def test_the_effects_catalogue_is_listed(capsys):
    code, out, _ = run(capsys, "effects", "--json")
    ids = {e["id"] for e in json.loads(out)}
    assert {"lr2", "creep-log"} <= ids


def test_analyze_by_the_papers_method(capsys, rec_path):
    assert main(["analyze", str(rec_path), "--method", "paper", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["model"]["method"] == "paper"
    assert doc["parameters"]["Bl"]["value"] == pytest.approx(PAPER.parameters["Bl"], rel=0.01)
    assert "std_model" not in doc["parameters"]["Bl"]          # the model describes the recording: no model part
    assert main(["analyze", str(rec_path)]) == 0
    assert "(joint fit)" in capsys.readouterr().out


def test_analyze_refuses_an_unknown_method(capsys, rec_path):
    assert main(["analyze", str(rec_path), "--method", "magic"]) == 2
    assert "invalid choice: 'magic' (choose from 'joint', 'paper', 'alternating')" in capsys.readouterr().err
