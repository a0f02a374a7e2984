"""The sidecar of a recording, NAME.json: its vocabulary, and its JSON read, checked by key, and written.

analysis.recording.format builds and checks Recordings; this module is the layer
below it that knows the JSON: the format's name, the signals and their units,
the keys of each object, a Channel (one entry of "channels"), RecordingError,
and the one-line messages about a sidecar. Import the public names from
analysis.recording.format, which re-exports them; the format is
docs/recording-format.md.
"""
from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from analysis.errors import LinparError
from analysis.files import read_bytes

FORMAT = "linpar-recording/1"
# The signals the analysis knows, with the only unit each may be in.
UNITS = MappingProxyType({"voltage": "V", "current": "A", "displacement": "m"})
# The keys the format defines in each object; any other key is kept and written back.
CHANNEL_KEYS = ("signal", "unit", "scale")
EXCITATION_KEYS = ("period_samples", "settle_periods", "excited_bins")
TOP_KEYS = ("format", "channels", "excitation", "driver")


class RecordingError(LinparError, ValueError):
    """A recording that breaks the format. str(err) is ONE line naming the file, the key or channel, and what was expected."""

    def __init__(self, message: str):
        super().__init__(" ".join(str(message).splitlines()))


@dataclass(frozen=True, slots=True)
class Channel:
    signal: str      # "voltage" | "current" | "displacement" | any other name (kept, not analysed)
    unit: str
    scale: float     # physical = sample * scale
    # Other keys of the sidecar's channel entry, written back unchanged; not compared.
    extra: Mapping[str, Any] = field(default_factory=dict, compare=False)


# --- reading -----------------------------------------------------------------

def load_sidecar(path: Path) -> Any:
    """The JSON document in `path`: UTF-8 (a BOM is allowed), finite numbers only, writable again as UTF-8."""
    try:
        text = read_bytes(path, "sidecar", "a JSON sidecar", RecordingError).decode("utf-8-sig")   # a BOM is fine
    except UnicodeDecodeError as err:
        raise RecordingError(f"{path}: not UTF-8 (byte {err.start}), expected a UTF-8 JSON object") from None
    try:
        doc = json.loads(text, parse_constant=_refuse_constant)
    except _NotJson as err:
        line = _line_of(text, str(err))
        raise RecordingError(f"{path}: invalid JSON at line {line}: {err} is not a JSON number, "
                             f"expected a JSON object with finite numbers") from None
    except json.JSONDecodeError as err:
        raise RecordingError(f"{path}: invalid JSON at line {err.lineno}, column {err.colno}: {err.msg}, "
                             f"expected a JSON object") from None
    except RecursionError:
        raise RecordingError(f"{path}: JSON nested too deeply, expected a JSON object") from None
    except ValueError as err:   # e.g. an integer of more digits than Python converts
        raise RecordingError(f"{path}: invalid JSON: {err}, expected a JSON object") from None
    try:
        # Valid JSON may escape half of a UTF-16 pair ("\\ud800"): no UTF-8 file could hold it again.
        json.dumps(doc, ensure_ascii=False).encode("utf-8")
    except UnicodeEncodeError as err:
        raise RecordingError(f"{path}: a string holds {err.object[err.start:err.end]!r}, half of a UTF-16 "
                             f"surrogate pair, expected Unicode text") from None
    return doc


class _NotJson(ValueError):
    pass


def _refuse_constant(name: str):
    # NaN and Infinity are Python's extension, not JSON: other readers refuse them.
    raise _NotJson(name)


def _line_of(text: str, token: str) -> int:
    """Line of the first bare `token` (not inside a string, as far as a regex can tell)."""
    match = re.search(rf'(?<![\w"]){re.escape(token)}(?![\w"])', text)
    return text.count("\n", 0, match.start()) + 1 if match else 1


