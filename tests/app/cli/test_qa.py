"""`linpar qa stats|limits|golden|export` on a folder archive: what they print, what they write, and every bad
input one line with exit 2."""
import csv
import json

import numpy as np
import pytest

from analysis.archive import Archive
from app.cli import main
from tests.production_helpers import LIMITS, small_measurement, unit


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def line(tmp_path_factory):
    """A folder archive: limits v1, then 120 units from stations QA1 and QA2; fs drifts up 2 sigma at unit 80."""
    folder = tmp_path_factory.mktemp("line")
    path, doc = small_measurement(folder)
    archive = Archive(folder / "archive")
    archive.store_limits(LIMITS, note="first article")
    rng = np.random.default_rng(5)
    ids = []
    for i in range(120):
        fs = 70.0 + 0.5 * rng.standard_normal() + (1.0 if i >= 80 else 0.0)
        ids.append(archive.store(path, unit(doc, fs=fs, RE=3.0 + 0.02 * rng.standard_normal()),
                                 {"serial": f"SN{i:03d}", "station": f"QA{i % 2 + 1}", "driver": "W6",
                                  "measured_at": f"2024-05-0{1 + i // 60}T{i % 60 // 6:02d}:{i % 6 * 10:02d}:00Z"}))
    return folder / "archive", ids, path, doc


def test_stats_text_and_json(capsys, line):
    root, ids, _, _ = line
    code, out, err = run(capsys, "qa", "stats", "--root", root, "--parameter", "fs", "--parameter", "RE")
    assert code == 0, err
    assert "120 measurement(s)" in out and "Limits: version 1, 6-inch woofer" in out
    assert "120 pass; first-pass yield 100.0 %" in out
    row = next(line for line in out.splitlines() if line.startswith("fs "))
    assert "70 ± 6 Hz" in row and row.split()[2] == "120"
    assert "Control-chart alarms" in out and "fs: WE" in out
    code, out, err = run(capsys, "qa", "stats", "--root", root, "--parameter", "fs", "--json", "--station", "QA2",
                         "--since", "2024-05-01T03:00:00+01:00")
    doc = json.loads(out)
    (fs,) = doc["parameters"]
    assert doc["measurements"] == fs["n"] == len([i for i in range(120) if i % 2 and i // 6 % 10 >= 2 or
                                                   i % 2 and i >= 60])
    assert fs["parameter"] == "fs" and fs["unit"] == "Hz" and fs["lsl"] == 64.0 and fs["usl"] == 76.0
    first = min(a["first"] for a in fs["control_chart"]["alarms"] if a["rule"] != "MR")
    alarm = next(a for a in fs["control_chart"]["alarms"] if a["first"] == first)
    assert alarm["measurements"] and all(m in ids for m in alarm["measurements"])


def test_the_indices_are_estimates_with_their_intervals_and_no_verdict_below_25_units(capsys, line):
    root, _, _, _ = line
    code, out, err = run(capsys, "qa", "stats", "--root", root, "--parameter", "RE", "--until", "2024-05-01T00:30:00Z")
    assert code == 0, err
    assert "4 measurement(s)" in out
    assert "only 4 units: a capability index needs at least 25" in out
    (row,) = [line for line in out.splitlines() if line.startswith("RE ") and "95 % intervals" in line]
    assert "Cpk " in row and " .. " in row
    code, out, err = run(capsys, "qa", "stats", "--root", root, "--parameter", "RE", "--until", "2024-05-01T00:30:00Z",
                         "--json")
    (re_,) = json.loads(out)["parameters"]
    low, high = re_["intervals_95"]["cpk"]
    assert low < re_["cpk"] < high and high - low > 0.5 * re_["cpk"]     # 4 units say little
    assert re_["too_few"].startswith("only 4 units")
    code, out, err = run(capsys, "qa", "stats", "--root", root, "--parameter", "RE", "--json")
    (re_,) = json.loads(out)["parameters"]
    assert re_["too_few"] is None and re_["n"] == 120


