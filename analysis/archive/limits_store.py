"""Limits kept in the archive: numbered versions, never changed once stored, and the verdict each one gives.

A limits version is a linpar-limits/1 document (analysis.limits) with a
number, a note, who stored it and when. A new version never replaces an old
one: every stored verdict names the version that judged it, so a verdict can
always be traced to the limits that made it, whatever was stored since.

Both back ends keep versions this way (the folder archive as files
limits/v0001.json, PostgreSQL in the table limits_versions); this module is
what they share: the version object, the checks of a document, the verdict.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from analysis.archive.names import ArchiveError
from analysis.archive.record import one_line_text
from analysis.text_boundary import shown

VERSION_FORMAT = "linpar-limits-version/1"
MAX_NOTE = 2000


@dataclass(frozen=True)
class LimitsVersion:
    version: int
    name: str
    document: dict          # the linpar-limits/1 document as stored
    note: str
    created_at: str         # ISO 8601, UTC
    created_by: str         # the database user (PostgreSQL) or the operating system's user (a folder)

    @property
    def label(self) -> str:
        return f"limits v{self.version} ({self.name})"

    def limits(self):
        """The analysis.limits.Limits of this version (its document was checked when it was stored)."""
        from analysis.limits import parse_limits
        return parse_limits(self.document, json.dumps(self.document, indent=1), Path(self.label))

    def as_json(self) -> dict:
        return {"version": self.version, "name": self.name, "note": self.note, "created_at": self.created_at,
                "created_by": self.created_by, "limits": self.document}


def checked_document(document: Any, where: str = "limits") -> tuple[dict, str]:
    """(the document, its name) when it is a linpar-limits/1 document analysis.limits can use; else LimitsError."""
    from analysis.limits import LimitsError, parse_limits
    if not isinstance(document, Mapping):
        raise LimitsError(f"{where}: expected a JSON object (a linpar-limits/1 document)")
    doc = json.loads(json.dumps(document, allow_nan=False))     # plain JSON types, a copy of its own
    return doc, parse_limits(doc, json.dumps(doc, indent=1), Path(where)).name


def checked_note(note: str | None) -> str:
    note = "" if note is None else str(note)
    if len(note) > MAX_NOTE:
        raise ArchiveError(f"the note of a limits version: {len(note)} characters, at most {MAX_NOTE}")
    return one_line_text(note, "the note of a limits version")


def version_of_json(doc: Any, where: str) -> LimitsVersion:
    """A LimitsVersion from its stored JSON (a file or a database row); ArchiveError naming `where` otherwise."""
    if not isinstance(doc, dict) or doc.get("format") != VERSION_FORMAT:
        raise ArchiveError(f"{where}: format: expected {VERSION_FORMAT!r}")
    version = doc.get("version")
    if isinstance(version, bool) or not isinstance(version, int) or version < 1:
        raise ArchiveError(f"{where}: version: expected a whole number from 1")
    stored = doc.get("limits")
    if isinstance(stored, dict) and isinstance(stored.get("name"), str):
        # A name stored before linpar refused control characters in it: shown escaped, the version still usable.
        stored = {**stored, "name": shown(stored["name"])}
    try:
        document, name = checked_document(stored, f"{where}: limits")
    except ValueError as exc:       # LimitsError
        raise ArchiveError(str(exc)) from None
    return LimitsVersion(version, name, document, one_line_text(doc.get("note", ""), f"{where}: note"),
                         one_line_text(doc.get("created_at", ""), f"{where}: created_at"),
                         one_line_text(doc.get("created_by", ""), f"{where}: created_by"))


def version_json(v: LimitsVersion) -> dict:
    return {"format": VERSION_FORMAT, **v.as_json()}


def judged(results_document: Mapping, version: LimitsVersion | None) -> dict | None:
    """The "qa" entry of a measurement record: its verdict under `version` (None: no limits, no verdict)."""
    if version is None:
        return None
    from analysis.archive.results import StoredResult
    from analysis.limits import judge_result
    stored = StoredResult.from_json(results_document)
    from analysis.validity.fit import STORED_VERDICT
    verdict = judge_result(version.limits(), stored.parameters, stored.validity)["verdict"]
    # An uncertain unit (an interval across a limit) is stored as "not judged": measured again, in no yield.
    return {"verdict": STORED_VERDICT.get(verdict, verdict), "limits_version": version.version,
            "limits_name": version.name}
