"""The SQLite index of the archive's folders: checked on every open, rebuilt when it cannot be trusted.

On open the index is checked, cheapest first: the file exists, starts with
SQLite's magic bytes, passes `PRAGMA quick_check`, has a schema_version this
program knows (older ones are migrated) and the expected columns. A file
that fails any check is renamed aside (index.sqlite.broken-<time>-<pid>, kept for
a look) and the index is rebuilt from the folders. Then the set of folders
is compared with the set of indexed ones, so that a folder stored by a
program that crashed before it reached the index, or one removed by hand,
is picked up: the folders are the truth, the index only a cache. The index
is compared again and changed under SQLite's write lock, so that a store
running meanwhile (it renames its folder into place, then adds its row)
never has its new row taken for that of a removed folder.

A rebuild writes a new database next to the old one and renames it into
place: readers see the old index or the new one.

When the index cannot be written (a read-only archive, a database another
program keeps locked) while it is stale, missing or damaged, the archive is
still readable: the index is built in memory from the folders for this one
use, and a note says what is wrong and how to repair it. Opening and
rebuilding also remove what interrupted programs left (analysis.archive.leftovers).
"""
from __future__ import annotations

import os
import sqlite3
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable

from analysis.archive.atomic import fsync_dir
from analysis.archive.leftovers import STALE_AFTER_S, sweep
from analysis.archive.names import ArchiveError, check_id
from analysis.archive.record import (Entry, checked_entry, checked_parameter, checked_qa, entry_of, one_line_text,
                                     read_record)
from analysis.archive.schema import (KEY_PARAMETERS, SchemaError, check_columns, measured_until, migrate, std_column,
                                     value_column)

SQLITE_MAGIC = b"SQLite format 3\x00"
INDEX_FILE = "index.sqlite"
MISSING = "the database file is missing"


@dataclass(frozen=True)
class Filter:
    """What `list` selects: substrings (case-insensitive) of the text fields, validity, a date range."""

    driver: str | None = None
    serial: str | None = None
    operator: str | None = None
    station: str | None = None
    validity: str | None = None
    since: str | None = None       # ISO date or date-time, inclusive
    until: str | None = None       # ISO date or date-time, inclusive (a bare date means the whole day)
    limit: int | None = None

    def sql(self, placeholder: str, like: str = "LIKE") -> tuple[str, list]:
        """The WHERE, ORDER BY and LIMIT that select this filter's measurements (newest first), and their
        arguments; `placeholder` and `like` are the database's ("?" and LIKE for SQLite, "%s" and ILIKE for
        PostgreSQL)."""
        where, args = [], []
        for column in ("driver", "serial", "operator", "station"):
            text = getattr(self, column)
            if text:
                where.append(f"{column} {like} {placeholder} ESCAPE '\\'")
                args.append(_like(text))
        until = self.until and measured_until(self.until)
        for column, op, value in (("validity", "=", self.validity), ("measured_at", ">=", self.since),
                                  ("measured_at", "<=", until)):
            if value:
                where.append(f"{column} {op} {placeholder}")
                args.append(value)
        sql = (" WHERE " + " AND ".join(where) if where else "") + " ORDER BY measured_at DESC, id DESC"
        if self.limit is not None:
            sql += f" LIMIT {placeholder}"
            args.append(int(self.limit))
        return sql, args


@dataclass
class RebuildReport:
    indexed: int = 0
    skipped: list[str] = field(default_factory=list)     # folders whose measurement.json could not be read
    reason: str = ""

    def describe(self) -> str:
        text = f"index rebuilt ({self.reason}): {self.indexed} measurement(s)"
        if self.skipped:
            text += f"; {len(self.skipped)} folder(s) skipped: " + "; ".join(self.skipped)
        return text


def _like(text: str) -> str:
    return "%" + text.replace("\\", "\\\\").replace("%", "\\%").replace("_", "\\_") + "%"


