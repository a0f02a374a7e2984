"""measurement.json: the one file per folder from which the index can always be rebuilt.

    {"format": "linpar-measurement/1", "id", "folder", "measured_at", "stored_at",
     "driver", "serial", "operator", "station", "notes", "validity", "effects", "sd_m2",
     "key_parameters": {name: {"value", "std", "unit"}},   (SI)
     "qa": {"verdict", "limits_version", "limits_name"},   (optional: when the archive had limits)
     "files": {"recording": "recording.wav", "sidecar": "recording.json", "results": "results.json",
               "settings": "settings.json", "calibration": "calibration.json", "laser_stream": ...}}

Dates are ISO 8601 in UTC. No numpy here: `linpar archive list` stays fast.

A measurement.json is a file like any other: whatever it holds is checked
when it is read (`read_record`), and the rows of the index the same way
(`checked_entry`, `checked_parameter`): strings without control characters
(one line each, as the listing prints them), dates that are dates, numbers
that are finite and within analysis.bounds. What fails is reported and
skipped, never printed as it is.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Any

from analysis.archive.names import ArchiveError, check_id
from analysis.bounds import PARAMETER, SD, YEAR
from analysis.files import read_text
from analysis.text_boundary import CONTROL, one_line, shown

RECORD_FORMAT = "linpar-measurement/1"
RECORD_FILE = "measurement.json"
TEXT_FIELDS = ("driver", "serial", "operator", "station")
VALIDITY_STATES = ("green", "yellow", "red", "unknown")
# analysis.limits.judge_result's verdicts: each stored verdict names the limits version that judged it.
QA_VERDICTS = ("pass", "fail", "invalid", "not judged")


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
    verdict: str | None = None            # QA_VERDICTS, when limits judged it as it was stored
    limits_version: int | None = None     # the version of the archive's limits that judged it

    def as_json(self) -> dict:
        return {"id": self.id, "folder": self.folder, "measured_at": self.measured_at, "stored_at": self.stored_at,
                "driver": self.driver, "serial": self.serial, "operator": self.operator, "station": self.station,
                "validity": self.validity, "effects": list(self.effects), "parameters": self.parameters,
                "verdict": self.verdict, "limits_version": self.limits_version}


def entry_of(record: dict) -> Entry:
    qa = record.get("qa") or {}
    return Entry(record["id"], record["folder"], record["measured_at"], record["stored_at"],
                 *(record[k] for k in TEXT_FIELDS), record["validity"], tuple(record.get("effects", ())),
                 dict(record.get("key_parameters", {})), qa.get("verdict"), qa.get("limits_version"))


def checked_qa(verdict, version, where: str) -> tuple[str | None, int | None]:
    """A stored verdict and the limits version that judged it: both, or neither."""
    if verdict is None and version is None:
        return None, None
    if verdict not in QA_VERDICTS:
        raise ArchiveError(f"{where}: verdict: found {str(verdict)[:20]!r}, expected one of {', '.join(QA_VERDICTS)}")
    if isinstance(version, bool) or not isinstance(version, int) or not 1 <= version <= 2**31 - 1:
        raise ArchiveError(f"{where}: limits_version: found {str(version)[:20]!r}, expected a version number "
                           "(a whole number from 1)")
    return verdict, version


def one_line_text(value, where: str) -> str:
    """A string without control characters (line breaks, NUL, escapes): it is printed on one line."""
    return one_line(value, where, ArchiveError)


def iso_date(value, where: str) -> str:
    """An ISO 8601 date (or date and time) string, its year within analysis.bounds.YEAR."""
    text = one_line_text(value, where)
    try:
        when = datetime.fromisoformat(text)
    except ValueError:
        raise ArchiveError(f"{where}: {text[:40]!r} is not an ISO 8601 date") from None
    YEAR.check(when.year, where, ArchiveError)
    return text


def number_or_null(value, where: str, bound=PARAMETER) -> float | None:
    """None, or a finite number within `bound` (as float); ArchiveError otherwise."""
    return None if value is None else bound.check(value, where, ArchiveError)


def checked_parameter(p, where: str) -> dict[str, Any]:
    if not isinstance(p, dict):
        raise ArchiveError(f"{where}: expected an object with value, std and unit")
    return {"value": number_or_null(p.get("value"), f"{where}.value"),
            "std": number_or_null(p.get("std"), f"{where}.std"),
            "unit": one_line_text(p.get("unit", ""), f"{where}.unit")}


def checked_entry(values: dict[str, Any], where: str) -> dict[str, Any]:
    """The fields an Entry is made of, each checked (a record's or an index row's)."""
    try:
        check_id(values.get("id"))
    except ArchiveError as exc:
        raise ArchiveError(f"{where}: id: {exc}") from None
    for key in ("folder", *TEXT_FIELDS):
        one_line_text(values.get(key), f"{where}: {key}")
    for key in ("measured_at", "stored_at"):
        iso_date(values.get(key), f"{where}: {key}")
    if values.get("validity") not in VALIDITY_STATES:
        raise ArchiveError(f"{where}: validity: found {str(values.get('validity'))[:20]!r}, expected one of "
                           f"{', '.join(VALIDITY_STATES)}")
    effects = values.get("effects", [])
    if not isinstance(effects, (list, tuple)):
        raise ArchiveError(f"{where}: effects: expected a list of effect ids (strings)")
    for i, e in enumerate(effects):
        one_line_text(e, f"{where}: effects[{i}]")
    qa = values.get("qa")
    if qa is not None:
        if not isinstance(qa, dict):
            raise ArchiveError(f"{where}: qa: expected an object with verdict and limits_version")
        checked_qa(qa.get("verdict"), qa.get("limits_version"), f"{where}: qa")
        one_line_text(qa.get("limits_name", ""), f"{where}: qa.limits_name")
    return values


def _flagged_text(holder: dict, key, where: str, flags: list[str]) -> None:
    """holder[key] with refused characters shown visibly (\\t, \\x1b), and a flag saying so: a name that
    broke the rule when it was stored (by an older linpar, or another program) is shown, never dropped."""
    value = holder.get(key) if isinstance(holder, dict) else None
    if isinstance(value, str) and CONTROL.search(value):
        holder[key] = shown(value)
        flags.append(f"{where} held characters that are not text; shown escaped: {holder[key][:60]}")


def _flagged_number(holder: dict, key, where: str, bound, flags: list[str]) -> None:
    """holder[key] set to None, with a flag, when it is not a number within `bound`."""
    if not isinstance(holder, dict) or holder.get(key) is None:
        return
    try:
        bound.check(holder[key], where, ArchiveError)
    except ArchiveError as exc:
        holder[key] = None
        flags.append(f"{exc}; not shown")


def _flag_bad_values(doc: dict) -> list[str]:
    """The record's names and numbers that would make it unreadable, made readable; what was changed."""
    flags: list[str] = []
    for key in (*TEXT_FIELDS, "notes"):
        _flagged_text(doc, key, key, flags)
    if isinstance(doc.get("qa"), dict):
        _flagged_text(doc["qa"], "limits_name", "qa.limits_name", flags)
    if isinstance(doc.get("effects"), list):
        for i in range(len(doc["effects"])):
            _flagged_text(doc["effects"], i, f"effects[{i}]", flags)
    params = doc.get("key_parameters")
    if isinstance(params, dict):
        for name, p in params.items():
            for key in ("value", "std"):
                _flagged_number(p, key, f"key_parameters.{shown(str(name))}.{key}", PARAMETER, flags)
            _flagged_text(p, "unit", f"key_parameters.{shown(str(name))}.unit", flags)
    _flagged_number(doc, "sd_m2", "sd_m2", SD, flags)
    return flags


