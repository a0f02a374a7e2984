"""The measurement archive: one folder per measurement and an SQLite index over them.

    root/
      index.sqlite                         the index (a cache: rebuilt from the folders when needed)
      measurements/
        20240501-120301-3fa2c1-paper-sn42/ one folder per measurement, named by generated id (+ a slug)
          measurement.json                 everything the index holds (analysis.archive.record)
          recording.wav, recording.json    the recording, byte for byte as it was read
          results.json                     the analysis (analysis.archive.results)
          settings.json, calibration.json  what the caller gave (and the recording's "capture" data)
          laser.<ext>                      the raw laser stream, when there is one

A folder is written complete under a hidden temporary name and renamed into
place, so the archive never holds half a measurement; only then is it added
to the index (unless a listing meanwhile found the folder and added it).
Nothing in a folder is code: JSON, WAV and the raw laser bytes.
"""
from __future__ import annotations

import json
import os
import shutil
import sqlite3
import tempfile
import uuid
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Mapping

from analysis.archive.atomic import DIR_MODE, FILE_MODE, fsync_dir, write_atomic
from analysis.archive.folder_qa import FolderQA
from analysis.archive.index import Filter, Index, RebuildReport, insert
from analysis.archive.leftovers import INCOMING_PREFIX, REMOVING_PREFIX
from analysis.archive.limits_store import judged
from analysis.archive.names import (ArchiveError, check_id, check_id_prefix, clean_text, folder_name, inside,
                                    new_measurement_id, safe_suffix)
from analysis.archive.record import RECORD_FILE, RECORD_FORMAT, TEXT_FIELDS, Entry, entry_of, read_record
from analysis.archive.schema import KEY_PARAMETERS
from analysis.bounds import YEAR
from analysis.config_folder import data_folder, overridden
from analysis.files import read_text, regular_file
from analysis.session import recording_header

MeasurementId = str
FOLDERS = "measurements"
RESULTS_FILE = "results.json"
OWN_LIMITS = object()       # store(judge_with=...): judge with the archive's newest limits version


def default_root() -> Path:
    """$LINPAR_ARCHIVE, else the archive folder in linpar's data folder (analysis.config_folder)."""
    return overridden("LINPAR_ARCHIVE") or data_folder() / "archive"


@dataclass(frozen=True)
class MeasurementMeta:
    """Who measured what, where and when; settings and calibration as the measuring program had them."""

    driver: str = ""                 # default: the recording's driver name
    serial: str = ""
    operator: str = ""
    station: str = ""
    measured_at: str | None = None   # ISO 8601; default: the time of storing
    notes: str = ""
    settings: Mapping[str, Any] = field(default_factory=dict)
    calibration: Mapping[str, Any] = field(default_factory=dict)

    @classmethod
    def coerce(cls, meta) -> "MeasurementMeta":
        if meta is None:
            return cls()
        if isinstance(meta, cls):
            return meta
        if isinstance(meta, Mapping):
            unknown = set(meta) - set(cls.__dataclass_fields__)
            if unknown:
                raise ArchiveError(f"meta: unknown key(s) {sorted(unknown)}; expected {sorted(cls.__dataclass_fields__)}")
            return cls(**meta)
        raise ArchiveError(f"meta: expected a MeasurementMeta or a mapping, found {type(meta).__name__}")


@dataclass(frozen=True)
class Measurement:
    """One stored measurement: its record and where its files are."""

    entry: Entry
    folder: Path
    record: dict

    @property
    def id(self) -> MeasurementId:
        return self.entry.id

    def path(self, role: str) -> Path | None:
        """The file of a role ('recording', 'sidecar', 'results', 'settings', 'calibration', 'laser_stream')."""
        name = self.record.get("files", {}).get(role)
        return inside(self.folder, name) if isinstance(name, str) else None

    def load_json(self, role: str) -> dict:
        path = self.path(role)
        if path is None:
            return {}
        text = read_text(path, "archive", f"the measurement's {role} (JSON)", ArchiveError)
        try:
            return json.loads(text)
        except ValueError as exc:
            raise ArchiveError(f"{path}: not readable JSON ({exc})") from None
        except RecursionError:
            raise ArchiveError(f"{path}: not readable JSON (nested too deeply)") from None

    def result(self):
        """The analysis as stored (analysis.archive.results.StoredResult)."""
        from analysis.archive.results import ResultsFormatError, StoredResult
        if self.path("results") is None:
            raise ArchiveError(f"{self.folder / RECORD_FILE}: files.results: missing, expected the name of the "
                               f"measurement's results file (results.json)")
        try:
            return StoredResult.from_json(self.load_json("results"))
        except ResultsFormatError as exc:
            raise ArchiveError(f"{self.path('results')}: {exc}") from None

    def recording_path(self) -> Path | None:
        return self.path("recording")


