"""Reading a population (analysis.archive.population) in bulk: each parameter as one array, never value by value.

`linpar qa stats` over a line's 100,000 units must take about a second, and
turning 2.4 million numbers into Python objects one at a time takes more than
that alone. So the key parameters are also columns of the measurement's own
row (analysis.archive.schema.value_column, written with it): one statement
gives one row per unit, without joining the 1.2 million parameter rows or
grouping, and the numbers go into arrays a column at a time. PostgreSQL sends
each row's numbers packed in one bytea, the doubles as they are (float8send,
big-endian), which numpy reads in one go: 100,000 rows of 12 numbers as 1.2
million Python floats and tuples cost a tenth of a second more. One
statement: one snapshot.

Both order the units by (measured_at, id): oldest first, ties broken the same
way every time. Values are exact: binary doubles on PostgreSQL, the REAL
column's own double on SQLite (never through text).
"""
from __future__ import annotations

import contextlib
import gc

import numpy as np

from analysis.archive.names import ArchiveError
from analysis.archive.population import Population, Selection, finite_or_nan
from analysis.archive.schema import KEY_PARAMETERS, measured_until, std_column, value_column

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
        args.append(measured_until(selection.until))
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


def _number_columns(names, with_stds: bool) -> list[str]:
    return [c for n in names for c in ((value_column(n), std_column(n)) if with_stds else (value_column(n),))]


def population_sql(names, with_stds: bool, where: str) -> str:
    """One row per unit, oldest first: HEADS, then each name's value (and std) from the measurement's own
    columns (schema.value_column): no join, no grouping."""
    numbers = _number_columns(names, with_stds)
    return f"SELECT {', '.join(f'm.{c}' for c in (*HEADS, *numbers))} FROM measurements m{where} ORDER BY {ORDER}"


def packed_population_sql(names, with_stds: bool, where: str) -> str:
    """population_sql for PostgreSQL with the numbers of a row in one bytea: each double's 8 bytes as
    float8send gives them (big-endian), NaN for NULL (|| of a NULL would make the whole row's NULL)."""
    numbers = _number_columns(names, with_stds)
    packed = " || ".join(f"float8send(coalesce(m.{c}, 'NaN'))" for c in numbers)
    return (f"SELECT {', '.join(f'm.{c}' for c in HEADS)}{', ' + packed if packed else ''} FROM measurements m"
            f"{where} ORDER BY {ORDER}")


@contextlib.contextmanager
def _collector_paused():
    """Python's cycle collector paused while the rows are read: 100,000 rows are 100,000 new tuples (none in a
    cycle), and the collector would walk them, and every object already there, several times over."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def read_sqlite(conn, selection: Selection, names=None, with_stds: bool = True) -> Population:
    """The population from an index (a sqlite3 connection): one statement, one row per unit."""
    names = checked_names(names)
    where, args = where_clause(selection, "?")
    with _collector_paused():
        return _from_rows(conn.execute(population_sql(names, with_stds, where), args).fetchall(), names, with_stds)


def read_postgres(conn, selection: Selection, names=None, with_stds: bool = True) -> Population:
    """The population from the server (a psycopg connection, search_path linpar): one statement, binary rows."""
    names = checked_names(names)
    where, args = where_clause(selection, "%s")
    with _collector_paused():
        rows = conn.cursor(binary=True).execute(packed_population_sql(names, with_stds, where), args).fetchall()
        return _from_packed_rows(rows, names, with_stds)


def _from_rows(rows, names, with_stds: bool) -> Population:
    """Rows of HEADS then each name's value (and std) -> a Population, the numbers a column at a time."""
    by_column = list(zip(*rows)) if rows else [()] * (len(HEADS) + len(names) * (2 if with_stds else 1))
    numbers = iter(by_column[len(HEADS):])
    values, stds = {}, {}
    for name in names:
        values[name] = finite_or_nan(np.array(next(numbers), dtype=float))     # None (no row, NULL): NaN
        if with_stds:
            stds[name] = finite_or_nan(np.array(next(numbers), dtype=float))
    return _population(by_column[:len(HEADS)], values, stds)


def _from_packed_rows(rows, names, with_stds: bool) -> Population:
    """Rows of HEADS then one bytea of the numbers (packed_population_sql) -> a Population."""
    per_row = len(names) * (2 if with_stds else 1)
    by_column = list(zip(*rows)) if rows else [()] * (len(HEADS) + 1)
    numbers = (np.frombuffer(b"".join(by_column[len(HEADS)]), dtype=">f8").reshape(len(rows), per_row)
               if per_row else np.empty((len(rows), 0)))
    columns = iter(numbers.T)
    values, stds = {}, {}
    for name in names:
        values[name] = finite_or_nan(next(columns))        # a copy in native byte order
        if with_stds:
            stds[name] = finite_or_nan(next(columns))
    return _population(by_column[:len(HEADS)], values, stds)