class Index:
    def __init__(self, root: Path, folders: Path):
        self.path = root / INDEX_FILE
        self.folders = folders
        self.notes: list[str] = []      # what opening had to repair, for the user

    # --- opening and checking ---------------------------------------------

    def connect(self) -> sqlite3.Connection:
        """The index, checked and brought up to date; in memory when the file cannot be (module doc)."""
        self.sweep_leftovers()
        try:
            return self._connect_file()
        except (sqlite3.DatabaseError, OSError) as exc:
            return self._connect_memory(exc)

    def sweep_leftovers(self) -> None:
        """Remove what interrupted stores and rebuilds left, once surely abandoned (analysis.archive.leftovers)."""
        removed = sweep(self.folders, self.path.parent, INDEX_FILE)
        if removed:
            self.notes.append(f"removed {len(removed)} unfinished store(s) or rebuild(s) left by interrupted "
                              f"programs more than {STALE_AFTER_S / 3600:g} h ago: {', '.join(removed)}")

    def _connect_memory(self, why: BaseException) -> sqlite3.Connection:
        """An index of the folders in memory, for an archive whose index file cannot be used or written."""
        conn = sqlite3.connect(":memory:")
        try:
            migrate(conn)
            skipped = 0
            with conn:
                for name in sorted(self._folder_names()):
                    try:
                        insert(conn, read_record(self.folders / name))
                    except (ArchiveError, sqlite3.IntegrityError):
                        skipped += 1
        except OSError as exc:
            conn.close()
            raise ArchiveError(f"{self.folders}: cannot be read ({exc.strerror or exc}); the index "
                               f"{self.path} cannot be used either ({why})") from None
        self.notes.append(f"the index {self.path} cannot be used or updated ({why}): listed from the measurement "
                          f"folders instead" + (f" ({skipped} unreadable)" if skipped else "") +
                          f"; to repair it, run 'linpar archive rebuild' as a user who may write to {self.path.parent}")
        return conn

    def _connect_file(self) -> sqlite3.Connection:
        problem = self._problem()
        if problem:
            report = self.rebuild(problem)
            if report.indexed or report.skipped or self.path.name != INDEX_FILE or problem != MISSING:
                self.notes.append(report.describe())     # a new, empty archive is no news
        conn = self._open()
        try:
            migrate(conn)
            check_columns(conn)
        except (sqlite3.DatabaseError, SchemaError) as exc:
            # Changed under our feet between the check and now: rebuild once more.
            conn.close()
            self.notes.append(self.rebuild(f"unusable: {exc}").describe())
            conn = self._open()
        try:
            self._sync(conn)
        except BaseException:
            conn.close()
            raise
        return conn

    def _open(self, path: Path | None = None) -> sqlite3.Connection:
        conn = sqlite3.connect(path or self.path, timeout=10.0)
        conn.execute("PRAGMA foreign_keys = ON")
        return conn

    def _problem(self) -> str | None:
        """Why the database file cannot be used as it is, or None."""
        if not self.path.exists():
            return MISSING
        if not self.path.is_file():     # a FIFO would block the read below forever, a folder cannot be opened
            return "the database file is not a regular file"
        try:
            with open(self.path, "rb") as f:
                head = f.read(len(SQLITE_MAGIC))
        except OSError as exc:
            return f"the database file cannot be read ({exc.strerror or exc})"
        if len(head) == 0:
            return "the database file is empty"
        if head != SQLITE_MAGIC:
            return "the database file is not an SQLite database"
        try:
            conn = self._open()
            try:
                status = conn.execute("PRAGMA quick_check").fetchone()[0]
                if status != "ok":
                    return f"the database is damaged ({status})"
                migrate(conn)
                check_columns(conn)
            finally:
                conn.close()
        except sqlite3.DatabaseError as exc:
            return f"the database is damaged ({exc})"
        except SchemaError as exc:
            return f"wrong schema ({exc})"
        return None

    def _folder_names(self) -> set[str]:
        if not self.folders.is_dir():
            return set()
        with os.scandir(self.folders) as it:
            return {e.name for e in it if e.is_dir(follow_symlinks=False) and not e.name.startswith(".")}

    def _sync(self, conn: sqlite3.Connection) -> None:
        if self._folder_names() == self._indexed(conn):
            return          # the usual case, and a read-only archive's: no lock taken
        # NB: stores in other threads and programs rename their folder into place, then insert its row. Under
        # the write lock no row is inserted, so a row is deleted only when its folder was gone after the row was
        # made; a folder found here before its store's insert is indexed here (the store takes that as done).
        conn.execute("BEGIN IMMEDIATE")
        try:
            indexed = self._indexed(conn)
            on_disk = self._folder_names()
            added = skipped = 0
            for name in sorted(indexed - on_disk):
                conn.execute("DELETE FROM measurements WHERE folder = ?", (name,))
            for name in sorted(on_disk - indexed):
                try:
                    insert(conn, read_record(self.folders / name))
                    added += 1
                except (ArchiveError, sqlite3.IntegrityError):
                    skipped += 1
            conn.commit()
        except BaseException:
            conn.rollback()
            raise
        if indexed - on_disk or added:
            self.notes.append(f"index brought up to date with the folders: {added} added, "
                              f"{len(indexed - on_disk)} removed" + (f", {skipped} unreadable" if skipped else ""))

    @staticmethod
    def _indexed(conn: sqlite3.Connection) -> set[str]:
        return {row[0] for row in conn.execute("SELECT folder FROM measurements")}

    # --- rebuilding -----------------------------------------------------------

    def rebuild(self, reason: str = "asked for") -> RebuildReport:
        report = RebuildReport(reason=reason)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        tmp = self.path.with_name(f".{INDEX_FILE}.{os.getpid()}.{time.monotonic_ns()}.tmp")
        conn = self._open(tmp)
        try:
            migrate(conn)
            with conn:
                for name in sorted(self._folder_names()):
                    try:
                        insert(conn, read_record(self.folders / name))
                        report.indexed += 1
                    except ArchiveError as exc:
                        report.skipped.append(str(exc))
                    except sqlite3.IntegrityError as exc:
                        report.skipped.append(f"{name}: {exc}")
            conn.close()
            self._set_aside()
            os.replace(tmp, self.path)
            fsync_dir(self.path.parent)
        except BaseException:
            conn.close()
            tmp.unlink(missing_ok=True)
            raise
        return report

    def _set_aside(self) -> None:
        """Keep a damaged database for a look, and never let its journal touch the new one."""
        if self.path.exists() and self._problem_is_damage():
            os.replace(self.path, _aside_name(self.path))
        for suffix in ("-journal", "-wal", "-shm"):
            side = Path(str(self.path) + suffix)
            if side.is_dir() and not side.is_symlink():     # not SQLite's: kept for a look, out of its way
                os.replace(side, _aside_name(side))
            else:
                side.unlink(missing_ok=True)

    def _problem_is_damage(self) -> bool:
        # A sound database that is merely being rebuilt on request is simply replaced.
        return self._problem() is not None

    # --- reading ----------------------------------------------------------------

    def query(self, conn: sqlite3.Connection, flt: Filter = Filter()) -> list[Entry]:
        selection, args = flt.sql("?")
        sql = "SELECT id, folder, measured_at, stored_at, driver, serial, operator, station, validity, effects, " \
              "verdict, limits_version FROM measurements" + selection
        entries: dict[str, Entry] = {}
        refused: list[str] = []
        for row in conn.execute(sql, args).fetchall():
            try:
                entries[row[0]] = _entry_of_row(row)
            except ArchiveError as exc:
                refused.append(str(exc))
        for mid, name, value, std, unit in self._parameters(conn, list(entries)):
            try:
                where = f"index row of {mid}: parameter {one_line_text(name, 'parameter name')}"
                entries[mid].parameters[name] = checked_parameter({"value": value, "std": std, "unit": unit}, where)
            except ArchiveError as exc:
                refused.append(str(exc))
        if refused:
            self.notes.append(f"skipped {len(refused)} row(s) of the index {self.path} that cannot be used "
                              f"({refused[0]}{'; ...' if len(refused) > 1 else ''}): 'linpar archive rebuild' "
                              f"makes the index anew from the measurement folders")
        return list(entries.values())

    def _parameters(self, conn, ids: list[str]) -> Iterable[tuple]:
        if not ids:
            return []
        if len(ids) > 500:     # SQLite's bound-variable limit: take them all, keep ours
            wanted = set(ids)
            return [r for r in conn.execute("SELECT measurement_id, name, value, std, unit FROM parameters")
                    if r[0] in wanted]
        marks = ",".join("?" * len(ids))
        return conn.execute(f"SELECT measurement_id, name, value, std, unit FROM parameters "
                            f"WHERE measurement_id IN ({marks})", ids).fetchall()

    def matching_ids(self, conn: sqlite3.Connection, prefix: str) -> list[tuple[str, str]]:
        """(id, folder) of every measurement whose id starts with `prefix` (rows that cannot be used: skipped)."""
        rows = conn.execute("SELECT id, folder FROM measurements WHERE substr(id, 1, ?) = ? ORDER BY id",
                            (len(prefix), prefix)).fetchall()
        usable = []
        for mid, folder in rows:
            try:
                usable.append((check_id(mid), one_line_text(folder, f"index row of {mid}: folder")))
            except ArchiveError as exc:
                self.notes.append(f"skipped a row of the index {self.path} ({exc}): 'linpar archive rebuild' "
                                  f"makes the index anew from the measurement folders")
        return usable


