"""The archive: folders + SQLite index; the index survives deletion, garbage, truncation and wrong schemas."""
import errno
import json
import os
import shutil
import sqlite3
import time

import pytest

from analysis.archive import Archive, ArchiveError, compare
from analysis.archive.archive import FOLDERS
from analysis.archive.index import INDEX_FILE, Index, insert
from analysis.archive.leftovers import sweep
from analysis.archive.names import folder_name, inside, safe_suffix, slug
from analysis.archive.record import read_record
from analysis.archive.results import StoredResult, results_document
from analysis.archive.schema import CURRENT_VERSION, MIGRATIONS
from analysis.pipeline import analyze_recording
from analysis.recording.format import read_recording, write_recording
from tests.builders import TYPICAL_NOISE, recording


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    """(recording path, results document) of one short synthetic measurement."""
    path = tmp_path_factory.mktemp("rec") / "paper"
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=3)
    write_recording(path, rec)
    return path, results_document(analyze_recording(rec), rec)


def fill(root, measured, n=5, **meta):
    path, doc = measured
    archive = Archive(root)
    ids = [archive.store(path, doc, {"serial": f"SN{i}", "operator": "ana", "station": "QA1", **meta})
           for i in range(n)]
    return archive, ids


def test_store_writes_a_complete_folder_and_the_index_lists_it(tmp_path, measured):
    archive, (mid,) = fill(tmp_path, measured, 1, driver="woofer 6", measured_at="2024-05-01T12:00:00+02:00")
    m = archive.get(mid)
    assert m.folder.parent == tmp_path / FOLDERS
    assert sorted(p.name for p in m.folder.iterdir()) == ["calibration.json", "measurement.json", "recording.json",
                                                          "recording.wav", "results.json", "settings.json"]
    assert m.record["measured_at"] == "2024-05-01T10:00:00Z"
    assert (m.folder / "recording.wav").read_bytes() == measured[0].with_suffix(".wav").read_bytes()
    read_recording(m.recording_path())        # the stored recording is a valid recording
    (entry,) = archive.list()
    assert (entry.id, entry.driver, entry.serial, entry.operator, entry.station, entry.validity) == \
           (mid, "woofer 6", "SN0", "ana", "QA1", "green")
    assert entry.parameters["fs"]["unit"] == "Hz"
    assert entry.parameters["fs"]["value"] == pytest.approx(70.5, rel=0.01)
    stored = m.result()
    assert stored.parameters["Bl"].value == measured[1]["parameters"]["Bl"]["value"]
    assert archive.notes == []


def test_store_takes_a_recording_object_and_an_analysis_result(tmp_path):
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=4)
    result = analyze_recording(rec)
    archive = Archive(tmp_path)
    mid = archive.store(rec, result, {"serial": "X"}, laser_stream=__file__)
    m = archive.get(mid)
    assert m.entry.driver == "synthetic"            # from the recording's sidecar
    assert m.path("laser_stream").name == "laser.py"
    assert isinstance(m.result(), StoredResult)


def test_list_filters_and_limits(tmp_path, measured):
    archive, ids = fill(tmp_path, measured, 4)
    archive.store(measured[0], measured[1], {"driver": "tweeter_x%", "serial": "T1", "operator": "ben"})
    assert len(archive.list()) == 5
    assert [e.serial for e in archive.list(driver="TWEETER_X%")] == ["T1"]
    assert archive.list(driver="%") == archive.list(driver="tweeter_x%")   # '%' is literal, not a wildcard
    assert len(archive.list(operator="ana")) == 4
    assert len(archive.list(limit=2)) == 2
    assert archive.list(validity="red") == []
    assert len(archive.list(since="2000-01-01", until="2999-12-31")) == 5


def test_ids_resolve_by_unique_prefix(tmp_path, measured):
    archive, ids = fill(tmp_path, measured, 2)
    assert archive.get(ids[0][:-1]).id == ids[0] or ids[0][:-1] == ids[1][:-1]
    with pytest.raises(ArchiveError, match="matches 2"):
        archive.get(ids[0][:8])      # same day: both match
    with pytest.raises(ArchiveError, match="no measurement"):
        archive.get("19990101")


