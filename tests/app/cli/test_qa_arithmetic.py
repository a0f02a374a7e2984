"""QA arithmetic (issue 31, class 3): first-pass yield counts each unit's first test; `qa stats` columns fit
their numbers and keep their signs."""
import copy
import json

import pytest

from analysis.archive import Archive
from app.cli import main
from tests.production_helpers import LIMITS, small_measurement, unit


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    return small_measurement(tmp_path_factory.mktemp("unit"))


def test_first_pass_yield_counts_each_units_first_test(capsys, tmp_path, measured):
    path, doc = measured
    archive = Archive(tmp_path / "archive")
    archive.store_limits(LIMITS)
    for serial, fs, when in (("SN1", 90.0, "01:00"), ("SN1", 70.0, "02:00"), ("SN2", 70.0, "03:00")):
        archive.store(path, unit(doc, fs=fs), {"serial": serial, "driver": "W6",
                                               "measured_at": f"2024-05-01T{when}:00Z"})
    code, out, err = run(capsys, "qa", "stats", "--root", archive.root, "--json")
    assert code == 0, err
    stats = json.loads(out)
    assert stats["verdicts"] == {"fail": 1, "pass": 2}
    assert stats["first_pass_yield"] == pytest.approx(0.5)       # SN1 failed first, SN2 passed: 1 of 2 units
    code, out, err = run(capsys, "qa", "stats", "--root", archive.root)
    assert "first-pass yield 50.0 %" in out


def test_stats_columns_fit_six_digit_capability_indices(capsys, tmp_path, measured):
    path, doc = measured
    archive = Archive(tmp_path / "archive")
    archive.store_limits(LIMITS)
    for i in range(12):        # RE within 2.5..3.5 ohm, spread 1e-7 ohm: Cp ~ 1e6; fs centred: Cp ~ 4
        archive.store(path, unit(doc, fs=70.0 + 0.5 * (-1) ** i, RE=3.0 + 1e-7 * (i % 3)),
                      {"serial": f"SN{i}", "driver": "W6", "measured_at": f"2024-05-01T{i:02d}:00:00Z"})
    code, out, err = run(capsys, "qa", "stats", "--root", archive.root, "--parameter", "RE", "--parameter", "fs")
    assert code == 0, err
    lines = out.splitlines()
    head = next(line for line in lines if line.startswith("parameter"))
    row = next(line for line in lines if line.startswith("RE "))
    for name in ("Cp", "Cpk", "Pp", "Ppk"):
        end = head.index(f"{name} ") + len(name)          # the header is right-aligned over its column
        cell = row[end - 8:end]
        assert cell[0] == " ", (name, row)                 # one space at least: never glued to its neighbour
        value = float(cell)
        assert value > 1e5, (name, cell, row)              # positive, and as large as it is
    code, out, err = run(capsys, "qa", "stats", "--root", archive.root, "--parameter", "RE", "--json")
    (re_stats,) = json.loads(out)["parameters"]
    assert re_stats["cp"] > 1e5


def test_the_limit_is_whole_and_the_extremes_tell_themselves_from_it(capsys, tmp_path, measured):
    """A limit in m/N was cut to 21 characters ("0.000421234 .. 0.0004": its upper bound and unit lost), and a
    max of 3.0201 against "≤ 3.02 Ω" read "3.02"."""
    path, doc = measured
    archive = Archive(tmp_path / "archive")
    archive.store_limits({"format": "linpar-limits/1", "name": "edge", "parameters": {
        "RE": {"max": 3.02, "unit": "ohm"}, "Cms": {"min": 0.000421234, "max": 0.000438765, "unit": "m/N"}}})
    for i, re_ in enumerate((3.0100000, 3.0150000, 3.0201000)):          # the last fails by 0.1 mohm (2 sigma: 0.07)
        archive.store(path, unit(doc, RE=re_), {"serial": f"SN{i}", "driver": "W6",
                                                "measured_at": f"2024-05-01T{i:02d}:00:00Z"})
    code, out, err = run(capsys, "qa", "stats", "--root", archive.root, "--parameter", "RE", "--parameter", "Cms")
    assert code == 0, err
    re_row = next(line for line in out.splitlines() if line.startswith("RE "))
    cms_row = next(line for line in out.splitlines() if line.startswith("Cms "))
    assert " 3.0201 " in re_row and " 3.01 " in re_row
    assert "0.000421234 .. 0.000438765 m/N" in cms_row


def test_a_broken_measurement_is_refused_as_a_golden_unit_where_it_is_marked(capsys, tmp_path, measured):
    """A red unit marked golden was taken, and only `qa limits --from-golden` refused it, later and elsewhere."""
    path, doc = measured
    archive = Archive(tmp_path / "archive")
    broken = copy.deepcopy(doc)
    broken["validity"]["overall"] = "red"
    good = archive.store(path, doc, {"serial": "SN1", "driver": "W6"})
    bad = archive.store(path, broken, {"serial": "SN2", "driver": "W6"})
    code, _, err = run(capsys, "qa", "golden", "--root", archive.root, "--add", good, bad)
    assert code == 2 and f"{bad} (red)" in err and "measure it again or leave it out" in err
    assert archive.golden() == []                         # nothing marked: neither of the two
    code, out, err = run(capsys, "qa", "golden", "--root", archive.root, "--add", good, "--json")
    assert code == 0, err
    assert json.loads(out)["golden"] == [good]
