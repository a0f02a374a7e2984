"""The PostgreSQL archive: the line's measurements on one server, shared by its stations, roles enforced there.

    PostgresArchive("postgresql://station1@qa-db/linpar").store(recording, result, meta) -> id

It offers what the folder archive does (analysis.archive.backends.ArchiveBackend).
Storing goes through the station's local queue (analysis.archive.pg.outbox),
so a station that loses the server keeps storing and the queue is sent when
the server is back. Reading asks the server; a stored file is fetched on first
use into a local cache ($LINPAR_CACHE or the platform's cache folder, archive/<server>/),
checked against its SHA-256, so that reports, exports and the GUI open it as a
file, as they do a folder archive's.
"""
from __future__ import annotations

import contextlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable, Iterator

from analysis import config_folder
from analysis.archive.archive import Measurement, export_folder
from analysis.archive.index import Filter, _entry_of_row
from analysis.archive.limits_store import LimitsVersion, checked_document, checked_note, version_of_json
from analysis.archive.names import ArchiveError, check_id, check_id_prefix, inside
from analysis.archive.pg.files import fetch_file
from analysis.archive.pg.outbox import Outbox, queue_folder
from analysis.archive.pg.queue_identity import adopt, point, remembered, server_identity
from analysis.archive.pg.server import ServerRefused, ServerUnreachable, connect, parse_url, server_errors
from analysis.archive.record import RECORD_FILE, checked_parameter, entry_of, one_line_text, read_record
from analysis.archive.sync_report import SyncReport

LIST_COLUMNS = ("id, folder, measured_at, stored_at, driver, serial, operator, station, validity, effects, "
                "verdict, limits_version")


def cache_folder(slug: str) -> Path:
    return config_folder.cache_folder() / "archive" / slug


@dataclass(frozen=True)
class ServerMeasurement(Measurement):
    """A measurement on the server: its files are fetched into the cache folder when first asked for."""

    fetch: Callable[[str], Path | None] | None = None

    def path(self, role: str) -> Path | None:
        return self.fetch(role) if self.fetch is not None else None