@pytest.mark.parametrize("bad", ["../x", "../../etc/passwd", "/etc/passwd", "a\x00b", "..", "", "20240101/../.."])
def test_ids_that_are_paths_are_refused(tmp_path, measured, bad):
    archive, _ = fill(tmp_path, measured, 1)
    with pytest.raises(ArchiveError, match="not a measurement id"):
        archive.get(bad)


@pytest.mark.parametrize("evil", ["../../outside", "/etc/passwd", "a\x00b/../../c", "..", "C:\\Windows\\x",
                                  "ünïcödé / ≠ \\ : * ? \" < > |", "-" * 300])
def test_names_from_users_never_place_anything_outside_the_root(tmp_path, measured, evil):
    root = tmp_path / "archive"
    archive = Archive(root)
    mid = archive.store(measured[0], measured[1], {"driver": evil, "serial": evil, "operator": evil,
                                                   "station": evil}, laser_stream=_evil_file(tmp_path, evil))
    m = archive.get(mid)
    assert m.folder.parent == root / FOLDERS
    assert all(c.isalnum() or c == "-" for c in m.folder.name)
    assert "\x00" not in m.entry.driver
    outside = [p for p in tmp_path.rglob("*") if root not in p.parents and p != root and p.name != "evil-src"]
    assert outside == []


def _evil_file(tmp_path, evil):
    src = tmp_path / "evil-src"
    src.write_bytes(b"laser bytes")
    return src


def test_inside_refuses_escapes(tmp_path):
    for bad in ("../x", "/abs", "a/../../b", "x\x00y", ""):
        with pytest.raises(ArchiveError):
            inside(tmp_path, bad)
    assert inside(tmp_path, "a/b") == (tmp_path / "a" / "b").resolve()
    assert slug("../../Etc/Passwd\x00") == "etc-passwd"
    assert folder_name("20240101-000000-abcdef", "../..", "") == "20240101-000000-abcdef"
    assert safe_suffix("x.B!N\x00") == ".bn" and safe_suffix("noext") == ".bin"


def _corrupt_garbage(db):
    db.write_bytes(b"this is not a database\x00" * 50)


