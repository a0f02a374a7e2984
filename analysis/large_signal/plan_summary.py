"""A large-signal plan's summary, NAME.large-signal.json: which of its steps' recordings can be identified.

instruments/measurement/large_signal_plan.py writes it after every step:
{"format": "linpar-large-signal-plan/1", "plan": {...}, "stopped_by": ..., "message": ...,
 "steps": [{"index", "level_v", "partial", "usable", "message", "recording", "measures"}, ...]}.
A step is identified when it has a recording and is usable (complete, no input clipped); the
recordings are named relative to the summary's folder.
"""
from __future__ import annotations

import json
from pathlib import Path

from analysis.errors import user_message
from analysis.files import read_text
from analysis.large_signal.data import LargeSignalError

SUMMARY_SUFFIX = ".large-signal.json"


def is_summary(path: str | Path) -> bool:
    return Path(path).name.endswith(SUMMARY_SUFFIX)


def summary_recordings(path: str | Path) -> list[Path]:
    """The recordings of the plan's usable steps; LargeSignalError (one line) for a file that is no summary or
    a plan that recorded no complete step."""
    path = Path(path)
    text = read_text(path, "config", "a large-signal plan summary (NAME.large-signal.json)", LargeSignalError)
    try:
        doc = json.loads(text)
    except RecursionError:
        raise LargeSignalError(f"{path}: not a large-signal plan summary (nested too deeply)") from None
    except ValueError as exc:
        raise LargeSignalError(f"{path}: not a large-signal plan summary ({user_message(exc)})") from None
    steps = doc.get("steps") if isinstance(doc, dict) else None
    if not isinstance(steps, list) or not all(isinstance(s, dict) for s in steps):
        raise LargeSignalError(f"{path}: not a large-signal plan summary (no list of steps in it)")
    names = [str(s["recording"]) for s in steps
             if s.get("recording") and s.get("usable", not s.get("partial"))]
    if not names:
        raise LargeSignalError(f"{path}: the plan recorded no complete step")
    return [path.parent / name for name in names]
