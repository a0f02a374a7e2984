"""Hostile files and archives at the command line (the issue's findings 6, 7, 8, 10 and 11).

Devices and FIFOs are named as what they are and never read; a damaged index row or a crafted
measurement.json is reported and skipped; `--json` is always valid JSON; every message is one line.
"""
from __future__ import annotations

import json
import os
import sqlite3
import time

import pytest

from analysis.archive import Archive
from analysis.recording.format import make_recording, write_recording
from app.cli import main
from tests.builders import TYPICAL_NOISE, recording
from tests.pace import paced


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def strict_json(text: str):
    """JSON as any other reader takes it: NaN and Infinity are refused."""
    def refuse(name):
        raise AssertionError(f"{name} in the JSON output")
    return json.loads(text, parse_constant=refuse)


def error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("linpar: error: "), err
    return lines[0]


@pytest.fixture(scope="module")
def rec(tmp_path_factory):
    path = tmp_path_factory.mktemp("rec") / "paper"
    write_recording(path, recording(noise=TYPICAL_NOISE, n_periods=3, seed=41))
    return path


@pytest.fixture
def archive(rec, tmp_path, capsys):
    root = tmp_path / "archive"
    ids = []
    for serial in ("SN1", "SN2"):
        code, out, err = run(capsys, "archive", "store", rec, "--root", root, "--serial", serial, "--json")
        assert code == 0, err
        ids.append(json.loads(out)["id"])
    return root, ids


def test_a_device_as_laser_stream_is_refused_at_once(capsys, rec, tmp_path):
    started = time.monotonic()
    code, _, err = run(capsys, "archive", "store", rec, "--root", tmp_path / "a", "--laser-stream", "/dev/zero")
    assert code == 2 and time.monotonic() - started < paced(60)        # /dev/zero was copied forever
    assert "/dev/zero: a device, not a regular file" in error_line(err)
    assert not any((tmp_path / "a").rglob("laser*"))


def test_a_fifo_as_laser_stream_is_refused(capsys, rec, tmp_path):
    fifo = tmp_path / "stream.bin"
    os.mkfifo(fifo)
    code, _, err = run(capsys, "archive", "store", rec, "--root", tmp_path / "a", "--laser-stream", fifo)
    assert code == 2 and "a FIFO (named pipe), not a regular file" in error_line(err)


def test_a_blob_in_a_text_column_is_skipped_with_a_note_and_json_stays_valid(capsys, archive):
    root, ids = archive
    with sqlite3.connect(root / "index.sqlite") as conn:
        conn.execute("UPDATE measurements SET driver = ? WHERE id = ?", (b"\x00\xff", ids[0]))
        conn.execute("UPDATE parameters SET value = ? WHERE measurement_id = ? AND name = 'RE'", (1e308 * 10, ids[1]))
    code, out, err = run(capsys, "archive", "list", "--root", root)
    assert code == 0 and ids[1] in out and ids[0] not in out
    assert "skipped 2 row(s) of the index" in err and "linpar archive rebuild" in err
    code, out, err = run(capsys, "archive", "list", "--root", root, "--json")
    listed = strict_json(out)
    assert code == 0 and [e["id"] for e in listed] == [ids[1]] and "RE" not in listed[0]["parameters"]


def test_a_date_beyond_9998_is_one_line(capsys, rec, tmp_path):
    code, _, err = run(capsys, "archive", "store", rec, "--root", tmp_path / "a",
                       "--measured-at", "9999-12-31T23:59:59-05:00")
    assert code == 2 and "meta.measured_at" in error_line(err) and "a year" in err


@pytest.mark.parametrize("when", ["2026-05-04T09:30:00", "2026-05-04 09:30", "2026-05-04"])
def test_a_measurement_time_without_its_utc_offset_is_one_line_and_nothing_stored(capsys, rec, tmp_path, when):
    """Taken as UTC, 09:30 typed at a station on UTC+2 would date the unit two hours late in the line's archive:
    the offset is asked for, before the analysis runs, and nothing is stored."""
    root = tmp_path / "a"
    code, out, err = run(capsys, "archive", "store", rec, "--root", root, "--measured-at", when)
    line = error_line(err)
    assert code == 2 and "has no UTC offset" in line and "+01:00" in line and "or Z for UTC" in line
    assert Archive(root).list() == []
    code, out, err = run(capsys, "archive", "store", rec, "--root", root, "--measured-at", when + "+02:00"
                         if "T" in when or " " in when else when + "T00:00+02:00", "--json")
    assert code == 0
    stored = Archive(root).list()
    assert len(stored) == 1 and stored[0].measured_at.endswith("Z") and stored[0].measured_at[11:13] in ("07", "22")