def _corrupt_truncated(db):
    data = db.read_bytes()
    db.write_bytes(data[: len(data) // 3])


def _corrupt_header(db):
    data = bytearray(db.read_bytes())
    data[100:4096] = b"\xff" * (4096 - 100)   # the first page's b-tree header and cells
    db.write_bytes(bytes(data))


def _corrupt_empty(db):
    db.write_bytes(b"")


def _corrupt_deleted(db):
    db.unlink()


def _wrong_schema(db):
    db.unlink()
    conn = sqlite3.connect(db)
    conn.execute("CREATE TABLE something_else (x INTEGER)")
    conn.commit()
    conn.close()


def _newer_schema(db):
    conn = sqlite3.connect(db)
    conn.execute("UPDATE schema_version SET version = 999")
    conn.commit()
    conn.close()


def _missing_column(db):
    conn = sqlite3.connect(db)
    conn.execute("DROP TABLE parameters")
    conn.execute("CREATE TABLE parameters (measurement_id TEXT)")
    conn.commit()
    conn.close()


@pytest.mark.parametrize("damage", [_corrupt_garbage, _corrupt_truncated, _corrupt_header, _corrupt_empty,
                                    _corrupt_deleted, _wrong_schema, _newer_schema, _missing_column])
def test_a_damaged_index_is_rebuilt_from_the_folders_without_losing_a_measurement(tmp_path, measured, damage):
    archive, ids = fill(tmp_path, measured, 6)
    before = {e.id: e for e in archive.list()}
    damage(tmp_path / INDEX_FILE)
    fresh = Archive(tmp_path)
    after = {e.id: e for e in fresh.list()}
    assert after == before and set(after) == set(ids)
    assert any("index rebuilt" in n for n in fresh.notes), fresh.notes
    assert fresh.get(ids[3]).id == ids[3]
    conn = sqlite3.connect(tmp_path / INDEX_FILE)
    assert conn.execute("PRAGMA integrity_check").fetchone()[0] == "ok"
    assert conn.execute("SELECT version FROM schema_version").fetchone()[0] == CURRENT_VERSION


def test_folders_stored_or_removed_behind_the_index_are_noticed(tmp_path, measured):
    archive, ids = fill(tmp_path, measured, 3)
    removed = archive.get(ids[1]).folder
    # A program that crashed between writing the folder and indexing it: an index without the folder's row.
    conn = sqlite3.connect(tmp_path / INDEX_FILE)
    with conn:
        conn.execute("DELETE FROM measurements WHERE id = ?", (ids[0],))
    conn.close()
    for f in removed.iterdir():
        f.unlink()
    removed.rmdir()
    fresh = Archive(tmp_path)
    assert {e.id for e in fresh.list()} == {ids[0], ids[2]}
    assert any("1 added, 1 removed" in n for n in fresh.notes), fresh.notes


def test_rebuild_skips_an_unreadable_folder_and_keeps_the_others(tmp_path, measured):
    archive, ids = fill(tmp_path, measured, 3)
    broken = archive.get(ids[0]).folder / "measurement.json"
    broken.write_text("{ not json")
    report = archive.rebuild()
    assert report.indexed == 2 and len(report.skipped) == 1 and str(broken) in report.skipped[0]
    assert broken.exists()                       # never deleted
    assert {e.id for e in archive.list()} == set(ids[1:])


def test_an_index_of_schema_version_1_is_migrated_in_place(tmp_path, measured):
    archive, ids = fill(tmp_path, measured, 2)
    db = tmp_path / INDEX_FILE
    db.unlink()
    conn = sqlite3.connect(db)
    conn.execute("CREATE TABLE schema_version (version INTEGER NOT NULL)")
    conn.execute("INSERT INTO schema_version VALUES (1)")
    MIGRATIONS[0](conn)
    conn.execute("INSERT INTO measurements VALUES (?, ?, '2024-01-01T00:00:00Z', '2024-01-01T00:00:00Z', 'd', 's', "
                 "'o', 'st', 'green')", ("19990101-000000-abcdef", "a-folder-that-is-gone"))
    conn.commit()
    conn.close()
    fresh = Archive(tmp_path)
    entries = fresh.list()
    conn = sqlite3.connect(db)
    assert conn.execute("SELECT version FROM schema_version").fetchone()[0] == CURRENT_VERSION
    columns = {row[1] for row in conn.execute("PRAGMA table_info(measurements)")}
    assert "effects" in columns
    # Migrated, not rebuilt: the v1 row survived, then the folder sync replaced it by the folders' truth.
    assert not any("index rebuilt" in n for n in fresh.notes)
    assert {e.id for e in entries} == set(ids)


def test_measurement_json_alone_rebuilds_the_index_entry(tmp_path, measured):
    archive, (mid,) = fill(tmp_path, measured, 1)
    record = json.loads((archive.get(mid).folder / "measurement.json").read_text())
    for key in ("id", "folder", "driver", "serial", "operator", "station", "measured_at", "validity",
                "key_parameters"):
        assert key in record
    (tmp_path / INDEX_FILE).unlink()
    assert Archive(tmp_path).list()[0].as_json() == archive.list()[0].as_json()


def test_export_copies_the_folder(tmp_path, measured):
    archive, (mid,) = fill(tmp_path / "a", measured, 1)
    target = archive.export(mid, tmp_path / "out")
    assert sorted(p.name for p in target.iterdir()) == sorted(p.name for p in archive.get(mid).folder.iterdir())
    with pytest.raises(ArchiveError, match="already exists"):
        archive.export(mid, tmp_path / "out")


def test_compare_up_to_eight(tmp_path, measured):
    archive, ids = fill(tmp_path, measured, 3)
    c = compare(archive, ids)
    fs = next(r for r in c.rows if r.name == "fs")
    assert fs.display_unit == "Hz" and len(fs.values) == 3
    assert fs.deviation_percent == (0.0, 0.0, 0.0) and fs.spread == 0.0
    mms = next(r for r in c.rows if r.name == "Mms")
    assert mms.values[0] == pytest.approx(measured[1]["parameters"]["Mms"]["value"] * 1e3)
    with pytest.raises(ArchiveError, match="1 to 8"):
        compare(archive, ids * 3)
    with pytest.raises(ArchiveError, match="twice"):
        compare(archive, [ids[0], ids[0]])


def test_reading_a_missing_archive_creates_nothing(tmp_path):
    archive = Archive(tmp_path / "none")
    assert archive.list() == []
    with pytest.raises(ArchiveError, match="no archive"):
        archive.get("2024")
    assert not (tmp_path / "none").exists()


def test_meta_is_checked(tmp_path, measured):
    archive = Archive(tmp_path)
    with pytest.raises(ArchiveError, match="unknown key"):
        archive.store(measured[0], measured[1], {"colour": "red"})
    with pytest.raises(ArchiveError, match="ISO 8601"):
        archive.store(measured[0], measured[1], {"measured_at": "yesterday"})
    assert not any((tmp_path / FOLDERS).iterdir())     # nothing half-stored


def _age(path, seconds):
    """Set the modification time of a path and of what is in it `seconds` into the past."""
    when = time.time() - seconds
    for p in [*(path.iterdir() if path.is_dir() else ()), path]:
        os.utime(p, (when, when), follow_symlinks=False)


def test_leftovers_of_interrupted_programs_are_removed_once_an_hour_old(tmp_path, measured):
    archive, (mid,) = fill(tmp_path, measured, 1)
    folders, hour = tmp_path / FOLDERS, 3600
    made = {}
    for name in ("old", "fresh", "busy"):
        made[name] = folders / f".incoming-{name}"
        made[name].mkdir()
        (made[name] / "recording.wav").write_bytes(b"RIFF")
    _age(made["old"], 2 * hour)
    _age(made["busy"], 2 * hour)
    os.utime(made["busy"] / "recording.wav")                   # a copy still writing into an old folder
    rebuild_tmp = tmp_path / f".{INDEX_FILE}.4242.1.tmp"
    rebuild_tmp.write_bytes(b"half an index")
    _age(rebuild_tmp, 2 * hour)
    rebuild_journal = tmp_path / f".{INDEX_FILE}.4242.1.tmp-journal"     # SQLite's, of that half index
    rebuild_journal.write_bytes(b"a journal")
    _age(rebuild_journal, 2 * hour)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "keep").write_text("not the archive's")
    (folders / ".incoming-link").symlink_to(elsewhere)         # not ours to follow
    _age(folders / ".incoming-link", 2 * hour)

    opened = Archive(tmp_path)
    assert [e.id for e in opened.list()] == [mid]
    assert not made["old"].exists() and not rebuild_tmp.exists() and not rebuild_journal.exists()
    assert made["fresh"].exists() and made["busy"].exists() and (elsewhere / "keep").exists()
    assert any("removed 3 unfinished" in n for n in opened.notes), opened.notes
    assert not [p for p in folders.iterdir() if p.name.startswith((".removing-", ".clock-probe-"))]
    _age(made["fresh"], 2 * hour)
    Archive(tmp_path).rebuild()                                # a rebuild sweeps too
    assert not made["fresh"].exists() and made["busy"].exists()


def _leftover(folders, name, age_s):
    folder = folders / name
    folder.mkdir(parents=True)
    for file in ("recording.wav", "measurement.json"):
        (folder / file).write_bytes(b"x")
    _age(folder, age_s)
    return folder


def test_a_leftover_is_claimed_before_it_is_deleted_so_a_stalled_store_cannot_move_half_of_it_in(tmp_path,
                                                                                                 monkeypatch):
    folders = tmp_path / FOLDERS
    incoming = _leftover(folders, ".incoming-stalled", 7200)
    final = folders / "20240101-000000-abcdef"
    real_rmtree, store = shutil.rmtree, []

    def delete_while_the_store_wakes_up(path, *args, **kwargs):
        next(iter(sorted(path.iterdir()))).unlink()          # the deletion has begun ...
        try:
            os.rename(incoming, final)                       # ... when the store renames its folder into place
            store.append("renamed")
        except FileNotFoundError:
            store.append("failed")
        real_rmtree(path, *args, **kwargs)
    monkeypatch.setattr(shutil, "rmtree", delete_while_the_store_wakes_up)
    removed = sweep(folders, tmp_path, INDEX_FILE)
    monkeypatch.undo()
    assert store == ["failed"] and not final.exists()        # the store failed rather than keep half a folder
    assert removed == [".incoming-stalled"] and list(folders.iterdir()) == []


def test_the_age_of_a_leftover_is_taken_on_the_file_systems_clock(tmp_path, monkeypatch):
    folders = tmp_path / FOLDERS
    old = _leftover(folders, ".incoming-old", 7200)
    in_use = _leftover(folders, ".incoming-in-use", 0)
    # This machine's clock two hours ahead of the file server's: to it, a folder written just now looks 2 h old.
    real_time = time.time
    monkeypatch.setattr(time, "time", lambda: real_time() + 7200)
    removed = sweep(folders, tmp_path, INDEX_FILE)
    monkeypatch.undo()
    assert removed == [".incoming-old"] and not old.exists() and in_use.exists()


def test_an_archive_where_nothing_can_be_written_is_not_swept(tmp_path, monkeypatch):
    folders = tmp_path / FOLDERS
    old = _leftover(folders, ".incoming-old", 7200)
    real_open = os.open

    def read_only(path, flags, *args, **kwargs):     # tests run as root: chmod cannot make a folder read-only
        if flags & os.O_CREAT:
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(path))
        return real_open(path, flags, *args, **kwargs)
    monkeypatch.setattr(os, "open", read_only)
    removed = sweep(folders, tmp_path, INDEX_FILE)
    monkeypatch.undo()
    assert removed == [] and sorted(p.name for p in old.iterdir()) == ["measurement.json", "recording.wav"]


