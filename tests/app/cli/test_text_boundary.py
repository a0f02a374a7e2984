"""Names crossing a boundary (issue 31, class 1): refused where they enter, escaped where they leave, and nothing
read back from the archive can make a record unreadable.

Each test is one class of the issue: a control character where a name enters; a record holding a bad value;
a spreadsheet formula in an exported cell; a terminal escape sequence in what is printed; bytes that were not
UTF-8 in an argument.
"""
import csv
import io
import json
import os
from pathlib import Path

import pytest

from analysis.archive import Archive
from analysis.archive.record import RECORD_FILE
from analysis.effects.file_error import EffectFileError
from analysis.effects.user import effect_from_text
from app.cli import main
from tests.production_helpers import LIMITS, small_measurement, unit

EFFECT = Path(__file__).resolve().parents[3] / "resources" / "effects" / "rms-sqrt-f.toml"
HOSTILE = ("A\tB", "A\nB", "A\x1b]0;owned\x07B", "A\x85B", "A\u2028B", "A\x00B", "st2\u202eSSAP", "A\u2066B")


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def refused(code, out, err, why=""):
    lines = [line for line in err.splitlines() if line.startswith("linpar: error: ")]
    return code == 2 and len(lines) == 1 and why in lines[0] and "Traceback" not in err and "\x1b" not in err + out


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    return small_measurement(tmp_path_factory.mktemp("unit"))


@pytest.mark.parametrize("name", HOSTILE)
def test_a_control_character_in_a_name_is_refused_where_it_enters(capsys, tmp_path, measured, name):
    """Class: names entering (limits names, serials, operators, stations, drivers, notes, effect titles)."""
    limits = tmp_path / "limits.json"
    limits.write_text(json.dumps({**LIMITS, "name": name}))
    root = tmp_path / "archive"
    assert refused(*run(capsys, "qa", "limits", "--store", limits, "--root", root), "name: holds")
    assert not (root / "limits").exists() or not list((root / "limits").iterdir())
    path, _ = measured
    for option in ("--driver", "--serial", "--operator", "--station", "--notes"):
        assert refused(*run(capsys, "archive", "store", "--root", root, path, option, name), "holds"), option
    effect = EFFECT.read_text()
    assert effect_from_text(effect, "mine.toml").title
    with pytest.raises(EffectFileError, match="title: holds"):
        effect_from_text(effect.replace('title = "Viscous', f'title = {json.dumps(name)[:-1]}Viscous'), "mine.toml")


def test_a_record_with_a_bad_value_is_shown_flagged_never_dropped(capsys, tmp_path, measured):
    """Class: read back. A record written with a tab in a name, an escape sequence in its limits' name and an
    impossible number is listed, rebuilt and shown, with what was wrong flagged."""
    path, doc = measured
    archive = Archive(tmp_path / "archive")
    archive.store_limits(LIMITS)
    mid = archive.store(path, unit(doc, fs=70.0), {"serial": "SN1", "driver": "W6"})
    record_path = archive.get(mid).folder / RECORD_FILE
    record = json.loads(record_path.read_text())
    record["operator"] = "M\tller"
    record["qa"]["limits_name"] = "\x1b[32mALL UNITS PASS\x1b[0m"
    record["key_parameters"]["fs"]["value"] = 1e300
    record_path.write_text(json.dumps(record))
    code, out, err = run(capsys, "archive", "rebuild", "--root", archive.root, "--json")
    assert code == 0 and json.loads(out)["indexed"] == 1, err
    code, out, err = run(capsys, "archive", "list", "--root", archive.root)
    assert code == 0 and mid in out and "SN1" in out, err
    code, out, err = run(capsys, "archive", "show", "--root", archive.root, mid)
    assert code == 0, err
    assert "M\\tller" in out and "\x1b" not in out
    flags = [line for line in out.splitlines() if line.startswith("flagged: ")]
    assert len(flags) == 3 and any("operator" in f for f in flags) and any("fs.value" in f for f in flags)
    code, out, err = run(capsys, "archive", "show", "--root", archive.root, mid, "--json")
    shown = json.loads(out)
    assert shown["key_parameters"]["fs"]["value"] is None and len(shown["flags"]) == 3