def _json_bytes(doc: Any) -> bytes:
    return (json.dumps(doc, indent=1, ensure_ascii=False, allow_nan=False, default=_jsonable) + "\n").encode()


def _jsonable(value):
    if isinstance(value, Mapping):
        return dict(value)
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"{type(value).__name__} cannot be stored as JSON")


def overall_of(validity: Mapping) -> str:
    """The overall light of a results document's "validity" (ArchiveError when the object cannot be read)."""
    from analysis.validity.result import ResultValidity, ResultValidityError
    try:
        return str(ResultValidity.from_json(validity).overall)
    except ResultValidityError as exc:
        raise ArchiveError(f"result: {exc}") from None


def _iso(text: str | None, field_name: str, naive_is_utc: bool = False) -> str | None:
    """The date as the archive writes it (UTC, seconds, 'Z'); ArchiveError when it is none.

    A time without its UTC offset is refused (naive_is_utc False): a measuring station's clock is local, and
    reading 08:00 at a station on UTC+1 as UTC dates the measurement an hour late in a line's shared archive,
    silently. The user adds the offset (or Z); linpar never guesses it."""
    if text is None:
        return None
    try:
        when = datetime.fromisoformat(str(text))
    except ValueError:
        raise ArchiveError(f"meta.{field_name}: {text!r} is not an ISO 8601 date or time") from None
    if when.tzinfo is None and not naive_is_utc:
        raise ArchiveError(f"meta.{field_name}: {text!r} has no UTC offset, and a time without one is hours off "
                           f"at any station not on UTC: add it ({when:%Y-%m-%dT%H:%M:%S}+01:00 for UTC+1, or Z "
                           "for UTC)")
    if when.tzinfo is None:
        when = when.replace(tzinfo=timezone.utc)
    YEAR.check(when.year, f"meta.{field_name} ({text})", ArchiveError)
    # 9999-12-31T23:59:59-05:00 is in the year 10000 in UTC: the bound keeps the conversion in range.
    return when.astimezone(timezone.utc).isoformat(timespec="seconds").replace("+00:00", "Z")


def checked_measured_at(text: str | None) -> str | None:
    """A measurement time given by the user (--measured-at, meta.measured_at), checked: ArchiveError unless it
    is an ISO 8601 time with its UTC offset."""
    return _iso(text, "measured_at")


def _sidecar_date(text: str | None) -> str | None:
    """The sidecar's session date as the archive writes dates; None (the time of storing) when it is no date.
    A sidecar date without an offset is read as UTC, as linpar read it before (its format asks for one)."""
    try:
        return _iso(text, "measured_at", naive_is_utc=True)
    except ArchiveError:
        return None


def _share(folder: Path) -> None:
    """mkdtemp and mkstemp make private files; an archive is shared by the people at the station."""
    os.chmod(folder, DIR_MODE)
    for item in folder.iterdir():
        os.chmod(item, FILE_MODE)