def parse_sidecar(doc: Any, label: str) -> dict[str, Any]:
    """Channels and the other Recording fields of a sidecar, by key; values are checked later."""
    if not isinstance(doc, dict):
        raise RecordingError(f"{label}: found a JSON {_json_type(doc)} at the top, expected a JSON object")
    if doc.get("format") != FORMAT:
        found = f"found {show(doc['format'])}" if "format" in doc else "missing"
        raise RecordingError(f"{label}: format: {found}, expected exactly {FORMAT!r}")
    entries = _required(doc, "channels", list, label, "channels", "a non-empty list of {signal, unit, scale}")
    channels = []
    for i, entry in enumerate(entries):
        if not isinstance(entry, dict):
            raise RecordingError(f"{label}: channels[{i}]: found a JSON {_json_type(entry)}, "
                                 f"expected an object with signal, unit and scale")
        signal = entry.get("signal")
        for key in CHANNEL_KEYS:
            if key not in entry:
                wanted = {"signal": "a signal name (voltage, current, displacement or another)",
                          "unit": unit_wanted(signal),
                          "scale": "a finite nonzero number (physical value = sample x scale)"}[key]
                raise RecordingError(f"{label}: channels[{i}].{key}: missing, expected {wanted}")
        extra = {k: v for k, v in entry.items() if k not in CHANNEL_KEYS}
        channels.append(Channel(entry["signal"], entry["unit"], entry["scale"], extra))
    excitation = _required(doc, "excitation", dict, label, "excitation", "an object with period_samples")
    if "period_samples" not in excitation:
        raise RecordingError(f"{label}: excitation.period_samples: missing, "
                             f"expected the length of one period in samples (a positive integer)")
    return {"channels": channels, "rest": {
        "period_samples": excitation["period_samples"],
        "settle_periods": excitation.get("settle_periods", 0),
        "excited_bins": excitation.get("excited_bins"),
        "excitation_extra": {k: v for k, v in excitation.items() if k not in EXCITATION_KEYS},
        "driver": doc.get("driver", {}),
        "extra": {k: v for k, v in doc.items() if k not in TOP_KEYS},
    }}


def _required(doc: dict, key: str, kind: type, label: str, where: str, expected: str):
    if key not in doc:
        raise RecordingError(f"{label}: {where}: missing, expected {expected}")
    if not isinstance(doc[key], kind):
        raise RecordingError(f"{label}: {where}: found a JSON {_json_type(doc[key])}, expected {expected}")
    return doc[key]


# --- writing -----------------------------------------------------------------

def format_sidecar(doc: dict[str, Any]) -> str:
    """The layout of the spec's example: one line per top-level key and per channel."""
    def compact(value: Any) -> str:
        return json.dumps(value, ensure_ascii=False, allow_nan=False, default=json_default)
    lines = []
    for key, value in doc.items():
        if key == "channels":
            entries = ",\n".join(f"    {compact(c)}" for c in value)
            lines.append(f'  "channels": [\n{entries}\n  ]')
        else:
            lines.append(f"  {compact(key)}: {compact(value)}")
    return "{\n" + ",\n".join(lines) + "\n}\n"


def json_default(value: Any) -> Any:
    """What json.dumps cannot write by itself but a program may put in `extra`."""
    if isinstance(value, Mapping):
        return dict(value)
    if isinstance(value, (np.generic, np.ndarray)):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


# --- files and messages, shared with analysis.recording.format ---------------------

def unit_wanted(signal) -> str:
    if isinstance(signal, str) and signal in UNITS:
        return f"{UNITS[signal]!r} for {signal}"
    return "a unit string ('V', 'A' and 'm' for voltage, current and displacement)"


def _json_type(value) -> str:
    for kind, name in ((dict, "object"), (list, "array"), (str, "string"), (bool, "boolean"),
                       (int, "number"), (float, "number")):
        if isinstance(value, kind):
            return name
    return "null" if value is None else type(value).__name__


def show(value, width: int = 60) -> str:
    """A short one-line repr for messages."""
    text = repr(value)
    return text if len(text) <= width else text[:width - 3] + "..."