def test_a_stored_limits_name_with_escapes_reaches_no_terminal(capsys, tmp_path, measured):
    """Class: terminal output. A limits version stored before names were checked (or by another program)
    still judges, and its name is printed without its escape sequences."""
    path, doc = measured
    archive = Archive(tmp_path / "archive")
    archive.store_limits(LIMITS)
    stored = archive.root / "limits" / "v0001.json"
    version = json.loads(stored.read_text())
    version["limits"]["name"] = "W6\x1b]0;owned\x07\x1b[2J"
    stored.write_text(json.dumps(version))
    archive.store(path, unit(doc, fs=70.0), {"serial": "SN1", "driver": "W6"})
    code, out, err = run(capsys, "qa", "stats", "--root", archive.root)
    assert code == 0, err
    assert "\x1b" not in out + err and "W6\\x1b]0;owned" in out
    code, out, err = run(capsys, "archive", "show", "--root", archive.root, "\x1b[31m")
    assert refused(code, out, err)
    from analysis.text_boundary import terminal
    assert terminal("a\x1b[31mred\x1b[0m \x1b]8;;http://x\x07link\x1b]8;;\x07 \x9b2J") == "ared link "


def test_exported_cells_never_run_as_spreadsheet_formulas(capsys, tmp_path, measured):
    """Class: CSV/Q-DAS cells (OWASP's CSV injection): names beginning with = + - @ or a tab are quoted."""
    path, doc = measured
    archive = Archive(tmp_path / "archive")
    archive.store_limits(LIMITS)
    names = {"serial": '=HYPERLINK("http://x","open")', "operator": "@SUM(1+1)", "station": "+cmd",
             "driver": "-2+3"}
    archive.store(path, unit(doc, fs=70.0), names)
    out_csv = tmp_path / "units.csv"
    code, out, err = run(capsys, "qa", "export", "--root", archive.root, "--csv", out_csv)
    assert code == 0, err
    rows = list(csv.DictReader(line for line in io.StringIO(out_csv.read_text()) if not line.startswith("#")))
    assert rows
    for row in rows:
        for key, typed in names.items():
            assert row[key] == "'" + typed
    dfq = tmp_path / "units.dfq"
    code, out, err = run(capsys, "qa", "export", "--root", archive.root, "--dfq", dfq)
    assert code == 0, err
    fields = [line.split(" ", 1)[1] for line in dfq.read_text(encoding="latin-1").splitlines()
              if line.startswith(("K0014", "K1001"))]
    assert fields and all(not f.startswith(("=", "+", "-", "@")) for f in fields)
    from analysis.text_boundary import spreadsheet_cell
    assert spreadsheet_cell("\tx") == "'\tx" and spreadsheet_cell("SN-1") == "SN-1"


def test_an_argument_that_is_not_utf8_is_one_line_and_no_crash(capsys, tmp_path):
    """Class: undecodable bytes in arguments (`--operator $'M\\xfcller'` in a UTF-8 locale)."""
    latin1 = os.fsdecode(b"M\xfcller")
    cache = Path(os.environ["LINPAR_CACHE"])
    before = set(cache.glob("crash-*")) if cache.is_dir() else set()
    code, out, err = run(capsys, "archive", "list", "--root", tmp_path / "a", "--operator", latin1)
    assert refused(code, out, err) and "\\xfc" in err
    assert not (set(cache.glob("crash-*")) if cache.is_dir() else set()) - before
    from app.crash_report import write_crash_report
    report = write_crash_report(RuntimeError("x"), argv=["archive", "list", "--operator", latin1])
    assert "M\\udcfcller" in report.read_text(encoding="utf-8") and "RuntimeError" in report.read_text()
    report.unlink()


def test_a_name_with_commas_puts_no_formula_in_a_cell_of_the_exports_comment_lines(capsys, tmp_path, measured):
    """A spreadsheet has no comment lines: it splits '# driver ACME,=1+2' at the comma, and '=1+2' is a cell."""
    path, doc = measured
    archive = Archive(tmp_path / "archive")
    names = {"driver": "ACME,=1+2,+3+4, -5+6,@SUM(1)", "serial": 'SN,"=HYPERLINK(""http://x"")"'}
    mid = archive.store(path, unit(doc, fs=70.0), names)
    out_csv = tmp_path / "parameters.csv"
    code, out, err = run(capsys, "export", mid, "--root", archive.root, "--csv", out_csv)
    assert code == 0, err
    text = out_csv.read_text()
    comments = [line for line in text.splitlines() if line.startswith("#")]
    cells = [cell.lstrip(" ") for row in csv.reader(comments) for cell in row]     # as a spreadsheet splits them
    assert len(cells) > len(comments) and not [c for c in cells if c.startswith(("=", "+", "-", "@"))]
    assert "# driver ACME,'=1+2,'+3+4,' -5+6,'@SUM(1)" in text.splitlines()       # still one line that says it
