"""Names inside the archive: measurement ids, folder names, and the check that a path stays inside.

Nothing a user typed or a file said becomes a path unsanitised: a folder
name is a generated id (date, time, random hex) plus, for people browsing
the folders, a slug of the driver and serial reduced to [a-z0-9-]. An id
given on the command line must match the id pattern before it is looked up,
so '../x', '/etc' or a NUL never reach the file system.
"""
from __future__ import annotations

import re
import secrets
import unicodedata
from datetime import datetime, timezone
from pathlib import Path

from analysis.errors import LinparError
from analysis.text_boundary import cleaned

ID_PATTERN = re.compile(r"^\d{8}-\d{6}-[0-9a-f]{6}$")
# What a user may type for an id: its leading part (a unique prefix selects).
ID_PREFIX_PATTERN = re.compile(r"^[0-9a-f-]{1,22}$")
SLUG_MAX = 40
_NOT_SLUG = re.compile(r"[^a-z0-9]+")


class ArchiveError(LinparError, RuntimeError):
    """An archive operation that cannot be done; str(err) is one line for the user."""


def new_measurement_id(now: datetime | None = None) -> str:
    """'20240501-120301-3fa2c1': sortable by time, unique by 24 random bits within the second."""
    now = (now or datetime.now(timezone.utc)).astimezone(timezone.utc)
    return f"{now:%Y%m%d-%H%M%S}-{secrets.token_hex(3)}"


def slug(text: str) -> str:
    """Lower-case ASCII letters, digits and single dashes only; '' when nothing is left."""
    ascii_text = unicodedata.normalize("NFKD", str(text)).encode("ascii", "ignore").decode("ascii")
    return _NOT_SLUG.sub("-", ascii_text.lower()).strip("-")[:SLUG_MAX].strip("-")


def folder_name(measurement_id: str, *labels: str) -> str:
    check_id(measurement_id)
    tail = slug("-".join(label for label in labels if label))
    return f"{measurement_id}-{tail}" if tail else measurement_id


def check_id(text: str) -> str:
    if not isinstance(text, str) or not ID_PATTERN.match(text):
        raise ArchiveError(f"{text!r} is not a measurement id: expected YYYYMMDD-HHMMSS-xxxxxx (6 hex digits)")
    return text


def check_id_prefix(text: str) -> str:
    if not isinstance(text, str) or not ID_PREFIX_PATTERN.match(text):
        raise ArchiveError(f"{text!r} is not a measurement id: expected YYYYMMDD-HHMMSS-xxxxxx or its "
                           "first characters (digits, a-f and '-')")
    return text


def clean_text(value, field: str, max_len: int = 200) -> str:
    """A metadata string as stored: control characters (NUL, newlines) become spaces, length is capped."""
    if value is None:
        return ""
    if not isinstance(value, str):
        raise ArchiveError(f"meta.{field}: expected text, found {type(value).__name__}")
    return cleaned(value, max_len)     # the class every reader of a record checks (analysis.text_boundary)


def inside(root: Path, relative: str) -> Path:
    """root/relative, refused unless it resolves to a path strictly inside root."""
    if not relative or "\x00" in relative or Path(relative).is_absolute():
        raise ArchiveError(f"{relative!r}: not a name inside the archive")
    base = root.resolve()
    path = (base / relative).resolve()
    if path == base or base not in path.parents:
        raise ArchiveError(f"{relative!r}: would lead outside the archive {base}")
    return path


def safe_suffix(name: str, default: str = ".bin") -> str:
    """A file's extension reduced to '.' + up to 8 [a-z0-9], for files copied in under our own names."""
    suffix = slug(Path(str(name).replace("\x00", "")).suffix.lstrip("."))[:8].replace("-", "")
    return f".{suffix}" if suffix else default


def shown(spec: str) -> str:
    """A specification as messages may show it: a URL's password masked."""
    return re.sub(r"(://[^:/@]*):[^@/]*@", r"\1:***@", str(spec))
