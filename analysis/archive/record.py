"""measurement.json: the one file per folder from which the index can always be rebuilt.

    {"format": "linpar-measurement/1", "id", "folder", "measured_at", "stored_at",
     "driver", "serial", "operator", "station", "notes", "validity", "effects", "sd_m2",
     "key_parameters": {name: {"value", "std", "unit"}},   (SI)
     "files": {"recording": "recording.wav", "sidecar": "recording.json", "results": "results.json",
               "settings": "settings.json", "calibration": "calibration.json", "laser_stream": ...}}

Dates are ISO 8601 in UTC. No numpy here: `linpar archive list` stays fast.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from analysis.archive.names import ArchiveError, check_id

RECORD_FORMAT = "linpar-measurement/1"
RECORD_FILE = "measurement.json"
TEXT_FIELDS = ("driver", "serial", "operator", "station")


@dataclass(frozen=True)
class Entry:
    """One measurement as the index lists it."""

    id: str
    folder: str
    measured_at: str
    stored_at: str
    driver: str
    serial: str
    operator: str
    station: str
    validity: str
    effects: tuple[str, ...] = ()
    parameters: dict[str, dict[str, Any]] = field(default_factory=dict)   # name -> {value, std, unit} (SI)

    def as_json(self) -> dict:
        return {"id": self.id, "folder": self.folder, "measured_at": self.measured_at, "stored_at": self.stored_at,
                "driver": self.driver, "serial": self.serial, "operator": self.operator, "station": self.station,
                "validity": self.validity, "effects": list(self.effects), "parameters": self.parameters}


def entry_of(record: dict) -> Entry:
    return Entry(record["id"], record["folder"], record["measured_at"], record["stored_at"],
                 *(record[k] for k in TEXT_FIELDS), record["validity"], tuple(record.get("effects", ())),
                 dict(record.get("key_parameters", {})))


def _number_or_null(value) -> bool:
    if value is None:
        return True
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        float(value)
    except OverflowError:       # an integer beyond the float range
        return False
    return True


def read_record(folder: Path) -> dict:
    """The checked measurement.json of a folder; ArchiveError naming the file and key otherwise."""
    path = folder / RECORD_FILE
    try:
        if path.exists() and not path.is_file():    # a FIFO or a device would block the read forever
            raise ArchiveError(f"{path}: not a regular file")
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ArchiveError(f"{path}: missing") from None
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ArchiveError(f"{path}: not readable JSON ({exc})") from None
    except RecursionError:
        raise ArchiveError(f"{path}: not readable JSON (nested too deeply)") from None
    try:
        json.dumps(doc, ensure_ascii=False).encode("utf-8")
    except UnicodeEncodeError:
        raise ArchiveError(f"{path}: a string holds half of a UTF-16 surrogate pair, expected Unicode text") from None
    if not isinstance(doc, dict) or doc.get("format") != RECORD_FORMAT:
        raise ArchiveError(f"{path}: format: expected {RECORD_FORMAT!r}")
    for key in ("id", "folder", "measured_at", "stored_at", "validity", *TEXT_FIELDS):
        if not isinstance(doc.get(key), str):
            raise ArchiveError(f"{path}: {key}: expected a string")
    try:
        check_id(doc["id"])
    except ArchiveError as exc:
        raise ArchiveError(f"{path}: id: {exc}") from None
    if doc["folder"] != folder.name:
        raise ArchiveError(f"{path}: folder: {doc['folder']!r} but the file is in {folder.name!r}")
    params = doc.get("key_parameters", {})
    if not isinstance(params, dict) or not all(isinstance(p, dict) for p in params.values()):
        raise ArchiveError(f"{path}: key_parameters: expected an object of objects")
    for name, p in params.items():
        for key in ("value", "std"):
            if not _number_or_null(p.get(key)):
                raise ArchiveError(f"{path}: key_parameters.{name}.{key}: expected a number or null")
    if not isinstance(doc.get("files", {}), dict):
        raise ArchiveError(f"{path}: files: expected an object")
    effects = doc.get("effects", [])
    if not isinstance(effects, list) or not all(isinstance(e, str) for e in effects):
        raise ArchiveError(f"{path}: effects: expected a list of effect ids (strings)")
    return doc