@pytest.mark.parametrize("field, value, words", [
    (("key_parameters", "RE", "value"), float("inf"), "key_parameters.RE.value: found inf"),
    (("driver",), "two\nlines", "driver held characters that are not text"),
    (("operator",), "\x1b[2J", "operator held characters that are not text"),
    (("sd_m2",), 1e300, "sd_m2: found 1e+300"),
])
def test_a_crafted_value_is_shown_flagged_never_dropped(capsys, archive, field, value, words):
    """A record whose value no measurement can have (or a name with control characters) stays in the archive:
    rebuilt, listed and shown, the bad value flagged and not shown (issue 31: nothing read back makes a record
    unreadable)."""
    root, ids = archive
    craft(root, ids[0], field, value)
    code, out, err = run(capsys, "archive", "rebuild", "--root", root, "--json")
    assert code == 0 and strict_json(out)["indexed"] == 2, err
    code, out, err = run(capsys, "archive", "list", "--root", root, "--json")
    assert sorted(e["id"] for e in strict_json(out)) == sorted(ids)
    code, out, _ = run(capsys, "archive", "show", ids[0], "--root", root, "--json")
    shown = strict_json(out)
    assert code == 0 and shown["id"] == ids[0] and any(words in flag for flag in shown["flags"]), shown["flags"]
    assert "\x1b" not in out


def test_a_record_whose_date_is_no_date_is_skipped_and_reported(capsys, archive):
    """A date that is not one cannot be placed in time (the index sorts and filters by it): skipped, said."""
    root, ids = archive
    craft(root, ids[0], ("measured_at",), "yesterday")
    code, out, err = run(capsys, "archive", "rebuild", "--root", root, "--json")
    report = strict_json(out)
    assert code == 0 and report["indexed"] == 1
    assert "measured_at: 'yesterday' is not an ISO 8601 date" in report["skipped"][0]
    code, out, err = run(capsys, "archive", "list", "--root", root, "--json")
    assert [e["id"] for e in strict_json(out)] == [ids[1]]
    code, out, _ = run(capsys, "archive", "show", ids[1], "--root", root, "--json")
    assert code == 0 and strict_json(out)["id"] == ids[1]


def craft(root, mid, field, value) -> None:
    """Write ``value`` at ``field`` of a stored record's JSON, as someone editing the file by hand would."""
    folder = Archive(root).get(mid).folder
    doc = json.loads((folder / "measurement.json").read_text())
    target = doc
    for key in field[:-1]:
        target = target[key]
    target[field[-1]] = value
    (folder / "measurement.json").write_text(json.dumps(doc))      # json writes Infinity: what a crafter would


def test_two_damaged_indexes_in_one_second_keep_both(capsys, archive, monkeypatch):
    import types

    import analysis.archive.index as index
    root, ids = archive
    frozen = types.SimpleNamespace(strftime=lambda fmt: "20240501-120000", monotonic_ns=time.monotonic_ns)
    monkeypatch.setattr(index, "time", frozen)            # one second for both
    for garbage in (b"first damage", b"second damage"):
        (root / "index.sqlite").write_bytes(garbage)
        code, out, _ = run(capsys, "archive", "list", "--root", root)
        assert code == 0 and ids[0] in out
    aside = sorted(p.read_bytes() for p in root.glob("index.sqlite.broken-*"))
    assert aside == [b"first damage", b"second damage"]


def test_the_json_of_every_archive_command_is_strict(capsys, archive, tmp_path):
    root, ids = archive
    for argv in (["list"], ["show", ids[0]], ["compare", *ids], ["rebuild"], ["export", ids[0], tmp_path / "x"]):
        code, out, err = run(capsys, "archive", *argv, "--root", root, "--json")
        assert code == 0, err
        strict_json(out)