def test_what_an_interrupted_sweep_claimed_is_removed_a_minute_after_the_claim(tmp_path):
    folders = tmp_path / FOLDERS
    claimed = _leftover(folders, ".removing-0123abcd", 7200)   # old files, but renamed (claimed) just now
    now = time.time()
    assert sweep(folders, tmp_path, INDEX_FILE, now=now + 30) == [] and claimed.exists()
    assert sweep(folders, tmp_path, INDEX_FILE, now=now + 90) == [".removing-0123abcd"]
    assert not claimed.exists()


def test_a_listing_between_a_stores_rename_and_its_index_insert_is_no_failure(tmp_path, measured, monkeypatch):
    import analysis.archive.archive as archive_module
    archive, (first,) = fill(tmp_path, measured, 1)
    real_fsync_dir, listed = archive_module.fsync_dir, []

    def then_a_listing(path):     # the store has just renamed its folder into place; a GUI listing runs now
        real_fsync_dir(path)
        listing = Archive(tmp_path)
        listed.append(({e.id for e in listing.list()}, listing.notes))
    monkeypatch.setattr(archive_module, "fsync_dir", then_a_listing)
    second = archive.store(*measured, {"serial": "late"})
    monkeypatch.undo()
    assert listed == [({first, second}, ["index brought up to date with the folders: 1 added, 0 removed"])]
    assert archive.notes == []                               # the listing indexed it: the store is complete
    assert sorted(e.id for e in Archive(tmp_path).list()) == sorted([first, second])