def test_limits_versions_from_golden_units_to_a_new_version(capsys, line, tmp_path):
    root, ids, _, _ = line
    code, out, err = run(capsys, "qa", "golden", "--root", root, "--add", *ids[:12], "--json")
    assert code == 0 and json.loads(out)["golden"] == ids[:12]
    proposal = tmp_path / "proposal.json"
    code, out, err = run(capsys, "qa", "limits", "--root", root, "--from-golden", "--k", "3", "--out", proposal)
    assert code == 0, err
    assert "Limits proposed from golden units" in out and f"written: {proposal}" in out
    doc = json.loads(proposal.read_text())
    fs = np.array([e.parameters["fs"]["value"] for e in Archive(root).list() if e.id in ids[:12]])
    assert doc["parameters"]["fs"]["min"] == pytest.approx(fs.mean() - 3 * fs.std(ddof=1), abs=1e-4)
    code, out, err = run(capsys, "qa", "limits", "--root", root, "--store", proposal, "--note", "from golden")
    assert code == 0 and "as limits version 2" in out
    code, out, err = run(capsys, "qa", "limits", "--root", root, "--json")
    assert [(v["version"], v["note"]) for v in json.loads(out)] == [(1, "first article"), (2, "from golden")]
    code, out, err = run(capsys, "qa", "limits", "--root", root, "--show", "1")
    assert json.loads(out) == LIMITS
    code, out, err = run(capsys, "qa", "stats", "--root", root, "--limits-version", "1", "--json")
    assert json.loads(out)["limits"]["version"] == 1


def test_export_csv_json_dfq(capsys, line, tmp_path):
    root, ids, _, _ = line
    code, out, err = run(capsys, "qa", "export", "--root", root, "--station", "QA1", "--csv", tmp_path / "p.csv",
                         "--json", tmp_path / "p.json", "--dfq", tmp_path / "p.dfq")
    assert code == 0, err
    assert out.count("written: ") == 3 and "60 measurement(s)" in err
    rows = list(csv.DictReader(line for line in (tmp_path / "p.csv").open() if not line.startswith("#")))
    assert len({r["id"] for r in rows}) == 60 and {r["station"] for r in rows} == {"QA1"}
    assert len(json.loads((tmp_path / "p.json").read_text())["measurements"]) == 60
    from analysis.production.aqdef import read_dfq
    assert len(read_dfq((tmp_path / "p.dfq").read_bytes()).values) == 60


@pytest.mark.parametrize("argv, message", [
    (["qa", "stats", "--since", "yesterday"], "--since: 'yesterday' is not a date"),
    (["qa", "stats", "--baseline", "3"], "found 3, expected a control-chart baseline"),
    (["qa", "stats", "--limits-version", "9"], "no limits version 9"),
    (["qa", "stats", "--parameter", "Zz"], "Zz: not a parameter the archive keeps"),
    (["qa", "limits", "--from-golden", "--k", "0"], "expected a coverage factor k"),
    (["qa", "limits", "--from-golden", "../x"], "not a measurement id"),
    (["qa", "limits", "--store", "/nonexistent/l.json"], "/nonexistent/l.json: missing"),
    (["qa", "golden", "--add", "19990101-000000-abcdef"], "no measurement"),
    (["qa", "export"], "give --csv FILE"),
    (["qa", "export", "--csv", "X", "--dfq", "X"], "same file"),
    (["qa", "stats", "--archive", "mysql://u@h/db"], "unknown kind of archive"),
    (["qa", "stats", "--archive", "postgresql://u@127.0.0.1:1/db?connect_timeout=2"], "cannot reach the server"),
    (["archive", "list", "--archive", "postgresql://u:pw@h:x/db"], "port 'x'"),
    (["archive", "setup", "--root", "ROOT"], "needs no setup"),
    (["measure", "--rig", "soundcard", "--out", "m", "--archive", "mysql://u@h/db"], "unknown kind of archive"),
    (["measure", "--rig", "soundcard", "--out", "m", "--archive", "postgresql://u:pw@h:x/db"], "port 'x'"),
    (["measure", "--rig", "soundcard", "--out", "m", "--archive", " "], "--archive: empty"),
    (["qa", "stats", "--archive", ""], "--archive: empty"),
    (["qa", "stats", "--root", "ROOT", "--archive", "ROOT"], "not allowed with argument"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, line, tmp_path, monkeypatch, argv, message):
    root, *_ = line
    monkeypatch.setenv("LINPAR_ARCHIVE", str(root))
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, *[str(root) if a == "ROOT" else a for a in argv])
    assert code == 2, (out, err)
    assert err.startswith("linpar: error:") and message in err and len(err.strip().splitlines()) == 1, err
    assert "pw" not in err


def test_a_bad_limits_file_is_refused_before_anything_is_stored(capsys, line, tmp_path):
    root, *_ = line
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({**LIMITS, "parameters": {"fs": {"min": 1, "unit": "furlong"}}}, indent=1))
    before = Archive(root).limits_versions()
    code, out, err = run(capsys, "qa", "limits", "--root", root, "--store", bad)
    assert code == 2 and "bad.json: line 5: parameters.fs.unit: found 'furlong'" in err
    assert Archive(root).limits_versions() == before


def test_an_empty_selection_says_so(capsys, line):
    root, *_ = line
    code, out, err = run(capsys, "qa", "stats", "--root", root, "--station", "nowhere")
    assert code == 0 and "0 measurement(s)" in out and "No measurement in this selection." in out