def read_record(folder: Path) -> dict:
    """The checked measurement.json of a folder; ArchiveError naming the file and key otherwise.

    A name or number that breaks the rules but does not make the record unusable (the id, the folder,
    the dates and the files do) is shown flagged: the record's "flags" list says what was changed.
    """
    path = folder / RECORD_FILE
    text = read_text(path, "archive", "a measurement record (JSON)", ArchiveError)
    try:
        doc = json.loads(text)
    except ValueError as exc:       # not JSON, or an integer of more digits than Python converts
        raise ArchiveError(f"{path}: not readable JSON ({exc})") from None
    except RecursionError:
        raise ArchiveError(f"{path}: not readable JSON (nested too deeply)") from None
    try:
        json.dumps(doc, ensure_ascii=False).encode("utf-8")
    except UnicodeEncodeError:
        raise ArchiveError(f"{path}: a string holds half of a UTF-16 surrogate pair, expected Unicode text") from None
    if not isinstance(doc, dict) or doc.get("format") != RECORD_FORMAT:
        raise ArchiveError(f"{path}: format: expected {RECORD_FORMAT!r}")
    flags = _flag_bad_values(doc)
    checked_entry(doc, str(path))
    if doc["folder"] != folder.name:
        raise ArchiveError(f"{path}: folder: {doc['folder']!r} but the file is in {folder.name!r}")
    if "notes" in doc:
        one_line_text(doc["notes"], f"{path}: notes")
    params = doc.get("key_parameters", {})
    if not isinstance(params, dict):
        raise ArchiveError(f"{path}: key_parameters: expected an object of objects")
    doc["key_parameters"] = {one_line_text(name, f"{path}: key_parameters"):
                             checked_parameter(p, f"{path}: key_parameters.{name}") for name, p in params.items()}
    files = doc.get("files", {})
    if not isinstance(files, dict):
        raise ArchiveError(f"{path}: files: expected an object")
    for role, name in files.items():
        one_line_text(role, f"{path}: files")
        one_line_text(name, f"{path}: files.{role}")
    doc["sd_m2"] = number_or_null(doc.get("sd_m2"), f"{path}: sd_m2", SD)
    doc.pop("flags", None)          # what the file says of itself is not a finding
    if flags:
        doc["flags"] = flags
    return doc
