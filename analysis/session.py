"""Who measured what, where, when and with which software: the traceability of a measurement.

The recording's sidecar holds it under "session" (docs/recording-format.md):

    "session": {"operator": "A. Tester", "station": "bench-2", "template": "woofer",
                "measured_at": "2025-05-01T10:20:30Z", "software": "linpar 0.1.0"}

and the driver's serial number under "driver". From there it goes into the
archive's record, every report and every export, through one header
(`trace_header`): a report of the recording, of its archived copy or of an
export shows the same lines.
"""
from __future__ import annotations

from datetime import datetime, timezone
from importlib import metadata
from typing import Any, Mapping

from analysis.text_boundary import cleaned, spreadsheet_comment

SESSION_KEY = "session"
SESSION_FIELDS = ("operator", "station", "template", "measured_at", "software")
# The header every report and export carries, in this order.
HEADER_KEYS = ("driver", "serial", "measured_at", "operator", "station", "template", "software")
MAX_TEXT = 200


def software() -> str:
    """'linpar 0.1.0': the name and version of the installed package."""
    try:
        return f"linpar {metadata.version('linpar')}"
    except metadata.PackageNotFoundError:       # run from a source tree that was never installed
        return "linpar (version unknown: not installed)"


def utc_now() -> str:
    """The time now as the archive writes dates: ISO 8601 in UTC, to the second."""
    return datetime.now(timezone.utc).isoformat(timespec="seconds").replace("+00:00", "Z")


def new_session(operator: str = "", station: str = "", template: str = "", measured_at: str | None = None) -> dict:
    """The "session" object of a recording about to be made."""
    doc = {"operator": operator, "station": station, "template": template,
           "measured_at": measured_at or utc_now(), "software": software()}
    return {k: v for k, v in doc.items() if v}


def _text(value: Any) -> str:
    """One line of text from a file's value, or '' when it is not a string (a file is never trusted)."""
    if not isinstance(value, str):
        return ""
    return cleaned(value, MAX_TEXT)


def session_of(recording) -> dict:
    """The recording's "session", its known fields as one-line strings (empty ones left out)."""
    doc = (recording.extra or {}).get(SESSION_KEY) if recording is not None else None
    if not isinstance(doc, Mapping):
        return {}
    return {k: _text(doc.get(k)) for k in SESSION_FIELDS if _text(doc.get(k))}


def trace_header(driver: Mapping | None, session: Mapping | None) -> dict:
    """The header of reports and exports from a recording's "driver" and "session" objects."""
    driver = driver if isinstance(driver, Mapping) else {}
    session = session if isinstance(session, Mapping) else {}
    header = {"driver": _text(driver.get("name")), "serial": _text(driver.get("serial"))}
    header.update({k: _text(session.get(k)) for k in SESSION_FIELDS})
    return {k: header[k] for k in HEADER_KEYS if header.get(k)}


def recording_header(recording) -> dict:
    """trace_header of a Recording."""
    return trace_header(recording.driver, session_of(recording))


def trace_items(header: Mapping) -> list[str]:
    """A header as 'key value' items, in HEADER_KEYS order."""
    return [f"{k.replace('_', ' ')} {header[k]}" for k in HEADER_KEYS if header.get(k)]


def trace_line(header: Mapping) -> str:
    """A header on one line, for the comment lines of curve files."""
    return ", ".join(trace_items(header))


def comment_lines(title: str, header: Mapping, marker: str = "#") -> list[str]:
    """Comment lines above a table (CSV exports): what it is, the header one item a line, the exporting software;
    the names in them never a spreadsheet's formula (analysis.text_boundary.spreadsheet_comment)."""
    return [spreadsheet_comment(f"{marker} {line}")
            for line in (title, *trace_items(header), f"exported by {software()}")]