# --- finding 11: messages that said the wrong thing --------------------------------------------------

@pytest.mark.parametrize("kind", ["fifo", "folder", "device"])
def test_a_sidecar_that_is_no_file_is_named_as_what_it_is(capsys, rec, tmp_path, kind):
    stem = tmp_path / "odd"
    (tmp_path / "odd.wav").write_bytes(rec.with_name("paper.wav").read_bytes())
    sidecar = tmp_path / "odd.json"
    if kind == "fifo":
        os.mkfifo(sidecar)
    elif kind == "folder":
        sidecar.mkdir()
    else:
        sidecar.symlink_to("/dev/zero")
    code, _, err = run(capsys, "analyze", stem)
    line = error_line(err)
    assert code == 2 and "missing" not in line
    assert {"fifo": "a FIFO (named pipe)", "folder": "a folder", "device": "a device"}[kind] in line


def test_added_masses_in_either_order(capsys):
    from tests.builders import REAL_DATA
    seas = REAL_DATA / "seas_l16rnx"
    if not seas.is_dir():
        pytest.skip(f"the real data are not at {seas}")
    free, m8, m16 = (seas / f"L16RNX_{n}_242_27mV.zma" for n in ("0g", "8_017g", "16_048g"))
    outs = []
    for order in ((("8.017", m8), ("16.048", m16)), (("16.048", m16), ("8.017", m8))):
        argv = ["addedmass", free, "--json"] + [x for grams, path in order for x in ("--mass", grams, path)]
        code, out, err = run(capsys, *argv)
        assert code == 0, err
        outs.append(strict_json(out))
    assert outs[0] == outs[1]
    code, _, err = run(capsys, "addedmass", free, "--mass", "20", m8, "--mass", "20", m16)
    assert code == 2 and "both added masses are 20 g" in error_line(err)


def test_a_record_without_a_results_file_says_so(capsys, archive):
    root, ids = archive
    folder = Archive(root).get(ids[0]).folder
    doc = json.loads((folder / "measurement.json").read_text())
    del doc["files"]["results"]
    (folder / "measurement.json").write_text(json.dumps(doc))
    code, _, err = run(capsys, "report", ids[0], "--root", root, "--html", root.parent / "r.html")
    line = error_line(err)
    assert code == 2 and "None" not in line and "files.results: missing" in line


def test_an_analysis_error_names_the_file(capsys, tmp_path):
    good = recording(noise=TYPICAL_NOISE, n_periods=3, seed=42)
    few = make_recording(good.sample_rate, {c.signal: good.signal(c.signal) for c in good.channels},
                         good.period_samples, good.settle_periods, good.excited_bins[40:43])
    write_recording(tmp_path / "three-lines", few)
    code, _, err = run(capsys, "stats", tmp_path / "three-lines")
    line = error_line(err)
    assert code == 2 and "three-lines.wav" in line and "impedance lines" in line


@pytest.mark.parametrize("command", [["report", "REC", "--html", "OUT"], ["export", "REC", "--csv", "OUT"]])
@pytest.mark.parametrize("kind", ["fifo", "device", "input"])
def test_an_output_never_replaces_a_fifo_a_device_or_an_input(capsys, rec, tmp_path, command, kind):
    work = tmp_path / "rec"
    for suffix in (".wav", ".json"):
        work.with_suffix(suffix).write_bytes(rec.with_suffix(suffix).read_bytes())
    before = work.with_suffix(".wav").read_bytes()
    if kind == "fifo":
        out = tmp_path / "out"
        os.mkfifo(out)
    elif kind == "device":
        out = tmp_path / "null"
        out.symlink_to("/dev/null")           # as root, a rename onto it would replace the device
    else:
        out = work.with_suffix(".wav")
    argv = [str(work) if a == "REC" else str(out) if a == "OUT" else a for a in command]
    code, _, err = run(capsys, *argv)
    assert code == 2 and "choose another name" in error_line(err)
    assert work.with_suffix(".wav").read_bytes() == before
    if kind == "fifo":
        assert os.path.exists(out) and not out.is_file()          # still the FIFO
