"""The population read in bulk (analysis.archive.population_read) gives exactly what the row-by-row reading gave.

The reference below is the reading `qa stats` used before: one pivot query
(a row per unit, a column per parameter, grouped by the database) and every
value turned into a Python float or None one at a time. Both back ends, a
small population with what makes alignment go wrong: a parameter missing on
one unit, a null value on another, units of several stations and drivers,
failed verdicts, and selections by station, driver and date.
"""
import math

import numpy as np
import pytest

from analysis.archive.backends import open_archive
from analysis.archive.population import Population, Selection
from analysis.archive.schema import KEY_PARAMETERS
from analysis.production import production_stats
from tests.production_helpers import LIMITS, small_measurement, unit

HEADS = ("id", "measured_at", "station", "driver", "serial", "operator", "validity", "verdict", "limits_version")


def reference_population(conn, selection: Selection, mark: str) -> Population:
    """The former reading: the pivot query and the values converted one by one."""
    where, args = [], []
    if selection.since:
        where.append(f"m.measured_at >= {mark}")
        args.append(selection.since)
    if selection.until:
        where.append(f"m.measured_at <= {mark}")
        args.append(selection.until + ("T99" if len(selection.until) == 10 else ""))
    for column, chosen in (("station", selection.stations), ("driver", selection.drivers)):
        if chosen:
            where.append(f"m.{column} IN ({', '.join([mark] * len(chosen))})")
            args.extend(chosen)
    pivot = [f"max(CASE WHEN p.name = {mark} THEN p.{c} END)" for _n in KEY_PARAMETERS for c in ("value", "std")]
    sql = (f"SELECT {', '.join('m.' + c for c in HEADS)}, {', '.join(pivot)} FROM measurements m "
           f"LEFT JOIN parameters p ON p.measurement_id = m.id{' WHERE ' + ' AND '.join(where) if where else ''} "
           f"GROUP BY {', '.join('m.' + c for c in HEADS)} ORDER BY m.measured_at, m.id")
    rows = conn.execute(sql, [n for n in KEY_PARAMETERS for _c in ("value", "std")] + args).fetchall()
    columns = list(zip(*rows)) if rows else [()] * (len(HEADS) + 2 * len(KEY_PARAMETERS))

    def finite(v):
        return None if v is None or not math.isfinite(float(v)) else float(v)
    n = len(HEADS)
    values = {name: tuple(finite(v) for v in columns[n + 2 * i]) for i, name in enumerate(KEY_PARAMETERS)}
    stds = {name: tuple(finite(v) for v in columns[n + 2 * i + 1]) for i, name in enumerate(KEY_PARAMETERS)}
    return Population(*(tuple(c) for c in columns[:n]), values=values, stds=stds)


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    return small_measurement(tmp_path_factory.mktemp("unit"))


@pytest.fixture(params=["folder", "postgresql"])
def archive_and_connection(request, tmp_path):
    """(archive, a function giving a raw connection to its database, the driver's placeholder)."""
    if request.param == "folder":
        import sqlite3
        root = tmp_path / "archive"
        return open_archive(str(root)), lambda: sqlite3.connect(root / "index.sqlite"), "?"
    import psycopg
    db = request.getfixturevalue("pg_database")
    return (open_archive(db.url("eva")),
            lambda: psycopg.connect(db.url("eva"), autocommit=True, options="-c search_path=linpar"), "%s")


def _store_population(archive, measured):
    path, doc = measured
    archive.store_limits(LIMITS)
    rng = np.random.default_rng(7)
    for i in range(40):
        values = {"fs": 70.5 + rng.normal(0, 1.5) + (8.0 if i % 13 == 5 else 0.0),      # some fail the limits
                  "RE": 3.0 * (1 + rng.normal(0, 0.01)), "Qts": 0.45 + rng.normal(0, 0.01)}
        document = unit(doc, **values)
        if i == 7:
            del document["parameters"]["Bl"]                  # not measured on this unit
        if i == 11:
            document["parameters"]["Qts"]["value"] = None      # undetermined
        archive.store(path, document, {"station": ("QA1", "QA2", "QA10")[i % 3], "driver": ("W6", "W8")[i % 5 == 0],
                                       "serial": f"SN{i}", "measured_at": f"2024-06-{1 + i % 20:02d}T{i % 24:02d}:00:00Z"})


def _same_population(new: Population, old: Population) -> None:
    for column in ("ids", "measured_at", "stations", "drivers", "serials", "operators", "validity", "verdicts",
                   "limits_versions"):
        assert getattr(new, column) == getattr(old, column), column
    assert set(new.values) == set(old.values) and set(new.stds) == set(old.stds)
    for name in old.values:     # bit for bit, NaN (no value) at the same units
        assert np.array_equal(new.values[name], old.values[name], equal_nan=True), name
        assert np.array_equal(new.stds[name], old.stds[name], equal_nan=True), name


@pytest.mark.parametrize("selection", [Selection(), Selection(stations=("QA1",)), Selection(drivers=("W8",)),
                                       Selection(since="2024-06-05", until="2024-06-12", stations=("QA1", "QA10"))],
                         ids=["all", "station", "driver", "dates"])
