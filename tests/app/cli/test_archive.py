"""`linpar archive`, `linpar report`, `linpar export` and `linpar analyze --limits`: output and exit codes."""
import json

import pytest

from analysis.importers import read_curve
from analysis.recording.format import write_recording
from app.cli import main
from instruments.simulation import faults
from tests.builders import TYPICAL_NOISE, recording


@pytest.fixture(scope="module")
def rec_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("rec") / "paper"
    write_recording(path, recording(noise=TYPICAL_NOISE, n_periods=3, seed=21))
    return path


@pytest.fixture(scope="module")
def red_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("rec") / "red"
    write_recording(path, faults.laser_errors())
    return path


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def root(tmp_path, monkeypatch):
    monkeypatch.setenv("LINPAR_ARCHIVE", str(tmp_path / "archive"))
    return tmp_path / "archive"


def store(capsys, path, *extra):
    code, out, err = run(capsys, "archive", "store", path, "--json", *extra)
    assert code == 0, err
    return json.loads(out)["id"]


def test_store_list_show_rebuild(capsys, root, rec_path):
    mid = store(capsys, rec_path, "--serial", "SN1", "--operator", "ana", "--driver", "W6")
    code, out, err = run(capsys, "archive", "list")
    assert code == 0 and mid in out and "W6" in out and "1 measurement(s)" in out
    code, out, _ = run(capsys, "archive", "list", "--json", "--serial", "nomatch")
    assert json.loads(out) == []
    code, out, _ = run(capsys, "archive", "show", mid[:-2])
    assert code == 0 and "SN1" in out and "recording.wav" in out
    (root / "index.sqlite").write_bytes(b"garbage" * 10)
    code, out, err = run(capsys, "archive", "list", "--json")
    assert [e["id"] for e in json.loads(out)] == [mid] and "index rebuilt" in err
    code, out, _ = run(capsys, "archive", "rebuild", "--json")
    assert json.loads(out) == {"indexed": 1, "skipped": []}


def test_store_says_the_verdict_the_archive_recorded_against_its_limits(capsys, root, rec_path, tmp_path):
    """The archive judges a stored unit against its newest limits; the command that stored it says so (it said
    only "stored ... (validity green)", and the operator never saw a FAIL the line's statistics counted)."""
    code, out, err = run(capsys, "archive", "store", rec_path)
    assert code == 0 and "QA:" not in out                     # no limits stored yet: nothing judged it
    limits = tmp_path / "limits.json"
    limits.write_text(json.dumps({"format": "linpar-limits/1", "name": "tight RE", "parameters": {
        "RE": {"nominal": 3.3, "tolerance": "1%", "unit": "ohm"}}}))
    code, out, err = run(capsys, "qa", "limits", "--store", limits)
    assert code == 0, err
    code, out, err = run(capsys, "archive", "store", rec_path, "--json")
    assert code == 0 and json.loads(out)["qa"] == {"verdict": "fail", "limits_version": 1}
    code, out, err = run(capsys, "archive", "store", rec_path)
    assert code == 0 and "QA: FAIL (the archive's limits, version 1: tight RE)" in out
    (re_line,) = [line for line in out.splitlines() if line.lstrip().startswith("RE")]
    assert "FAIL" in re_line


def test_root_option_overrides_the_environment(capsys, root, rec_path, tmp_path):
    other = tmp_path / "other"
    code, out, err = run(capsys, "archive", "store", rec_path, "--root", other)
    assert code == 0, err
    code, out, _ = run(capsys, "archive", "list", "--root", other, "--json")
    assert len(json.loads(out)) == 1
    assert not root.exists()


def test_export_folder_and_bad_ids(capsys, root, rec_path, tmp_path):
    mid = store(capsys, rec_path)
    code, out, _ = run(capsys, "archive", "export", mid, tmp_path / "out")
    assert code == 0 and (tmp_path / "out").is_dir()
    for bad in ("../../etc", "/etc/passwd", "nothing-like-an-id"):
        code, out, err = run(capsys, "archive", "show", bad)
        assert code == 2 and err.startswith("linpar: error:") and err.count("\n") == 1


