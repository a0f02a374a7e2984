"""`linpar large-signal`: text, the JSON contract, a plan's summary as input, and bad input in one line (exit 2)."""
from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from analysis.recording.format import make_recording, read_recording, write_recording
from analysis.spectra import excited_lines
from app.cli import main
from tests.large_signal_truth import KNOWN_OFFSET_M, known_driver, write_steps


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    folder = tmp_path_factory.mktemp("large-signal")
    return folder, write_steps(folder)


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_json_is_one_object_with_the_contract(recordings, capsys):
    _, paths = recordings
    code, out, err = run(["large-signal", *map(str, paths), "--json", "--predict", "6", "--sine", "40"], capsys)
    assert code == 0, err
    doc = json.loads(out)
    assert doc["x_unit"] == "m"
    for name, unit in (("Bl", "T*m"), ("Kms", "N/m"), ("Le", "H")):
        curve = doc["curves"][name]
        assert curve["unit"] == unit and len(curve["coefficients"]) == len(curve["std"])
        assert curve["x_range"][0] < 0 < curve["x_range"][1]
    assert doc["offset_m"] == pytest.approx(KNOWN_OFFSET_M, abs=1e-4)
    assert doc["limits"]["X_Bl"]["criterion"] == "Bl >= 82 %" and "value" in doc["limits"]["X_C"]
    assert {"electrical", "mechanical", "total"} <= set(doc["model"]["chi2_red"])
    assert len(doc["validity"]["recordings"]) == 2
    assert doc["distortion"]["predictions"][0]["sine"]["current"]["H3_db"] < 0


def test_text_names_the_offset_and_the_limits_and_thresholds_are_settable(recordings, capsys):
    _, paths = recordings
    code, out, _ = run(["large-signal", str(paths[1]), "--bl-min", "90", "--cms-min", "80"], capsys)
    assert code == 0
    assert "move the coil 1.50 mm in" in out
    assert "X_Bl (Bl >= 90 %): 2.00 mm" in out and "X_C (Cms >= 80 %)" in out


def test_a_plans_summary_stands_for_its_complete_steps(recordings, capsys):
    folder, paths = recordings
    summary = folder / "plan.large-signal.json"
    summary.write_text(json.dumps({"steps": [{"recording": paths[0].name, "partial": False},
                                             {"recording": paths[1].name, "partial": False},
                                             {"recording": "broken.wav", "partial": True}]}))
    code, out, err = run(["large-signal", str(summary), "--json"], capsys)
    assert code == 0, err
    assert [r["source"] for r in json.loads(out)["validity"]["recordings"]] == [p.name for p in paths]


def test_the_report_and_the_curves_are_written_and_never_over_an_input(recordings, capsys, tmp_path):
    _, paths = recordings
    files = {o: tmp_path / f"out.{o.split('-')[-1]}" for o in ("pdf", "html", "csv")}
    files["export-json"] = tmp_path / "curves.json"
    code, out, err = run(["large-signal", str(paths[1])] + [a for o, p in files.items() for a in (f"--{o}", str(p))],
                         capsys)
    assert code == 0, err
    assert all(p.stat().st_size > 1000 for p in files.values())
    assert json.loads(files["export-json"].read_text())["x_unit"] == "m"
    assert files["csv"].read_text().count("\n") > 100
    sidecar = paths[1].with_suffix(".json")
    before = sidecar.read_bytes()
    code, _, err = run(["large-signal", str(paths[1]), "--csv", str(sidecar)], capsys)
    assert code == 2 and "an input of this command" in err and sidecar.read_bytes() == before


def test_a_sidecar_without_its_lines_gives_the_same_curves_from_the_lines_found(recordings, capsys, tmp_path):
    """The format's minimal sidecar lists no excitation.excited_bins: the lines are found in the voltage spectrum
    (analysis.spectra, as for the linear analysis), and the identification is the one with the lines listed."""
    _, paths = recordings
    listed = paths[1]
    sidecar = json.loads(listed.with_suffix(".json").read_text())
    bins = sidecar["excitation"].pop("excited_bins")
    minimal = tmp_path / listed.name
    shutil.copyfile(listed, minimal)
    minimal.with_suffix(".json").write_text(json.dumps(sidecar))
    assert excited_lines(read_recording(minimal)).tolist() == sorted(bins)
    docs = []
    for path in (listed, minimal):
        code, out, err = run(["large-signal", str(path), "--json"], capsys)
        assert code == 0, err
        docs.append(json.loads(out))
    with_lines, found = docs
    assert found["offset_m"] == with_lines["offset_m"] == pytest.approx(KNOWN_OFFSET_M, abs=1e-4)
    for name in ("Bl", "Kms", "Le"):
        assert found["curves"][name] == with_lines["curves"][name], name
    bl0 = np.polynomial.polynomial.polyval(0.0, found["curves"]["Bl"]["coefficients"])
    assert bl0 == pytest.approx(known_driver(8192).values["Bl"], rel=0.01)
    assert found["validity"]["verdict"] == with_lines["validity"]["verdict"]


def test_bad_input_is_one_line_and_exit_2(recordings, capsys, tmp_path):
    _, paths = recordings
    good = str(paths[1])
    rec = make_recording(48000, {"voltage": np.ones(8192 * 3), "current": np.ones(8192 * 3)}, 8192, 1, (3, 5))
    no_laser = write_recording(tmp_path / "no-laser", rec)[0]
    (tmp_path / "empty.large-signal.json").write_text('{"steps": []}')
    cases = [
        (["large-signal", str(tmp_path / "missing")], "missing"),
        (["large-signal", str(no_laser)], "no displacement"),
        (["large-signal", good, "--order", "12"], "polynomial order"),
        (["large-signal", good, "--bl-min", "nan"], "limit's threshold"),
        (["large-signal", good, "--le-change", "150"], "limit's threshold"),
        (["large-signal", good, "--sine", "40"], "--predict"),
        (["large-signal", good, "--predict", "6", "--two-tones", "500,30"], "F1 < F2"),
        (["large-signal", good, "--predict", "inf"], "drive level"),
        (["large-signal", good, "--predict", "6", "--sine", "1e6"], "audio frequency"),
        (["large-signal", str(tmp_path / "empty.large-signal.json")], "no complete step"),
        (["large-signal", good, "--pdf", str(tmp_path)], "not a regular file"),
        (["large-signal", good, "--html", "/dev/null"], "not a regular file"),
        (["measure", "--out", str(tmp_path), "--plan", "large-signal", "--max-excursion", "-1"], "peak excursion"),
        (["measure", "--out", str(tmp_path), "--plan", "large-signal", "--step", "9"], "level factor"),
        # refused before any rig starts: a limit the single plan would ignore, a start above the top, a file as --out
        (["measure", "--out", str(tmp_path), "--max-excursion", "3"], "add --plan large-signal"),
        (["measure", "--out", str(tmp_path), "--plan", "large-signal", "--level", "20"], "--max-voltage 10 V"),
        (["measure", "--out", str(tmp_path / "empty.large-signal.json"), "--plan", "large-signal"], "not a folder"),
    ]
    for argv, words in cases:
        code, out, err = run(argv, capsys)
        assert code == 2, argv
        assert err.count("\n") == 1 and words in err, (argv, err)
        assert "Traceback" not in err
