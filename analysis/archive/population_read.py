"""Reading a population (analysis.archive.population) in bulk: each parameter as one array, never value by value.

`linpar qa stats` over a line's 100,000 units must take about a second, and
turning 2.4 million numbers into Python objects one at a time takes more than
that alone. So each back end hands its numbers over in the cheapest way it has:

PostgreSQL  the server packs each parameter's (position, value, std) into one
            bytea of fixed-size binary records (int4send, float8send: network
            byte order), read as one numpy structured array; the who, where and
            when (strings) come as plain rows. The two queries run in one
            REPEATABLE READ transaction, so that both see the same units and
            the positions, row numbers in the time order, match.
SQLite      the sqlite3 module can only give rows, so one statement gives one
            row per unit with its parameters beside it (a left join per
            parameter on the key (measurement_id, name): no grouping) and the
            numbers go into arrays column by column. One statement: one
            snapshot.

Both order the units by (measured_at, id): oldest first, ties broken the same
way every time. Values are exact: binary doubles on PostgreSQL, the REAL
column's own double on SQLite (never through text).
"""
from __future__ import annotations

import numpy as np

from analysis.archive.names import ArchiveError
from analysis.archive.population import Population, Selection, finite_or_nan
from analysis.archive.schema import KEY_PARAMETERS

# The columns that say who, where and when, in the order the readers select them (Population's first fields).
HEADS = ("id", "measured_at", "station", "driver", "serial", "operator", "validity", "verdict", "limits_version")
ORDER = "m.measured_at, m.id"


def checked_names(names) -> tuple[str, ...]:
    names = tuple(KEY_PARAMETERS if names is None else names)
    unknown = [n for n in names if n not in KEY_PARAMETERS]
    if unknown:
        raise ArchiveError(f"{', '.join(unknown)}: not a parameter the archive keeps for statistics "
                           f"(expected one of {', '.join(KEY_PARAMETERS)})")
    return names


def where_clause(selection: Selection, mark: str) -> tuple[str, list]:
    """(' WHERE ...' or '', its arguments) selecting `measurements m`; `mark` is the driver's placeholder."""
    where, args = [], []
    if selection.since:
        where.append(f"m.measured_at >= {mark}")
        args.append(selection.since)
    if selection.until:
        where.append(f"m.measured_at <= {mark}")
        args.append(selection.until + ("T99" if len(selection.until) == 10 else ""))   # a bare date: all of it
    for column, chosen in (("station", selection.stations), ("driver", selection.drivers), ("id", selection.ids)):
        if chosen:
            where.append(f"m.{column} IN ({', '.join([mark] * len(chosen))})")
            args.extend(chosen)
    return (" WHERE " + " AND ".join(where) if where else ""), args


def _population(heads, values: dict, stds: dict) -> Population:
    return Population(*(tuple(column) for column in heads), values=values, stds=stds)


def empty_population(names=None, with_stds: bool = True) -> Population:
    names = checked_names(names)
    return _population([()] * len(HEADS), {n: () for n in names}, {n: () for n in names} if with_stds else {})


# --- SQLite ------------------------------------------------------------------------------------------


def read_sqlite(conn, selection: Selection, names=None, with_stds: bool = True) -> Population:
    """The population from an index (a sqlite3 connection): one statement, one row per unit."""
    names = checked_names(names)
    where, args = where_clause(selection, "?")
    selected = [f"m.{c}" for c in HEADS]
    for i in range(len(names)):
        selected += [f"p{i}.value", f"p{i}.std"] if with_stds else [f"p{i}.value"]
    joins = "".join(f" LEFT JOIN parameters p{i} ON p{i}.measurement_id = m.id AND p{i}.name = ?"
                    for i in range(len(names)))
    sql = f"SELECT {', '.join(selected)} FROM measurements m{joins}{where} ORDER BY {ORDER}"
    rows = conn.execute(sql, [*names, *args]).fetchall()
    by_column = list(zip(*rows)) if rows else [()] * (len(HEADS) + len(names) * (2 if with_stds else 1))
    numbers = iter(by_column[len(HEADS):])
    values, stds = {}, {}
    for name in names:
        values[name] = finite_or_nan(np.array(next(numbers), dtype=float))     # None (no row, NULL): NaN
        if with_stds:
            stds[name] = finite_or_nan(np.array(next(numbers), dtype=float))
    return _population(by_column[:len(HEADS)], values, stds)


# --- PostgreSQL --------------------------------------------------------------------------------------

_RECORD = [("position", ">i4"), ("value", ">f8")]
_RECORD_STD = _RECORD + [("std", ">f8")]


def packed_sql(where: str, with_stds: bool) -> str:
    """Per parameter one bytea of records (position in the time order, value[, std]); NULL packed as NaN."""
    record = "int4send(c.k) || float8send(coalesce(p.value, 'NaN'))"
    if with_stds:
        record += " || float8send(coalesce(p.std, 'NaN'))"
    return (f"SELECT p.name, string_agg({record}, ''::bytea) "
            f"FROM (SELECT m.id, (row_number() OVER (ORDER BY {ORDER}) - 1)::int4 AS k FROM measurements m{where}) c "
            f"JOIN parameters p ON p.measurement_id = c.id WHERE p.name = ANY(%s) GROUP BY p.name")


def read_postgres(conn, selection: Selection, names=None, with_stds: bool = True) -> Population:
    """The population from the server (a psycopg connection in autocommit, search_path linpar)."""
    from psycopg import IsolationLevel
    names = checked_names(names)
    where, args = where_clause(selection, "%s")
    conn.isolation_level, conn.read_only = IsolationLevel.REPEATABLE_READ, True
    try:
        with conn.transaction():
            heads = conn.execute(f"SELECT {', '.join(f'm.{c}' for c in HEADS)} FROM measurements m{where} "
                                 f"ORDER BY {ORDER}", args).fetchall()
            packed = conn.cursor(binary=True).execute(packed_sql(where, with_stds), [*args, list(names)]).fetchall()
    finally:
        conn.isolation_level, conn.read_only = None, None
    n = len(heads)
    values = {name: np.full(n, np.nan) for name in names}
    stds = {name: np.full(n, np.nan) for name in names} if with_stds else {}
    for name, blob in packed:
        records = np.frombuffer(blob, dtype=_RECORD_STD if with_stds else _RECORD)
        values[name][records["position"]] = records["value"]
        if with_stds:
            stds[name][records["position"]] = records["std"]
    for column in (*values.values(), *stds.values()):
        column[~np.isfinite(column)] = np.nan           # an infinity the server kept judges nothing
    return _population(zip(*heads) if heads else [()] * len(HEADS), values, stds)
