"""Effects of the user's own on the command line: analyze, diagnose, effects, report and the archive with them."""
import json

import pytest

from analysis.effects import parse_effects
from analysis.effects.user import load_effect_file
from analysis.model.composed import Model
from analysis.multitone import design_multitone
from analysis.recording.format import write_recording
from analysis.synthesis import synthesize_recording
from app.cli import main
from tests.analysis.effects.test_user_effects import BAD_FILES, EXAMPLE
from tests.builders import PAPER, TYPICAL_NOISE


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def rms_recording(tmp_path_factory):
    """The paper's driver with Rms(f) = Rms * sqrt(f / fs) (the example file with r = Rms), realistic noise."""
    truth = dict(PAPER.parameters)
    truth["r"] = truth["Bl"] ** 2 / truth["RES"]
    model = Model(parse_effects("lr2,creep-log") + (load_effect_file(EXAMPLE),))
    mt = design_multitone(48000, 16384, 5.0, 10000.0, rms=1.0)
    rec = synthesize_recording(model, truth, mt.waveform, mt.excited_bins, 48000, 8, 1, TYPICAL_NOISE, seed=31,
                               driver={"name": "synthetic", "sd_m2": 0.0133})
    path = tmp_path_factory.mktemp("rms") / "rms"
    write_recording(path, rec)
    return path, truth


def _mechanical(p):
    return {"RE": p["RE"]["value"], "Bl": p["Bl"]["value"], "Mms": p["Mms"]["value"], "Kms": p["Kms"]["value"]}