def _aside_name(path: Path) -> Path:
    """NAME.broken-<time>-<pid>[-n]: unique, so that two damaged indexes set aside in one second (by one
    program or two) never replace one another."""
    stem = f"{path.name}.broken-{time.strftime('%Y%m%d-%H%M%S')}-{os.getpid()}"
    for n in range(1, 1000):
        candidate = path.with_name(stem if n == 1 else f"{stem}-{n}")
        if not os.path.lexists(candidate):
            return candidate
    raise ArchiveError(f"{path.parent}: a thousand damaged indexes set aside this second: remove some")


def _entry_of_row(row: tuple) -> Entry:
    """An Entry of an index row, checked as a record is (the index is a file like any other)."""
    keys = ("id", "folder", "measured_at", "stored_at", "driver", "serial", "operator", "station", "validity")
    values = dict(zip(keys, row[:9]))
    effects = row[9]
    where = f"index row of {row[0]!r:.40}"
    one_line_text(effects, f"{where}: effects")
    values["effects"] = tuple(e for e in effects.split(",") if e)
    checked_entry(values, where)
    verdict, version = checked_qa(row[10], row[11], where)
    return Entry(*(values[k] for k in keys), values["effects"], {}, verdict, version)


def insert(conn: sqlite3.Connection, record: dict) -> None:
    """Add one record, all of it or nothing (a savepoint), replacing any orphaned parameter rows."""
    conn.execute("SAVEPOINT record")
    try:
        _insert(conn, record)
    except BaseException:
        conn.execute("ROLLBACK TO record")
        conn.execute("RELEASE record")
        raise
    conn.execute("RELEASE record")


