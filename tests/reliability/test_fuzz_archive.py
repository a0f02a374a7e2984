"""The archive among hostile files: folders the index cannot read are skipped, never fatal, never followed out.

Two good measurements are stored, then one folder's measurement.json or
results.json is replaced by random content, or random files, folders,
links and FIFOs with random names are put anywhere under the archive root.
Whatever was put there, `Archive.list`, `rebuild`, `get`, `result`, `export`
and the `linpar archive` commands either work or raise ArchiveError with
one line (exit 2), the two good measurements stay listed, and nothing
outside the root is read, written or exported.
"""
from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from analysis.archive import Archive, ArchiveError
from analysis.archive.archive import FOLDERS, RESULTS_FILE
from analysis.archive.index import INDEX_FILE
from analysis.archive.record import RECORD_FILE
from analysis.archive.results import results_document
from analysis.pipeline import analyze_recording
from analysis.recording.format import write_recording
from app.cli import main as linpar
from tests.builders import TYPICAL_NOISE, recording
from tests.reliability.fuzzing import FUZZ_FEW, one_line

pytestmark = pytest.mark.timeout(90)


@pytest.fixture(scope="module")
def template(tmp_path_factory) -> tuple[Path, list[str], str]:
    """An archive of two good measurements and a third to damage, copied afresh for every example."""
    base = tmp_path_factory.mktemp("template")
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=5)
    write_recording(base / "rec", rec)
    doc = results_document(analyze_recording(rec), rec)
    archive = Archive(base / "archive")
    ids = [archive.store(base / "rec", doc, {"driver": "paper", "serial": f"SN{i}"}) for i in range(3)]
    return base / "archive", ids[:2], archive.get(ids[2]).folder.name


def fresh(template, tmp_path_factory) -> tuple[Path, list[str], Path]:
    """(root, the good ids, the victim's folder) of a new copy of the template, beside a folder 'outside'."""
    root, good, victim = template
    work = tmp_path_factory.mktemp("work")
    shutil.copytree(root, work / "archive", symlinks=True)
    (work / "outside").mkdir()
    (work / "outside" / "secret.json").write_text('{"format": "linpar-measurement/1"}')
    return work / "archive", good, work / "archive" / FOLDERS / victim


def outside_untouched(root: Path) -> None:
    outside = root.parent / "outside"
    assert sorted(p.name for p in outside.iterdir()) == ["secret.json"]
    assert not any(p for p in root.parent.iterdir() if p.name not in ("archive", "outside", "exported"))


def exercise(root: Path, good: list[str], capsys) -> None:
    """Everything a user can do with the archive; the good measurements survive whatever else is there."""
    archive = Archive(root)
    listed = {e.id for e in archive.list()}
    assert set(good) <= listed
    for note in archive.notes:
        one_line(ArchiveError(note))
    report = archive.rebuild()
    assert report.indexed >= len(good)
    for skipped in report.skipped:
        assert "\n" not in skipped
    assert set(good) <= {e.id for e in Archive(root).list()}
    for mid in sorted(listed):
        try:
            m = archive.get(mid)
            m.result()
            for role in ("recording", "sidecar", "results", "settings", "calibration", "laser_stream"):
                path = m.path(role)
                assert path is None or root.resolve() in path.parents
                if role in ("settings", "calibration"):
                    m.load_json(role)
            target = archive.export(mid, root.parent / "exported")
            assert all(p.is_file() and not p.is_symlink() for p in target.iterdir())
        except ArchiveError as exc:
            assert mid not in good, f"{mid} is good but: {exc}"
            one_line(exc)
    for argv in (["list"], ["list", "--json"], ["rebuild"], ["show", good[0]], ["compare", *good],
                 ["compare", "--json", *sorted(listed)[:8]], *(["show", mid] for mid in sorted(listed))):
        code = linpar(["archive", *argv, "--root", str(root)])
        out, err = capsys.readouterr()
        assert "Traceback" not in out + err
        assert code == 0 or (code == 2 and err.startswith("linpar: error: ") and err.count("\n") == 1), (argv, err)
    outside_untouched(root)


# --- measurement.json and results.json of random content -------------------------------------------

json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.just(10**400) | st.floats() | st.text(max_size=10)
    | st.sampled_from(["../../outside/secret.json", "/etc/passwd", "x\x00y", "a" * 300, "CON", "recording.wav"]),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=6), inner, max_size=3),
    max_leaves=8)
RECORD_KEYS = ["format", "id", "folder", "measured_at", "stored_at", "driver", "serial", "validity", "effects",
               "key_parameters", "files", "sd_m2", "notes"]


def set_path(doc, path, value):
    for key in path[:-1]:
        if not isinstance(doc, dict):
            return
        doc = doc.setdefault(key, {})
    if isinstance(doc, dict):
        doc[path[-1]] = value