def test_compare(capsys, root, rec_path):
    ids = [store(capsys, rec_path, "--serial", f"S{i}") for i in range(2)]
    code, out, _ = run(capsys, "archive", "compare", *ids, "--json")
    doc = json.loads(out)
    assert code == 0 and doc["ids"] == ids and any(r["name"] == "Qts" for r in doc["rows"])


def test_compare_heads_each_column_so_that_two_of_one_driver_are_told_apart(capsys, root, rec_path):
    ids = [store(capsys, rec_path, "--driver", "Paper driver") for _ in range(2)]      # no serial: alike
    code, out, err = run(capsys, "archive", "compare", *ids)
    assert code == 0, err
    lines = out.splitlines()
    # The legend first: each column's number with its id and date, then the table headed by the numbers.
    for number, mid in enumerate(ids, 1):
        said = lines[number - 1]
        assert said.startswith(f"{number}. {mid}  measured 20") and " UTC  Paper driver" in said
    header = next(line for line in lines if line.startswith("parameter"))
    assert "1. Paper driver" in header and "2. Paper driver" in header
    code, out, _ = run(capsys, "archive", "compare", *ids, "--json")
    doc = json.loads(out)
    assert len(doc["measured_at"]) == 2 and all(when.endswith("Z") for when in doc["measured_at"])


def test_report_from_path_and_id(capsys, root, rec_path, tmp_path):
    code, out, err = run(capsys, "report", rec_path, "--html", tmp_path / "a.html")
    assert code == 0, err
    assert "<svg" in (tmp_path / "a.html").read_text()
    mid = store(capsys, rec_path, "--serial", "SN9")
    code, out, err = run(capsys, "report", mid, "--pdf", tmp_path / "b.pdf")
    assert code == 0, err
    assert (tmp_path / "b.pdf").read_bytes().startswith(b"%PDF")
    code, out, err = run(capsys, "report", mid)
    assert code == 2 and "--pdf" in err


def test_export_every_kind(capsys, root, rec_path, tmp_path):
    files = {k: tmp_path / f"x.{k}" for k in ("csv", "json", "zma", "frd", "driver")}
    args = [a for k, f in files.items() for a in (f"--{k}", f)]
    code, out, err = run(capsys, "export", rec_path, *args, "--zma-model", tmp_path / "m.zma")
    assert code == 0, err
    assert read_curve(files["zma"]).transfer.freqs.size > 10
    assert files["driver"].read_bytes().startswith(b"[Driver]\r\n")
    code, out, err = run(capsys, "export", rec_path)
    assert code == 2 and "--csv" in err


def write_limits(tmp_path, **params):
    path = tmp_path / "limits.json"
    path.write_text(json.dumps({"format": "linpar-limits/1", "parameters": params}))
    return path


def test_analyze_limits_exit_codes(capsys, rec_path, red_path, tmp_path):
    ok = write_limits(tmp_path, fs={"nominal": 70.5, "tolerance": "2%", "unit": "Hz"},
                      Mms={"min": 11, "max": 13, "unit": "g"})
    code, out, err = run(capsys, "analyze", rec_path, "--limits", ok)
    assert code == 0 and "QA: PASS" in out
    assert "fit error: impedance" in out and "judged by value ± 2 σ" in out
    bad = write_limits(tmp_path, fs={"nominal": 50, "tolerance": "2%", "unit": "Hz"})
    code, out, err = run(capsys, "analyze", rec_path, "--limits", bad, "--json")
    doc = json.loads(out)
    assert code == 1 and doc["limits"]["verdict"] == "fail" and doc["limits"]["parameters"][0]["pass"] is False
    code, out, err = run(capsys, "analyze", red_path, "--limits", ok)
    # INVALID in its own word (issue 32), never FAIL: the unit was not judged, the measurement must be repeated.
    assert code == 2 and "QA: INVALID: measure again — measurement invalid" in out and "QA: FAIL" not in out
    code, out, err = run(capsys, "analyze", red_path, "--limits", ok, "--json")
    assert code == 2 and json.loads(out)["limits"]["verdict"] == "invalid"
    code, out, err = run(capsys, "report", red_path, "--html", tmp_path / "red.html", "--limits", ok)
    assert code == 0 and out.startswith("QA: INVALID: measure again")
    assert "QA: INVALID: measure again" in (tmp_path / "red.html").read_text()
    broken = write_limits(tmp_path, fs={"nominal": 50, "unit": "Hz"})
    code, out, err = run(capsys, "analyze", rec_path, "--limits", broken)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and str(broken) in err and "parameters.fs.tolerance" in err and "line " in err