def _insert(conn: sqlite3.Connection, record: dict) -> None:
    e = entry_of(record)
    conn.execute("DELETE FROM parameters WHERE measurement_id = ?", (e.id,))
    kept = {name: p for name in KEY_PARAMETERS if (p := e.parameters.get(name)) is not None}
    columns = ["id", "folder", "measured_at", "stored_at", "driver", "serial", "operator", "station", "validity",
               "effects", "verdict", "limits_version"]
    values = [e.id, e.folder, e.measured_at, e.stored_at, e.driver, e.serial, e.operator, e.station, e.validity,
              ",".join(e.effects), e.verdict, e.limits_version]
    for name, p in kept.items():        # the statistics' copy of the key parameters (schema.value_column)
        columns += [value_column(name), std_column(name)]
        values += [_real(p.get("value")), _real(p.get("std"))]
    conn.execute(f"INSERT INTO measurements ({', '.join(columns)}) VALUES ({', '.join('?' * len(values))})", values)
    for name, p in kept.items():
        conn.execute("INSERT INTO parameters VALUES (?, ?, ?, ?, ?)",
                     (e.id, name, _real(p.get("value")), _real(p.get("std")), str(p.get("unit", ""))))


def _real(value) -> float | None:
    """A number as the REAL column takes it; None for anything else (an integer beyond the float range too)."""
    if not isinstance(value, (int, float)):
        return None
    try:
        return float(value)
    except OverflowError:
        return None
