"""`linpar analyze --impedance Z.txt --hx HX.txt` on Klippel dB-Lab exports: the fit, the fit error, bad input."""
from __future__ import annotations

import json

import pytest

from app.cli import main
from tests.builders import PAPER
from tests.lpm_files import curve, lpm_text, write_lpm


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def exports(tmp_path_factory):
    d = tmp_path_factory.mktemp("lpm")
    return (write_lpm(d / "Z.txt", "impedance", curve("impedance", noise=0.003, seed=1), curve("impedance")),
            write_lpm(d / "HX.txt", "displacement", curve("displacement", noise=0.003, seed=2),
                      curve("displacement")))


def test_analyze_reads_the_exports_and_reports_each_channels_fit_error(capsys, exports):
    z, hx = exports
    code, out, err = run(capsys, "analyze", "--impedance", z, "--hx", hx, "--hx-fmax", 500, "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["parameters"]["Bl"]["value"] == pytest.approx(PAPER.parameters["Bl"], rel=0.01)
    assert set(doc["validity"]["fit_error_percent"]) == {"impedance", "displacement"}
    assert doc["validity"]["magnitude_only"] == ["impedance", "displacement"]
    code, out, err = run(capsys, "analyze", "--impedance", z, "--hx", hx, "--hx-fmax", 500)
    assert code == 0 and "fit error: impedance" in out and "Klippel dB-Lab export" in out
    assert "magnitude only" in out


def edited(line: int, new: str) -> str:
    """An export of the paper's |Z| (measured and fitted) with one line replaced."""
    lines = lpm_text("impedance", curve("impedance"), curve("impedance")).split("\r\n")
    lines[line - 1] = new
    return "\r\n".join(lines)


@pytest.mark.parametrize("what, text, message", [
    ("missing column", lambda: edited(5, "3.906250\t6.2\t3.906250"), "line 5: column 4 is missing"),
    ("unknown unit", lambda: lpm_text("impedance", curve("impedance"), unit="Ohms/V"), "line 3: column 2: unknown unit"),
    ("text for a number", lambda: edited(4, "1.953125\tabc\t1.953125\t3.1"), "line 4: column 2: non-numeric field"),
    ("fitted only", lambda: lpm_text("impedance", None, curve("impedance")), "line 2: only a fitted curve"),
])
def test_a_bad_export_exits_2_with_one_line_naming_the_file_and_line(capsys, tmp_path, what, text, message):
    path = tmp_path / "Z.txt"
    path.write_text(text(), encoding="latin-1")
    code, out, err = run(capsys, "analyze", "--impedance", path)
    assert code == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and str(path) in lines[0] and message in lines[0], err