def test_report_with_limits_carries_the_verdict(capsys, root, rec_path, tmp_path):
    ok = write_limits(tmp_path, fs={"nominal": 70.5, "tolerance": "2%", "unit": "Hz"},
                      Mms={"min": 11, "max": 13, "unit": "g"})
    code, out, err = run(capsys, "report", rec_path, "--html", tmp_path / "ok.html", "--limits", ok)
    assert code == 0, err
    assert out.startswith("QA: PASS") and "QA: PASS" in (tmp_path / "ok.html").read_text()
    bad = tmp_path / "bad-limits.json"
    bad.write_text(json.dumps({"format": "linpar-limits/1", "parameters": {"fs": {"max": 60, "unit": "Hz"}}}))
    mid = store(capsys, rec_path, "--serial", "SN7")
    code, out, err = run(capsys, "report", mid, "--html", tmp_path / "bad.html", "--pdf", tmp_path / "bad.pdf",
                         "--limits", bad)
    assert code == 0, err                          # the report was written; `analyze --limits` gives the verdict
    page = (tmp_path / "bad.html").read_text()
    assert out.startswith("QA: FAIL") and "QA: FAIL" in page and "bad-limits.json" in page
    assert (tmp_path / "bad.pdf").read_bytes().startswith(b"%PDF")
    broken = write_limits(tmp_path, fs={"nominal": 50, "unit": "Hz"})
    code, out, err = run(capsys, "report", rec_path, "--html", tmp_path / "never.html", "--limits", broken)
    assert code == 2 and "parameters.fs.tolerance" in err and not (tmp_path / "never.html").exists()


def test_a_read_only_archive_lists_from_its_folders_and_says_so(capsys, root, rec_path, monkeypatch):
    import sqlite3

    from analysis.archive.index import Index
    ids = {store(capsys, rec_path, "--serial", f"R{i}") for i in range(2)}
    (root / "index.sqlite").unlink()
    # As in a folder this user may not write (tests run as root): every index file opens read-only.
    monkeypatch.setattr(Index, "_open", lambda self, path=None: sqlite3.connect(
        f"file:{path or self.path}?mode=ro", uri=True, timeout=0.1))
    code, out, err = run(capsys, "archive", "list", "--json")
    assert code == 0, err
    assert {e["id"] for e in json.loads(out)} == ids
    assert "listed from the measurement folders" in err and "linpar archive rebuild" in err
    assert "Traceback" not in err and not (root / "index.sqlite").exists()
    code, out, err = run(capsys, "archive", "rebuild")
    assert code == 2 and err.startswith("linpar: error:") and err.count("\n") == 1
    assert "cannot rebuild the index" in err and str(root) in err


def test_an_sqlite_error_is_one_line_not_a_traceback(capsys, root, rec_path, monkeypatch):
    import sqlite3

    from analysis.archive.index import Index
    mid = store(capsys, rec_path)

    def io_error(*args, **kwargs):
        raise sqlite3.OperationalError("disk I/O error")
    monkeypatch.setattr(Index, "matching_ids", io_error)
    code, out, err = run(capsys, "archive", "show", mid)
    assert code == 2 and err.count("\n") == 1
    assert "disk I/O error" in err and "linpar archive rebuild" in err


def test_a_mistyped_archive_folder_is_refused_not_read_as_empty(capsys, root, rec_path, tmp_path):
    """`qa stats --archive /archiv_typo` answered "0 measurement(s)", exit 0, as if the line had measured nothing."""
    typo = tmp_path / "archiv_typo"
    for argv in (("archive", "list", "--root", typo), ("qa", "stats", "--archive", typo),
                 ("archive", "show", "20240501-000000-abcdef", "--root", typo)):
        code, out, err = run(capsys, *argv)
        assert code == 2 and err.count("\n") == 1 and f"{typo}: no archive there: check the path" in err, argv
        assert not typo.exists()
    code, out, err = run(capsys, "archive", "store", rec_path, "--root", typo)     # a first store makes one
    assert code == 0, err
    code, out, err = run(capsys, "archive", "list", "--root", typo)
    assert code == 0 and "1 measurement(s)" in out
