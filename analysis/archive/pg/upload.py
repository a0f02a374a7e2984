"""One measurement sent to the server in one transaction: its row, its parameters, its files; or nothing.

The row is inserted with ON CONFLICT (id) DO NOTHING: when two senders race
with one id, PostgreSQL makes the second wait for the first and then tells it
the id is taken; the record's SHA-256 then says whether it is the same
measurement (sent before: nothing to do) or another one (analysis.archive.pg.outbox
gives it a new id).
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

from analysis.archive.names import ArchiveError, inside
from analysis.archive.pg.files import send_file
from analysis.archive.record import entry_of
from analysis.archive.schema import KEY_PARAMETERS, std_column, value_column

SENT, ALREADY = "sent", "already"


class IdTaken(ArchiveError):
    """The server holds another measurement under this id (the outbox then draws another one)."""


def canonical(record: dict) -> bytes:
    return json.dumps(record, sort_keys=True, separators=(",", ":"), ensure_ascii=False,
                      allow_nan=False).encode("utf-8")


def record_sha256(record: dict) -> str:
    return hashlib.sha256(canonical(record)).hexdigest()


def send_measurement(conn, record: dict, folder: Path) -> str:
    """SENT, or ALREADY when the server has this very record; IdTaken when it has another under its id."""
    from psycopg.types.json import Jsonb
    digest = record_sha256(record)
    e = entry_of(record)
    kept = {name: p for name in KEY_PARAMETERS if (p := e.parameters.get(name)) is not None}
    columns = ["id", "folder", "measured_at", "stored_at", "driver", "serial", "operator", "station", "validity",
               "effects", "verdict", "limits_version", "record", "record_sha256"]
    values = [e.id, e.folder, e.measured_at, e.stored_at, e.driver, e.serial, e.operator, e.station, e.validity,
              ",".join(e.effects), e.verdict, e.limits_version, Jsonb(record), digest]
    for name, p in kept.items():        # the statistics' copy of the key parameters (schema version 2)
        columns += [value_column(name), std_column(name)]
        values += [p.get("value"), p.get("std")]
    with conn.transaction():
        row = conn.execute(
            f"INSERT INTO measurements ({', '.join(columns)}) VALUES ({', '.join(['%s'] * len(values))}) "
            "ON CONFLICT (id) DO NOTHING RETURNING id", values).fetchone()
        if row is None:
            existing = conn.execute("SELECT record_sha256 FROM measurements WHERE id = %s", (e.id,)).fetchone()
            if existing is not None and existing[0] == digest:
                return ALREADY
            raise IdTaken(e.id)
        rows = [(e.id, name, p.get("value"), p.get("std"), str(p.get("unit", ""))) for name, p in kept.items()]
        if rows:
            with conn.cursor() as cur:
                cur.executemany("INSERT INTO parameters (measurement_id, name, value, std, unit) "
                                "VALUES (%s, %s, %s, %s, %s)", rows)
        for role, name in record.get("files", {}).items():
            send_file(conn, e.id, role, name, inside(folder, name))
    return SENT