class Archive(FolderQA):
    def __init__(self, root: str | Path | None = None):
        self.root = Path(root) if root is not None else default_root()
        self.folders = self.root / FOLDERS
        self._index = Index(self.root, self.folders)

    @property
    def location(self) -> str:
        return str(self.root)

    @property
    def notes(self) -> list[str]:
        """What opening the index had to repair (a rebuild, folders added), for the user to see."""
        return self._index.notes

    def _connect(self):
        try:
            self.folders.mkdir(parents=True, exist_ok=True)
        except OSError:
            pass       # a read-only archive: the index says so, or lists what there is
        return self._index.connect()

    @contextmanager
    def _index_errors(self, doing: str):
        """An SQLite error of the index as an ArchiveError that says what to do (no traceback for users)."""
        try:
            yield
        except sqlite3.Error as exc:
            raise ArchiveError(f"{self._index.path}: {doing}: {exc} (the index is a cache of the folders: "
                               f"'linpar archive rebuild' makes it anew)") from None

    # --- storing --------------------------------------------------------------------

    def store(self, recording, result, meta=None, laser_stream: str | Path | None = None,
              now: datetime | None = None, judge_with=OWN_LIMITS) -> MeasurementId:
        """Store a measurement; return its id.

        recording: a path (NAME, NAME.wav or NAME.json; copied byte for byte)
        or an analysis.recording.format.Recording (written as float32). result: an
        analysis.pipeline.AnalysisResult or its results document (a dict, as
        analysis.archive.results.results_document makes). meta: MeasurementMeta or a dict.
        When the archive holds limits, the record keeps the verdict of its newest version and that
        version's number (`judge_with`: another analysis.archive.limits_store.LimitsVersion, or None).
        """
        from analysis.archive.results import results_document
        from analysis.recording.format import Recording, read_recording, recording_paths, write_recording
        meta = MeasurementMeta.coerce(meta)
        rec_obj = recording if isinstance(recording, Recording) else read_recording(recording)
        doc = result if isinstance(result, Mapping) else results_document(result, rec_obj)
        for key in ("parameters", "model", "validity"):
            if not isinstance(doc.get(key), Mapping):
                raise ArchiveError(f"result: {key}: expected an object (a results document)")

        stored_at = (now or datetime.now(timezone.utc)).astimezone(timezone.utc)
        mid = new_measurement_id(stored_at)
        # What the caller does not say, the recording's sidecar does (analysis.session): who, where, when.
        traced = recording_header(rec_obj)
        text = {k: clean_text(getattr(meta, k) or traced.get(k, ""), k) for k in TEXT_FIELDS}
        name = folder_name(mid, text["driver"], text["serial"])
        self.folders.mkdir(parents=True, exist_ok=True)
        measured_at = _iso(meta.measured_at, "measured_at") or _sidecar_date(traced.get("measured_at"))
        final = inside(self.folders, name)
        if final.exists():
            raise ArchiveError(f"{final}: already exists")

        settings = {**dict(doc.get("settings") or {}), **dict(meta.settings)}
        calibration = dict(meta.calibration)
        extra = dict(rec_obj.extra or {})
        for key in ("calibration", "capture", "audio_capture"):
            if key in extra and key not in calibration:
                calibration[key] = extra[key]
        files = {"recording": "recording.wav", "sidecar": "recording.json", "results": RESULTS_FILE,
                 "settings": "settings.json", "calibration": "calibration.json"}
        if laser_stream is not None:
            # /dev/zero would be copied forever, a FIFO block: only a regular file within its size limit.
            regular_file(laser_stream, "laser-stream", "the raw laser stream of the measurement", ArchiveError)
            files["laser_stream"] = "laser" + safe_suffix(str(laser_stream))
        params = doc["parameters"]
        record = {
            "format": RECORD_FORMAT, "id": mid, "folder": name,
            "measured_at": measured_at or stored_at.isoformat(timespec="seconds").replace("+00:00", "Z"),
            "stored_at": stored_at.isoformat(timespec="seconds").replace("+00:00", "Z"),
            **text, "notes": clean_text(meta.notes, "notes", 2000),
            "validity": overall_of(doc["validity"]),
            "effects": list(doc["model"].get("effects", [])), "sd_m2": doc.get("sd_m2"),
            "key_parameters": {k: {"value": params[k].get("value"), "std": params[k].get("std"),
                                   "unit": params[k].get("unit", "")} for k in KEY_PARAMETERS if k in params},
            "files": files,
        }
        qa = judged(doc, self.limits() if judge_with is OWN_LIMITS else judge_with)
        if qa is not None:
            record["qa"] = qa
        with self._index_errors("opening the index"):
            conn = self._connect()
        tmp = Path(tempfile.mkdtemp(dir=self.folders, prefix=INCOMING_PREFIX))
        try:
            if isinstance(recording, Recording):
                write_recording(tmp / "recording", recording)
            else:
                for src, dst in zip(recording_paths(recording), ("recording.wav", "recording.json")):
                    shutil.copyfile(src, tmp / dst)
            if laser_stream is not None:
                shutil.copyfile(laser_stream, tmp / files["laser_stream"])
            write_atomic(tmp / RESULTS_FILE, _json_bytes(doc))
            write_atomic(tmp / "settings.json", _json_bytes(settings))
            write_atomic(tmp / "calibration.json", _json_bytes(calibration))
            write_atomic(tmp / RECORD_FILE, _json_bytes(record))     # last: a folder with it is complete
            _share(tmp)
            os.rename(tmp, final)
            fsync_dir(self.folders)
        except BaseException:
            conn.close()
            shutil.rmtree(tmp, ignore_errors=True)
            raise
        try:
            try:
                with conn:   # a crash before this line is repaired by the next open (folders vs index)
                    insert(conn, record)
            except sqlite3.IntegrityError:
                # A listing meanwhile (Index._sync, another thread or program) may have found the folder
                # and indexed it: then the row is this one, and there is nothing left to do.
                if conn.execute("SELECT folder FROM measurements WHERE id = ?", (mid,)).fetchone() != (name,):
                    raise
        except sqlite3.Error as exc:
            # The folder is in place, so the measurement is stored: the next open adds it to the index.
            self._index.notes.append(f"stored {mid}, but the index {self._index.path} could not be updated "
                                     f"({exc}): the next opening of the archive adds it")
        finally:
            conn.close()
        return mid

    # --- reading ----------------------------------------------------------------------

    def list(self, flt: Filter | None = None, **kwargs) -> list[Entry]:
        """Measurements, newest first. Filter fields may also be given as keywords (driver='xyz', limit=10)."""
        flt = flt or Filter(**kwargs)
        if not self.root.is_dir():
            return []        # reading never creates an archive
        with self._index_errors("listing"):
            conn = self._connect()
            try:
                return self._index.query(conn, flt)
            finally:
                conn.close()

    def resolve(self, id_or_prefix: str) -> tuple[MeasurementId, str]:
        """(id, folder) of the one measurement whose id is, or starts with, the text."""
        check_id_prefix(id_or_prefix)
        if not self.root.is_dir():
            raise ArchiveError(f"no archive at {self.root} (store a measurement first, or give --root)")
        with self._index_errors(f"looking up {id_or_prefix!r}"):
            conn = self._connect()
            try:
                found = self._index.matching_ids(conn, id_or_prefix)
            finally:
                conn.close()
        if not found:
            raise ArchiveError(f"no measurement {id_or_prefix!r} in the archive {self.root}")
        if len(found) > 1:
            shown = ", ".join(f[0] for f in found[:5]) + (" ..." if len(found) > 5 else "")
            raise ArchiveError(f"{id_or_prefix!r} matches {len(found)} measurements ({shown}): give more of the id")
        return found[0]

    def get(self, id_or_prefix: str) -> Measurement:
        mid, folder = self.resolve(id_or_prefix)
        path = inside(self.folders, folder)
        record = read_record(path)
        if record["id"] != check_id(mid):
            raise ArchiveError(f"{path / RECORD_FILE}: id {record['id']!r}, but the index says {mid!r}: "
                               "run 'linpar archive rebuild'")
        return Measurement(entry_of(record), path, record)

    def rebuild(self) -> RebuildReport:
        self.folders.mkdir(parents=True, exist_ok=True)
        self._index.sweep_leftovers()
        try:
            return self._index.rebuild()
        except sqlite3.Error as exc:
            raise ArchiveError(f"{self._index.path}: cannot rebuild the index: {exc} (it is written beside the "
                               f"old one: may this user write to {self.root}?)") from None

    def export(self, id_or_prefix: str, directory: str | Path) -> Path:
        """Copy a measurement's folder into `directory` (made if missing); return the copy's path."""
        return export_folder(self.get(id_or_prefix).folder, directory)

    def discard(self, mid: MeasurementId) -> None:
        """Remove a measurement: for a station's local queue (analysis.archive.pg.outbox), once the server has it.

        The folder is renamed away first (one step: it is there or it is not), then deleted; a crash in
        between leaves a .removing-* folder that the next opening sweeps away, and an index row that the
        next opening drops because its folder is gone.
        """
        mid, folder = self.resolve(mid)
        path = inside(self.folders, folder)
        gone = path.with_name(f"{REMOVING_PREFIX}{uuid.uuid4().hex}")
        os.rename(path, gone)
        shutil.rmtree(gone, ignore_errors=True)
        with self._index_errors(f"removing {mid} from the index"):
            conn = self._connect()
            try:
                with conn:
                    conn.execute("DELETE FROM measurements WHERE id = ?", (mid,))
            finally:
                conn.close()


def export_folder(folder: Path, directory: str | Path) -> Path:
    """Copy a measurement's folder (its regular files) into `directory` as a complete folder, or not at all."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    target = directory / folder.name
    if target.exists():
        raise ArchiveError(f"{target}: already exists; choose another directory")
    tmp = Path(tempfile.mkdtemp(dir=directory, prefix=f".{folder.name}."))
    try:
        for item in folder.iterdir():
            if item.is_file() and not item.is_symlink() and not item.name.startswith("."):
                shutil.copy2(item, tmp / item.name)
        _share(tmp)
        os.rename(tmp, target)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return target