def test_analyze_with_the_users_effect_reaches_the_noise_and_the_truth(capsys, rms_recording):
    path, truth = rms_recording
    code, out, err = run(capsys, "analyze", path, "--effects-file", EXAMPLE, "--model", "lr2,creep-log,rms-sqrt-f",
                         "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["model"]["effects"] == ["lr2", "creep-log", "rms-sqrt-f"]
    for channel, chi2_red in doc["model"]["chi2_red"].items():
        assert chi2_red <= 1.5, channel
    true = {"RE": truth["RE"], "Bl": truth["Bl"], "Mms": truth["CMES"] * truth["Bl"] ** 2,
            "Kms": truth["Bl"] ** 2 / truth["LCES"]}
    for name, value in _mechanical(doc["parameters"]).items():
        assert value == pytest.approx(true[name], rel=5e-3), name
    assert doc["parameters"]["r"]["unit"] == "kg/s"


def test_diagnose_ranks_the_users_effect_first_and_explains_the_recording(capsys, rms_recording):
    path, _ = rms_recording
    code, out, err = run(capsys, "diagnose", path, "--effects-file", EXAMPLE, "--from", "lr2,creep-log", "--json")
    assert code == 0, err
    doc = json.loads(out)
    first = doc["candidates"][0]
    assert first["effect"] == "rms-sqrt-f" and first["site"] == "mechanical" and first["accepted"]
    assert doc["verdict"] == "explained"
    assert doc["final"]["effects"] == ["lr2", "creep-log", "rms-sqrt-f"]
    assert all(v <= 2 for v in doc["final"]["chi2_red"].values())
    # The verdict credits the user's effect, not "no effect of the catalogue has anything to explain".
    assert "rms-sqrt-f is an effect of your own" in doc["verdict_text"]
    assert "of the catalogue" not in doc["verdict_text"]


def test_without_the_file_the_effect_is_unknown_and_the_message_says_how(capsys, rms_recording):
    path, _ = rms_recording
    code, _, err = run(capsys, "analyze", path, "--model", "lr2,creep-log,rms-sqrt-f")
    assert code == 2
    assert err.count("\n") == 1 and "unknown effect 'rms-sqrt-f'" in err and "--effects-file" in err


@pytest.mark.parametrize("case", sorted(BAD_FILES))
@pytest.mark.parametrize("command", ["analyze", "diagnose", "effects", "report"])
def test_each_bad_file_exits_2_with_one_line(capsys, tmp_path, rms_recording, command, case):
    text, words = BAD_FILES[case]
    bad = tmp_path / "bad.toml"
    bad.write_text(text, encoding="utf-8")
    path, _ = rms_recording
    args = {"analyze": ["analyze", path], "diagnose": ["diagnose", path], "effects": ["effects"],
            "report": ["report", path, "--html", tmp_path / "r.html"]}[command]
    code, out, err = run(capsys, *args, "--effects-file", bad)
    assert code == 2
    assert err.startswith(f"linpar: error: {bad}: ") and err.count("\n") == 1, err
    assert words in err
    assert "Traceback" not in err and not (tmp_path / "r.html").exists()
    assert "none: write a TOML file there" not in out         # the file is there: the error says what is wrong


def test_a_bad_file_in_the_user_folder_is_named_too(capsys, tmp_path, monkeypatch):
    monkeypatch.setenv("LINPAR_EFFECTS", str(tmp_path))
    (tmp_path / "broken.toml").write_text(BAD_FILES["unknown site"][0], encoding="utf-8")
    code, _, err = run(capsys, "effects")
    assert code == 2 and f"{tmp_path / 'broken.toml'}: site: unknown site" in err


def test_effects_lists_the_users_effects_with_their_file(capsys, tmp_path, monkeypatch):
    monkeypatch.setenv("LINPAR_EFFECTS", str(tmp_path))
    (tmp_path / "rms.toml").write_text(EXAMPLE.read_text(encoding="utf-8"), encoding="utf-8")
    code, out, _ = run(capsys, "effects")
    assert code == 0
    mine = out[out.index("[effects of your own]"):]
    assert "rms-sqrt-f" in mine and f"from: {tmp_path / 'rms.toml'}" in mine and "r * (sqrt(w / ws) - 1)" in mine
    code, out, _ = run(capsys, "effects", "--json")
    entry = next(e for e in json.loads(out) if e["id"] == "rms-sqrt-f")
    assert entry["user"] and entry["file"] == str(tmp_path / "rms.toml") and entry["site"] == "mechanical"


def test_an_archived_result_keeps_the_effect_file_and_reports_without_it(capsys, tmp_path, rms_recording):
    path, _ = rms_recording
    own = tmp_path / "rms.toml"
    own.write_text(EXAMPLE.read_text(encoding="utf-8"), encoding="utf-8")
    root = tmp_path / "archive"
    code, out, err = run(capsys, "archive", "store", path, "--root", root, "--model", "lr2,creep-log,rms-sqrt-f",
                         "--effects-file", own, "--json")
    assert code == 0, err
    mid = json.loads(out)["id"]
    own.unlink()           # the file is gone (or changed): the stored text still rebuilds the model
    code, out, err = run(capsys, "report", mid, "--root", root, "--html", tmp_path / "r.html")
    assert code == 0, err
    html = (tmp_path / "r.html").read_text(encoding="utf-8")
    assert "rms-sqrt-f" in html and "r * (sqrt(w / ws) - 1)" in html and "mechanical" in html


# An effect file whose term vanishes at r = 1 but that the fit runs to its bound (log turns complex below 0).
STUCK = """id = "log-root"
title = "a term that vanishes at r = 1"
site = "electrical"
formula = "0.001 * log(r) * sqrt(f)"
physics = "none: a test of a fit worse than leaving the effect out"
[parameters.r]
unit = "-"
start = 1.5
min = -5
max = 5
"""


def test_analyze_says_when_an_added_effect_is_stuck_on_its_bound_far_from_the_data(capsys, tmp_path):
    from tests.builders import recording
    write_recording(tmp_path / "paper", recording(noise=TYPICAL_NOISE, n_periods=8, seed=3))
    (tmp_path / "log-root.toml").write_text(STUCK, encoding="utf-8")
    args = ("analyze", tmp_path / "paper", "--effects-file", tmp_path / "log-root.toml", "--model",
            "lr2,creep-log,log-root")
    code, out, err = run(capsys, *args)
    assert code == 0, err
    said = [line for line in out.splitlines() if line.startswith("warning: the added effect log-root")]
    assert len(said) == 1 and "r = -5" in said[0] and "--model lr2,creep-log" in said[0]
    code, out, err = run(capsys, *args, "--json")
    doc = json.loads(out)
    assert max(doc["model"]["chi2_red"].values()) > 100
    assert len(doc["model"]["notes"]) == 1 and "log-root" in doc["model"]["notes"][0]