def test_a_row_of_another_folder_under_the_stores_id_is_still_reported(tmp_path, measured, monkeypatch):
    import analysis.archive.archive as archive_module
    archive, (first,) = fill(tmp_path, measured, 1)
    real_fsync_dir = archive_module.fsync_dir

    def then_a_row_elsewhere(path):
        real_fsync_dir(path)
        (new,) = [p for p in path.iterdir() if not p.name.startswith(".") and not p.name.startswith(first)]
        with sqlite3.connect(tmp_path / INDEX_FILE) as conn:
            insert(conn, {**read_record(new), "folder": "someone-elses"})
    monkeypatch.setattr(archive_module, "fsync_dir", then_a_row_elsewhere)
    archive.store(*measured, {"serial": "late"})
    assert any("could not be updated (UNIQUE constraint failed" in n for n in archive.notes), archive.notes


def test_a_store_during_a_listings_sync_keeps_its_index_row(tmp_path, measured, monkeypatch):
    archive, (first,) = fill(tmp_path, measured, 1)
    real_scan, armed, stored = Index._folder_names, [True], []

    def scan_then_a_store(self):  # another thread stores a measurement just after this listing scanned the folders
        names = real_scan(self)
        if armed:
            armed.clear()
            stored.append(Archive(tmp_path).store(*measured, {"serial": "meanwhile"}))
        return names
    monkeypatch.setattr(Index, "_folder_names", scan_then_a_store)
    listing = Archive(tmp_path)
    listing.list()
    monkeypatch.undo()
    assert len(stored) == 1
    with sqlite3.connect(tmp_path / INDEX_FILE) as conn:     # the new row was not taken for a removed folder
        assert {row[0] for row in conn.execute("SELECT id FROM measurements")} == {first, *stored}
    assert listing.notes == []