class PostgresArchive:
    def __init__(self, url: str, queue_root: str | Path | None = None, cache_root: str | Path | None = None):
        self.server = parse_url(url)
        self.location = self.server.display
        self.notes: list[str] = []
        self.cache = Path(cache_root) if cache_root else cache_folder(self.server.slug)
        # The queue is the server's, not the URL spelling's (analysis.archive.pg.queue_identity): the URL's
        # folder points to it once this URL has reached the server; until then the URL's folder is the queue.
        self._url_queue = None if queue_root else queue_folder(self.server.slug)
        self._identity_checked = queue_root is not None
        if queue_root:
            self.outbox = Outbox(Path(queue_root))
        else:
            known = remembered(self._url_queue)
            self.outbox = Outbox(known or self._url_queue)
            if known is not None:
                adopt(self._url_queue, known)        # queued there by a linpar that kept queues per URL

    def _connect(self, doing: str):
        """A connection to the server; the first one also tells which queue is this server's."""
        conn = connect(self.server, doing)
        if not self._identity_checked:
            self._identity_checked = True
            name = server_identity(conn)
            if name is not None:
                target = self._url_queue.parent / name
                point(self._url_queue, target)
                for source in {self._url_queue, self.outbox.root}:
                    adopt(source, target)
                self.outbox = Outbox(target)
        return conn

    @contextlib.contextmanager
    def _session(self, doing: str, needs: str = "") -> Iterator:
        try:
            conn = self._connect(doing)
        except ServerUnreachable as exc:
            waiting = self.pending
            if not waiting:
                raise
            raise ServerUnreachable(f"{exc}; {waiting} measurement(s) of this station wait in the local queue "
                                    f"{self.outbox.root}") from None
        try:
            with server_errors(self.server, doing, needs):
                yield conn
        finally:
            conn.close()

    # --- storing --------------------------------------------------------------------------------

    def store(self, recording, result, meta=None, laser_stream=None, now=None) -> str:
        """Queue the measurement at this station, then send the queue; the measurement's id.

        Cut off from the server, the measurement waits in the queue (a note says so) and is judged with the
        last limits version this station saw. A server that refuses it (a role without the right to store)
        raises ServerRefused: it waits in the queue all the same, nothing is lost.
        """
        try:
            with self._session("reading the limits") as conn:
                limits = self._newest_limits(conn)
            self.outbox.remember_limits(limits)
        except (ServerUnreachable, ServerRefused):
            limits = self.outbox.last_limits()
        mid = self.outbox.put(recording, result, meta, laser_stream, now, limits)
        report = self.sync()
        if mid in report.sent or mid in report.already:
            return mid
        if report.sent and mid not in report.sent:       # sent under a new id (two stations drew the same one)
            return report.sent[-1]
        where = f"the local queue {self.outbox.root}"
        if report.refused:
            error = ServerRefused(f"{report.problem}; the measurement {mid} waits in {where} and is sent once the "
                                  "server accepts it ('linpar archive sync')")
            error.queued_id = mid
            raise error
        others = f" with {report.waiting - 1} other(s)" if report.waiting > 1 else ""
        self.notes.append(f"{report.problem or 'not sent'}: the measurement {mid} waits in {where}{others}; it is "
                          "sent with the next store or 'linpar archive sync'")
        return mid

    def sync(self) -> SyncReport:
        """Send this station's local queue to the server."""
        if self._identity_checked and not self.pending:
            return SyncReport()         # (unchecked, this URL's spelling may not be where its server's queue is)
        try:
            conn = self._connect("sending the local queue")
        except (ServerUnreachable, ServerRefused) as exc:
            waiting = self.pending
            return SyncReport(waiting=waiting, problem=str(exc) if waiting else "",
                              refused=bool(waiting) and isinstance(exc, ServerRefused))
        try:
            return self.outbox.send(conn, self.server) if self.pending else SyncReport()
        finally:
            conn.close()

    @property
    def pending(self) -> int:
        return len(self.outbox.waiting())

    # --- reading ------------------------------------------------------------------------------

    def _waiting_note(self) -> None:
        n = self.pending
        if n:
            self.notes.append(f"{n} measurement(s) of this station wait in the local queue {self.outbox.root}, not "
                              "yet on the server ('linpar archive sync' sends them)")

    def list(self, flt: Filter | None = None, **kwargs) -> list:
        flt = flt or Filter(**kwargs)
        selection, args = flt.sql("%s", like="ILIKE")
        sql = f"SELECT {LIST_COLUMNS} FROM measurements" + selection
        with self._session("listing") as conn:
            rows = conn.execute(sql, args).fetchall()
            params = conn.execute("SELECT measurement_id, name, value, std, unit FROM parameters "
                                  "WHERE measurement_id = ANY(%s)", ([r[0] for r in rows],)).fetchall()
        entries, refused = {}, []
        for row in rows:
            try:
                entries[row[0]] = _entry_of_row(row)
            except ArchiveError as exc:
                refused.append(str(exc))
        for mid, name, value, std, unit in params:
            if mid in entries:
                try:
                    where_ = f"row of {mid}: parameter {one_line_text(name, 'parameter name')}"
                    entries[mid].parameters[name] = checked_parameter({"value": value, "std": std, "unit": unit},
                                                                      where_)
                except ArchiveError as exc:
                    refused.append(str(exc))
        if refused:
            self.notes.append(f"skipped {len(refused)} row(s) of the server that cannot be used ({refused[0]})")
        self._waiting_note()
        return list(entries.values())

    def resolve(self, id_or_prefix: str) -> tuple[str, str]:
        check_id_prefix(id_or_prefix)
        with self._session(f"looking up {id_or_prefix!r}") as conn:
            found = conn.execute("SELECT id, folder FROM measurements WHERE left(id, %s) = %s ORDER BY id LIMIT 6",
                                 (len(id_or_prefix), id_or_prefix)).fetchall()
        if not found:
            raise ArchiveError(f"no measurement {id_or_prefix!r} in the archive {self.location}")
        if len(found) > 1:
            shown = ", ".join(f[0] for f in found[:5]) + (" ..." if len(found) > 5 else "")
            raise ArchiveError(f"{id_or_prefix!r} matches {len(found)} or more measurements ({shown}): give more "
                               "of the id")
        return check_id(found[0][0]), one_line_text(found[0][1], f"row of {found[0][0]}: folder")

    def get(self, id_or_prefix: str) -> ServerMeasurement:
        mid, folder_name = self.resolve(id_or_prefix)
        with self._session(f"reading {mid}") as conn:
            (record,) = conn.execute("SELECT record FROM measurements WHERE id = %s", (mid,)).fetchone()
            files = {role: (name, lo, size, sha) for role, name, lo, size, sha in conn.execute(
                "SELECT role, name, lo, size, sha256 FROM files WHERE measurement_id = %s", (mid,)).fetchall()}
        folder = inside(self.cache, folder_name)
        folder.mkdir(parents=True, exist_ok=True)
        (folder / RECORD_FILE).write_text(json.dumps(record, indent=1, ensure_ascii=False) + "\n")
        record = read_record(folder)         # the server's record, checked as a file's would be

        def fetch(role: str) -> Path | None:
            if role not in files:
                return None
            name, lo, size, sha = files[role]
            target = inside(folder, name)
            with self._session(f"reading the {role} of {mid}") as conn:
                return fetch_file(conn, lo, size, sha, target, f"{self.location}: {mid}: {role}")
        return ServerMeasurement(entry_of(record), folder, record, fetch)

    def export(self, id_or_prefix: str, directory) -> Path:
        m = self.get(id_or_prefix)
        for role in m.record.get("files", {}):
            m.path(role)
        return export_folder(m.folder, directory)

    def rebuild(self):
        raise ArchiveError(f"{self.location}: a PostgreSQL archive has no index to rebuild: its tables are the "
                           "archive ('linpar archive sync' sends this station's local queue)")

    # --- limits and golden units -----------------------------------------------------------------

    def _newest_limits(self, conn) -> LimitsVersion | None:
        rows = self._versions(conn, "ORDER BY version DESC LIMIT 1")
        return rows[-1] if rows else None

    def _versions(self, conn, tail: str, args=()) -> list[LimitsVersion]:
        rows = conn.execute("SELECT version, name, document, note, created_at, created_by FROM limits_versions "
                            + tail, args).fetchall()
        return [version_of_json({"format": "linpar-limits-version/1", "version": v, "limits": doc, "note": note,
                                 "created_at": at.isoformat(timespec="seconds").replace("+00:00", "Z"),
                                 "created_by": by}, f"{self.location}: limits v{v}")
                for v, _name, doc, note, at, by in rows]

    def limits_versions(self) -> list[LimitsVersion]:
        with self._session("reading the limits") as conn:
            return self._versions(conn, "ORDER BY version")

    def limits(self, version: int | None = None) -> LimitsVersion | None:
        with self._session("reading the limits") as conn:
            if version is None:
                return self._newest_limits(conn)
            found = self._versions(conn, "WHERE version = %s", (int(version),))
        if not found:
            raise ArchiveError(f"no limits version {version} in the archive {self.location}")
        return found[0]

    def store_limits(self, document, note: str = "") -> LimitsVersion:
        from psycopg.types.json import Jsonb
        document, name = checked_document(document)
        note = checked_note(note)
        with self._session("storing a limits version", needs="an engineer") as conn:
            (version,) = conn.execute("INSERT INTO limits_versions (name, document, note) VALUES (%s, %s, %s) "
                                      "RETURNING version", (name, Jsonb(document), note)).fetchone()
            stored = self._versions(conn, "WHERE version = %s", (version,))[0]
        self.outbox.remember_limits(stored)
        return stored

    def golden(self) -> list[str]:
        with self._session("reading the golden units") as conn:
            return [r[0] for r in conn.execute("SELECT measurement_id FROM golden_units "
                                                "ORDER BY marked").fetchall()]

    def set_golden(self, ids: Iterable[str], golden: bool = True) -> list[str]:
        wanted = [self.resolve(i)[0] for i in ids]
        with self._session("changing the golden units", needs="an engineer") as conn:
            with conn.transaction(), conn.cursor() as cur:
                if golden:
                    cur.executemany("INSERT INTO golden_units (measurement_id) VALUES (%s) ON CONFLICT DO NOTHING",
                                    [(i,) for i in wanted])
                else:
                    cur.execute("DELETE FROM golden_units WHERE measurement_id = ANY(%s)", (wanted,))
        return self.golden()

    # --- statistics -------------------------------------------------------------------------------

    def population(self, selection=None, names=None, with_stds: bool = True):
        from analysis.archive.population import Selection
        from analysis.archive.population_read import read_postgres
        with self._session("reading the population") as conn:
            population = read_postgres(conn, selection or Selection(), names, with_stds)
        self._waiting_note()
        return population