@FUZZ_FEW
@given(which=st.sampled_from([RECORD_FILE, RESULTS_FILE]),
       edits=st.lists(st.tuples(st.lists(st.sampled_from(RECORD_KEYS + ["RE", "value", "std", "unit", "results",
                                                                        "parameters", "model", "curves",
                                                                        "display_scale", "impedance", "freqs_hz",
                                                                        "values", "effects"]),
                                         min_size=1, max_size=3), json_values), min_size=1, max_size=4),
       raw=st.one_of(st.none(), st.binary(max_size=40)))
@example(which=RECORD_FILE, edits=[(["effects"], [1, 2])], raw=None)                        # was TypeError
@example(which=RECORD_FILE, edits=[(["key_parameters", "RE", "value"], 10**30)], raw=None)   # was OverflowError
@example(which=RECORD_FILE, edits=[(["key_parameters", "RE", "value"], "abc")], raw=None)    # `show` formatted it
@example(which=RECORD_FILE, edits=[(["files", "results"], "../../../outside/secret.json")], raw=None)
@example(which=RESULTS_FILE, edits=[(["parameters", "RE"], [1])], raw=None)                 # was AttributeError
@example(which=RESULTS_FILE, edits=[(["parameters", "RE", "value"], 1e308),
                                    (["parameters", "RE", "display_scale"], 1e10)], raw=None)   # compare --json: inf
@example(which=RESULTS_FILE, edits=[(["validity"], "green")], raw=None)                    # was ValueError
@example(which=RECORD_FILE, edits=[(["x"], 0)], raw=b"[" * 5000)                             # was RecursionError
def test_random_content_in_a_measurements_files(template, tmp_path_factory, capsys, which, edits, raw):
    root, good, folder = fresh(template, tmp_path_factory)
    victim = folder / which
    if raw is not None:
        victim.write_bytes(raw)
    else:
        doc = json.loads(victim.read_text())
        for path, value in edits:
            set_path(doc, path, value)
        victim.write_text(json.dumps(doc))
    (root / INDEX_FILE).unlink()       # the index is rebuilt from the folders, the damaged one among them
    exercise(root, good, capsys)


# --- random files and names anywhere under the root -----------------------------------------------------

names = st.one_of(
    st.text(alphabet=st.characters(codec="utf-8", exclude_characters="/\x00"), min_size=1, max_size=20),
    st.sampled_from(["..", ".", "...", "CON", "nul.txt", "AUX", "com1", "LPT9.json", " ", "-rf", "~", "$HOME",
                     "20240101-000000-abcdef", "20240101-000000-abcdef-x", ".incoming-x", "index.sqlite-journal",
                     "a" * 255, "measurement.json", "results.json", "\n", "x\ny", "ünï\u202ecöde", "index.sqlite",
                     "measurements", "recording.wav", "laser.bin"]))
kinds = st.sampled_from(["file", "folder", "link-out", "link-loop", "fifo", "record", "empty-folder"])
places = st.sampled_from(["root", "folders", "measurement"])


@FUZZ_FEW
@given(items=st.lists(st.tuples(places, names, kinds, st.binary(max_size=30)), min_size=1, max_size=6))
@example(items=[("folders", "20240101-000000-abcdef", "record", b""), ("measurement", RESULTS_FILE, "link-out", b"")])
@example(items=[("folders", "20240101-000000-abcdef", "folder", b""), ("measurement", RECORD_FILE, "fifo", b"")])
@example(items=[("measurement", RESULTS_FILE, "fifo", b""), ("measurement", "settings.json", "link-loop", b"")])
@example(items=[("root", "index.sqlite", "fifo", b"")])
def test_random_files_and_names_under_the_root(template, tmp_path_factory, capsys, items):
    root, good, victim = fresh(template, tmp_path_factory)
    for place, name, kind, payload in items:
        if name in (".", ".."):
            continue                      # those exist already
        parent = {"root": root, "folders": root / FOLDERS, "measurement": victim}[place]
        target = parent / name
        if target.is_file() and not target.is_symlink():
            target.unlink()           # index.sqlite or one of the victim's files: replaced
        try:
            if kind == "file":
                target.write_bytes(payload)
            elif kind in ("folder", "empty-folder", "record"):
                target.mkdir()
                if kind == "folder":
                    (target / RECORD_FILE).write_bytes(payload)
                if kind == "record":
                    (target / RECORD_FILE).write_text(json.dumps({
                        "format": "linpar-measurement/1", "id": "20240101-000000-abcdef", "folder": name,
                        "measured_at": "2024", "stored_at": "2024", "validity": "green", "driver": "d",
                        "serial": "", "operator": "", "station": "",
                        "files": {"results": "../../../outside/secret.json", "settings": "/etc/passwd"}}))
            elif kind == "link-out":
                target.symlink_to(root.parent / "outside" / "secret.json")
            elif kind == "link-loop":
                target.symlink_to(target)
            elif kind == "fifo":
                os.mkfifo(target)
        except (FileExistsError, IsADirectoryError, OSError):
            continue                      # a name the file system refuses, or one already there
    exercise(root, good, capsys)
