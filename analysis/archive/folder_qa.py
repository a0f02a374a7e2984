"""Production QA in a folder archive: limits versions, golden units and the population for statistics.

    root/limits/v0001.json, v0002.json ...   one file per limits version, never rewritten
    root/golden.json                          the golden units' ids

A version's number is taken by hard-linking its complete file to the name
vNNNN.json: a link fails when the name exists, so two programs storing at
once get two numbers, and a reader never sees half a file. golden.json is
rewritten atomically under an exclusive lock (fcntl), so two changes at once
are both kept. Like measurement.json, these files are the truth: the index
holds nothing of them, and `linpar archive rebuild` keeps them.

A folder archive has no roles: who may change limits is who may write to the
folder (its permissions). Roles are the PostgreSQL back end's.
"""
from __future__ import annotations

import getpass
import json
import os
import re
import tempfile
from datetime import datetime, timezone
from pathlib import Path
from typing import Iterable

from analysis import file_lock
from analysis.archive.atomic import FILE_MODE, fsync_dir, write_atomic
from analysis.archive.limits_store import (LimitsVersion, checked_document, checked_note, version_json,
                                           version_of_json)
from analysis.archive.names import ArchiveError, check_id
from analysis.files import read_text

LIMITS_FOLDER = "limits"
GOLDEN_FILE = "golden.json"
GOLDEN_FORMAT = "linpar-golden/1"
_VERSION_FILE = re.compile(r"^v(\d{4,9})\.json$")


def _now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds").replace("+00:00", "Z")


def _user() -> str:
    try:
        return getpass.getuser()
    except (KeyError, OSError):       # no name for this uid (a container)
        return f"uid {os.getuid()}" if hasattr(os, "getuid") else "unknown user"   # Windows has no uid


class FolderQA:
    """Mixed into analysis.archive.Archive (needs self.root, self.notes, self.list)."""

    root: Path
    notes: list[str]

    # --- limits versions ---------------------------------------------------------------

    def limits_versions(self) -> list[LimitsVersion]:
        """Every stored version, oldest first (a file that cannot be read is skipped, with a note)."""
        folder = self.root / LIMITS_FOLDER
        if not folder.is_dir():
            return []
        versions = []
        for path in sorted(folder.iterdir()):
            match = _VERSION_FILE.match(path.name)
            if not match:
                continue
            try:
                text = read_text(path, "config", "a stored limits version (JSON)", ArchiveError)
                try:
                    v = version_of_json(json.loads(text), str(path))
                except (ValueError, RecursionError) as exc:
                    raise ArchiveError(f"{path}: not readable JSON ({exc})") from None
                if v.version != int(match.group(1)):
                    raise ArchiveError(f"{path}: version {v.version} in a file named for {int(match.group(1))}")
                versions.append(v)
            except ArchiveError as exc:
                self.notes.append(f"skipped a limits version that cannot be used: {exc}")
        return versions

    def limits(self, version: int | None = None) -> LimitsVersion | None:
        """The newest version (or the one numbered `version`); None when none is stored."""
        versions = self.limits_versions()
        if version is None:
            return versions[-1] if versions else None
        for v in versions:
            if v.version == version:
                return v
        raise ArchiveError(f"no limits version {version} in the archive {self.location} "
                           f"(stored: {', '.join(str(v.version) for v in versions) or 'none'})")

    def store_limits(self, document, note: str = "") -> LimitsVersion:
        """Store a linpar-limits/1 document as the next version; return it."""
        document, name = checked_document(document)
        note = checked_note(note)
        folder = self.root / LIMITS_FOLDER
        folder.mkdir(parents=True, exist_ok=True)
        taken = [int(m.group(1)) for p in folder.iterdir() if (m := _VERSION_FILE.match(p.name))]
        number = max(taken, default=0) + 1
        for _attempt in range(1000):
            version = LimitsVersion(number, name, document, note, _now(), _user())
            fd, tmp = tempfile.mkstemp(dir=folder, prefix=".limits-", suffix=".tmp")
            try:
                with os.fdopen(fd, "wb") as f:
                    f.write((json.dumps(version_json(version), indent=1, ensure_ascii=False) + "\n").encode())
                    f.flush()
                    os.fsync(f.fileno())
                os.chmod(tmp, FILE_MODE)
                try:
                    os.link(tmp, folder / f"v{number:04d}.json")     # fails when the number is taken
                except FileExistsError:
                    number += 1
                    continue
                fsync_dir(folder)
                return version
            finally:
                Path(tmp).unlink(missing_ok=True)
        raise ArchiveError(f"{folder}: could not take a version number (a thousand taken meanwhile)")

    # --- golden units ----------------------------------------------------------------

    def golden(self) -> list[str]:
        """The golden units' measurement ids, in the order they were marked."""
        path = self.root / GOLDEN_FILE
        if not path.exists():
            return []
        text = read_text(path, "config", "the archive's golden units (JSON)", ArchiveError)
        try:
            doc = json.loads(text)
        except (ValueError, RecursionError) as exc:
            raise ArchiveError(f"{path}: not readable JSON ({exc})") from None
        if not isinstance(doc, dict) or doc.get("format") != GOLDEN_FORMAT or not isinstance(doc.get("ids"), list):
            raise ArchiveError(f"{path}: expected {{\"format\": \"{GOLDEN_FORMAT}\", \"ids\": [...]}}")
        return [check_id(i) for i in doc["ids"]]

    def set_golden(self, ids: Iterable[str], golden: bool = True) -> list[str]:
        """Mark (or unmark) measurements as golden units; the golden ids afterwards."""
        wanted = [self.resolve(i)[0] for i in ids]
        self.root.mkdir(parents=True, exist_ok=True)
        with self._golden_lock():
            current = self.golden()
            if golden:
                current += [i for i in wanted if i not in current]
            else:
                current = [i for i in current if i not in wanted]
            doc = {"format": GOLDEN_FORMAT, "ids": current, "changed_at": _now(), "changed_by": _user()}
            write_atomic(self.root / GOLDEN_FILE, json.dumps(doc, indent=1) + "\n")
        return current

    def _golden_lock(self):
        return file_lock.exclusive(self.root / ".golden.lock")

    # --- statistics ---------------------------------------------------------------------

    def population(self, selection=None, names=None, with_stds: bool = True):
        """The selected measurements' key parameters, oldest first (analysis.archive.population); without
        their standard deviations if not `with_stds` (the statistics need none)."""
        from analysis.archive.population import Selection
        from analysis.archive.population_read import empty_population, read_sqlite
        selection = selection or Selection()
        if not self.root.is_dir():
            return empty_population(names, with_stds)
        with self._index_errors("reading the population"):
            conn = self._connect()
            try:
                return read_sqlite(conn, selection, names, with_stds)
            finally:
                conn.close()

    def sync(self):
        """A folder archive has no server to send to: nothing waits."""
        from analysis.archive.sync_report import SyncReport
        return SyncReport()

    @property
    def pending(self) -> int:
        return 0