@pytest.mark.parametrize("state", ["stale", "missing", "damaged"])
def test_a_read_only_archive_with_an_unusable_index_lists_from_the_folders(tmp_path, measured, state,
                                                                           monkeypatch):
    archive, ids = fill(tmp_path, measured, 3)
    index = tmp_path / INDEX_FILE
    if state == "stale":        # a store whose program died before it reached the index
        with sqlite3.connect(index) as conn:
            conn.execute("DELETE FROM measurements WHERE id = ?", (ids[1],))
    elif state == "missing":
        index.unlink()
    else:
        index.write_bytes(b"garbage" * 100)
    before = index.read_bytes() if index.exists() else None
    # As in a folder this user may not write (tests run as root: chmod cannot show it): SQLite opens every
    # index file read-only, so updating the index or writing a new one fails as it would there.
    monkeypatch.setattr(Index, "_open", lambda self, path=None: sqlite3.connect(
        f"file:{path or self.path}?mode=ro", uri=True, timeout=0.1))
    ro = Archive(tmp_path)
    assert {e.id for e in ro.list()} == set(ids)
    assert ro.get(ids[1]).id == ids[1]
    assert any("listed from the measurement folders" in n and "linpar archive rebuild" in n for n in ro.notes)
    assert (index.read_bytes() if index.exists() else None) == before      # nothing was written
    with pytest.raises(ArchiveError, match="cannot rebuild the index"):
        ro.rebuild()


def test_other_sqlite_errors_become_archive_errors_and_a_failed_index_update_loses_nothing(tmp_path, measured,
                                                                                           monkeypatch):
    archive, (mid,) = fill(tmp_path, measured, 1)
    def malformed(*args, **kwargs):
        raise sqlite3.DatabaseError("database disk image is malformed")
    monkeypatch.setattr(Index, "query", malformed)
    with pytest.raises(ArchiveError, match=r"index.sqlite: listing: database disk image is malformed.*rebuild"):
        Archive(tmp_path).list()
    monkeypatch.undo()
    import analysis.archive.archive as archive_module
    def locked(conn, record):
        raise sqlite3.OperationalError("database is locked")
    monkeypatch.setattr(archive_module, "insert", locked)
    second = archive.store(measured[0], measured[1], {"serial": "late"})
    assert any("could not be updated (database is locked)" in n for n in archive.notes)
    monkeypatch.undo()
    assert {e.id for e in Archive(tmp_path).list()} == {mid, second}     # the next opening indexes it


def test_layers_archive_loads_no_numpy_and_report_export_load_no_qt():
    import subprocess
    import sys
    code = ("import sys, analysis.archive, analysis.archive.index;"
            "assert 'numpy' not in sys.modules, 'numpy';"
            "import analysis.report.pdf, analysis.report.html, analysis.export, analysis.limits;"
            "bad = [m for m in sys.modules if m.split('.')[0] in ('PySide6', 'pyqtgraph', 'app', 'instruments')];"
            "assert not bad, bad;"
            "import matplotlib; assert 'qt' not in matplotlib.get_backend().lower()")
    subprocess.run([sys.executable, "-c", code], check=True)