def test_bulk_population_and_its_statistics_are_the_row_by_row_ones(archive_and_connection, measured, selection):
    archive, connect, mark = archive_and_connection
    _store_population(archive, measured)
    selection = selection.checked()
    conn = connect()
    try:
        old = reference_population(conn, selection, mark)
    finally:
        conn.close()
    new = archive.population(selection)
    assert len(new) > 0 and (len(new) == 40 or selection != Selection())
    assert np.isnan(new.values["Bl"]).sum() == (selection == Selection())     # the unit without Bl, if chosen
    _same_population(new, old)
    without_stds = archive.population(selection, with_stds=False)
    assert without_stds.stds == {}
    limits = archive.limits()
    assert production_stats(without_stds, limits).as_json() == production_stats(old, limits).as_json()


def _back_to_the_schema_without_columns(archive_and_connection, request) -> None:
    """Make the archive what the previous schema made: no key parameter columns on measurements."""
    from analysis.archive.schema import std_column, value_column
    drops = [f"DROP COLUMN {c(n)}" for n in KEY_PARAMETERS for c in (value_column, std_column)]
    archive, connect, mark = archive_and_connection
    if mark == "?":
        conn = connect()
        with conn:
            for drop in drops:
                conn.execute(f"ALTER TABLE measurements {drop}")
            conn.execute("UPDATE schema_version SET version = 3")
        conn.close()
        return
    with request.getfixturevalue("pg_database").admin() as conn:
        conn.execute(f"ALTER TABLE linpar.measurements {', '.join(drops)}")
        conn.execute(WITHOUT_THE_AUDIT_TRAIL)          # versions 3 and 4's, which setup then adds again
        conn.execute("UPDATE linpar.schema_version SET version = 1")


# What the audit migrations (analysis/archive/pg/audit.py, schema versions 3 and 4) add, taken away again.
WITHOUT_THE_AUDIT_TRAIL = """
ALTER TABLE linpar.measurements DROP CONSTRAINT names_without_bidi_controls;
ALTER TABLE linpar.limits_versions DROP CONSTRAINT name_without_bidi_controls;
DROP TRIGGER stamp ON linpar.measurements; DROP TRIGGER stamp ON linpar.limits_versions;
DROP TRIGGER stamp ON linpar.golden_units; DROP TRIGGER own ON linpar.parameters;
DROP FUNCTION linpar.stamp_measurement(), linpar.stamp_limits_version(), linpar.stamp_golden_unit(),
              linpar.own_measurement();
ALTER TABLE linpar.limits_versions DROP CONSTRAINT limits_document_checked;
ALTER TABLE linpar.measurements DROP CONSTRAINT names_one_line;
DROP FUNCTION linpar.limits_document_ok(jsonb, text);
"""


def test_an_archive_of_the_previous_schema_is_migrated_with_its_key_parameter_columns_filled(
        archive_and_connection, measured, request):
    """The columns the statistics read (SQLite schema 4, PostgreSQL 2) are filled from the parameters table:
    the population afterwards is the row-by-row one."""
    archive, connect, mark = archive_and_connection
    _store_population(archive, measured)
    _back_to_the_schema_without_columns(archive_and_connection, request)
    if mark == "%s":
        from analysis.archive.pg import ServerRefused, setup
        from tests.pg_server import ADMIN
        db = request.getfixturevalue("pg_database")
        with pytest.raises(ServerRefused, match="linpar archive setup"):      # a station asks for the migration
            open_archive(db.url("eva")).population()
        assert setup(db.server.url(ADMIN, db.name)).schema_from == 1
        archive = open_archive(db.url("eva"))
    else:
        archive = open_archive(str(archive.root))       # the index migrates as it is opened
    conn = connect()
    try:
        old = reference_population(conn, Selection(), mark)
        assert conn.execute("SELECT count(*) FROM measurements WHERE \"fs\" IS NOT NULL").fetchone()[0] == 40
    finally:
        conn.close()
    new = archive.population()
    assert len(new) == 40 and np.isnan(new.values["Bl"]).sum() == 1 and np.isnan(new.values["Qts"]).sum() == 1
    _same_population(new, old)


def test_some_parameters_and_an_empty_selection_read_alike(archive_and_connection, measured):
    """The numbers of a row are read by position (PostgreSQL packs them in one bytea): a subset of the
    parameters, with and without their standard deviations, and a selection of no unit."""
    archive, _connect, _mark = archive_and_connection
    _store_population(archive, measured)
    every = archive.population()
    for with_stds in (True, False):
        some = archive.population(names=("Qts", "fs"), with_stds=with_stds)
        assert list(some.values) == ["Qts", "fs"] and list(some.stds) == (["Qts", "fs"] if with_stds else [])
        for name in ("Qts", "fs"):
            assert np.array_equal(some.values[name], every.values[name], equal_nan=True), name
            if with_stds:
                assert np.array_equal(some.stds[name], every.stds[name], equal_nan=True), name
    nobody = archive.population(Selection(stations=("nobody",)).checked())
    assert len(nobody) == 0 and nobody.ids == ()
    assert all(v.shape == (0,) for v in (*nobody.values.values(), *nobody.stds.values()))
    assert set(nobody.values) == set(KEY_PARAMETERS)
