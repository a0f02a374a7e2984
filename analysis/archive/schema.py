"""The index's SQLite schema: a schema_version table and ordered migrations.

MIGRATIONS[i] takes a database from version i to version i + 1; a new
database runs them all. Each runs in its own transaction together with the
version update, so a crash leaves the database at one version or the next,
never between. Add a migration at the end; never edit one that has shipped.

The index is a cache of the folders (every fact in it is also in a
measurement.json), so a database that is unreadable, or of a schema this
program does not know, is set aside and rebuilt rather than repaired.
"""
from __future__ import annotations

import sqlite3
from typing import Callable

# The parameters copied into the index for listing, filtering and comparing.
KEY_PARAMETERS = ("RE", "LE", "fs", "Bl", "Mms", "Cms", "Rms", "Qms", "Qes", "Qts", "Vas", "SPL_2.83V_1m")


def value_column(name: str) -> str:
    """The measurements table's column with a key parameter's value, quoted for SQL ("RE", "SPL_2.83V_1m").

    Both back ends keep each key parameter's value and standard deviation beside the measurement's row too
    (SQLite schema 4, PostgreSQL schema 2): the statistics read one row per unit, without joining 1.2
    million parameter rows (`qa stats` over 100,000 units in about a second). The parameters table stays
    what listing and comparing read; both are written together, in one transaction."""
    return '"' + name.replace('"', '""') + '"'


def std_column(name: str) -> str:
    return value_column(name + "_std")


def measured_until(until: str) -> str:
    """The upper bound of measured_at (ISO text) for an inclusive "until": a bare date means the whole day."""
    return until + ("T99" if len(until) == 10 else "")


def _v1(conn: sqlite3.Connection) -> None:
    conn.execute("""CREATE TABLE measurements (
        id TEXT PRIMARY KEY,
        folder TEXT NOT NULL UNIQUE,
        measured_at TEXT NOT NULL,
        stored_at TEXT NOT NULL,
        driver TEXT NOT NULL,
        serial TEXT NOT NULL,
        operator TEXT NOT NULL,
        station TEXT NOT NULL,
        validity TEXT NOT NULL)""")
    conn.execute("""CREATE TABLE parameters (
        measurement_id TEXT NOT NULL REFERENCES measurements(id) ON DELETE CASCADE,
        name TEXT NOT NULL,
        value REAL,
        std REAL,
        unit TEXT NOT NULL,
        PRIMARY KEY (measurement_id, name))""")


def _v2(conn: sqlite3.Connection) -> None:
    # Listing is newest first and filters by driver: index both.
    conn.execute("ALTER TABLE measurements ADD COLUMN effects TEXT NOT NULL DEFAULT ''")
    conn.execute("CREATE INDEX measurements_by_date ON measurements(measured_at)")
    conn.execute("CREATE INDEX measurements_by_driver ON measurements(driver, serial)")


def _v3(conn: sqlite3.Connection) -> None:
    # Production QA: each measurement's verdict and the limits version that judged it; statistics select
    # by station and by date.
    conn.execute("ALTER TABLE measurements ADD COLUMN verdict TEXT")
    conn.execute("ALTER TABLE measurements ADD COLUMN limits_version INTEGER")
    conn.execute("CREATE INDEX measurements_by_station ON measurements(station, measured_at)")


def _v4(conn: sqlite3.Connection) -> None:
    # The key parameters beside the measurement's row (value_column): filled from the parameters table.
    for name in KEY_PARAMETERS:
        for column, source in ((value_column(name), "value"), (std_column(name), "std")):
            conn.execute(f"ALTER TABLE measurements ADD COLUMN {column} REAL")
            conn.execute(f"UPDATE measurements SET {column} = (SELECT p.{source} FROM parameters p "
                         f"WHERE p.measurement_id = measurements.id AND p.name = ?)", (name,))


MIGRATIONS: tuple[Callable[[sqlite3.Connection], None], ...] = (_v1, _v2, _v3, _v4)
CURRENT_VERSION = len(MIGRATIONS)
# What a database of the current version must have (checked on open).
EXPECTED_COLUMNS = {
    "measurements": {"id", "folder", "measured_at", "stored_at", "driver", "serial", "operator", "station",
                     "validity", "effects", "verdict", "limits_version",
                     *(name + suffix for name in KEY_PARAMETERS for suffix in ("", "_std"))},
    "parameters": {"measurement_id", "name", "value", "std", "unit"},
}


class SchemaError(Exception):
    """The database is not a linpar index this program can use."""


def version_of(conn: sqlite3.Connection) -> int:
    tables = {row[0] for row in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
    if "schema_version" not in tables:
        if tables:
            raise SchemaError(f"tables {sorted(tables)} but no schema_version: not a linpar index")
        return 0
    rows = conn.execute("SELECT version FROM schema_version").fetchall()
    if len(rows) != 1 or not isinstance(rows[0][0], int):
        raise SchemaError("schema_version must hold exactly one integer")
    return rows[0][0]


def migrate(conn: sqlite3.Connection) -> int:
    """Bring the database to CURRENT_VERSION; return the version it had."""
    start = version_of(conn)
    if start > CURRENT_VERSION:
        raise SchemaError(f"schema version {start} is newer than this program's {CURRENT_VERSION}")
    for version in range(start, CURRENT_VERSION):
        with conn:   # one transaction: the migration and the new version number
            if version == 0:
                conn.execute("CREATE TABLE schema_version (version INTEGER NOT NULL)")
                conn.execute("INSERT INTO schema_version VALUES (0)")
            MIGRATIONS[version](conn)
            conn.execute("UPDATE schema_version SET version = ?", (version + 1,))
    return start


def check_columns(conn: sqlite3.Connection) -> None:
    for table, wanted in EXPECTED_COLUMNS.items():
        have = {row[1] for row in conn.execute(f"PRAGMA table_info({table})")}
        if not wanted <= have:
            raise SchemaError(f"table {table} lacks {sorted(wanted - have)}")
