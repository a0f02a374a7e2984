"""A population of stored measurements for statistics: who, where, when, the verdict and the key parameters.

`Selection` says which measurements (dates, stations, drivers, ids: exact
names, not the substrings `archive list` matches: statistics of "QA1" must
not take "QA10"). `population_sql` is the one query both back ends run
(SQLite and PostgreSQL speak the same SQL here, but for the parameter mark):
one row per measurement, its parameters pivoted into columns by the
database, oldest first, so that a control chart reads them in the order they
were measured. No numpy here: the statistics turn the columns into arrays.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from datetime import datetime, timezone

from analysis.archive.names import ArchiveError, check_id_prefix
from analysis.archive.record import one_line_text
from analysis.archive.schema import KEY_PARAMETERS
from analysis.bounds import YEAR

# The row's leading columns, in the order population_sql selects them.
COLUMNS = ("id", "measured_at", "station", "driver", "serial", "operator", "validity", "verdict", "limits_version")


def selection_date(text: str | None, option: str) -> str | None:
    """A date or date-time from a user as the archive compares it: 'YYYY-MM-DD' (a UTC day) or UTC
    'YYYY-MM-DDTHH:MM:SSZ'; ArchiveError (one line naming the option) otherwise."""
    if text is None:
        return None
    text = str(text).strip()
    try:
        when = datetime.fromisoformat(text)
    except ValueError:
        raise ArchiveError(f"{option}: {text[:40]!r} is not a date: expected ISO 8601, e.g. 2024-05-01 or "
                           "2024-05-01T08:00:00+02:00") from None
    YEAR.check(when.year, option, ArchiveError)
    if len(text) == 10:
        return when.date().isoformat()
    if when.tzinfo is None:
        when = when.replace(tzinfo=timezone.utc)
    return when.astimezone(timezone.utc).isoformat(timespec="seconds").replace("+00:00", "Z")


@dataclass(frozen=True)
class Selection:
    since: str | None = None                # inclusive; a bare date means from its first second (UTC)
    until: str | None = None                # inclusive; a bare date means to its last second
    stations: tuple[str, ...] = ()          # exact names; empty: every station
    drivers: tuple[str, ...] = ()
    ids: tuple[str, ...] = ()               # exact ids; empty: every measurement

    def checked(self) -> "Selection":
        for i in self.ids:
            check_id_prefix(i)
        for name in (*self.stations, *self.drivers):
            one_line_text(name, "a station or driver name")
        return Selection(selection_date(self.since, "--since"), selection_date(self.until, "--until"),
                         tuple(self.stations), tuple(self.drivers), tuple(self.ids))

    def describe(self) -> str:
        parts = [f"since {self.since}" if self.since else "", f"until {self.until}" if self.until else "",
                 f"station {', '.join(self.stations)}" if self.stations else "",
                 f"driver {', '.join(self.drivers)}" if self.drivers else "",
                 f"{len(self.ids)} chosen measurement(s)" if self.ids else ""]
        return ", ".join(p for p in parts if p) or "every measurement"


@dataclass(frozen=True)
class Population:
    """Columns of equal length, oldest measurement first; a parameter not measured is None."""

    ids: tuple[str, ...]
    measured_at: tuple[str, ...]
    stations: tuple[str, ...]
    drivers: tuple[str, ...]
    serials: tuple[str, ...]
    operators: tuple[str, ...]
    validity: tuple[str, ...]
    verdicts: tuple[str | None, ...]
    limits_versions: tuple[int | None, ...]
    values: dict[str, tuple[float | None, ...]] = field(default_factory=dict)    # SI
    stds: dict[str, tuple[float | None, ...]] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.ids)


def population_sql(selection: Selection, names=None, mark: str = "?") -> tuple[str, list, tuple[str, ...]]:
    """(SQL, arguments, parameter names) of the selection's population; `mark` is the driver's placeholder."""
    names = tuple(KEY_PARAMETERS if names is None else names)
    unknown = [n for n in names if n not in KEY_PARAMETERS]
    if unknown:
        raise ArchiveError(f"{', '.join(unknown)}: not a parameter the archive keeps for statistics "
                           f"(expected one of {', '.join(KEY_PARAMETERS)})")
    where, args = [], []
    if selection.since:
        where.append(f"m.measured_at >= {mark}")
        args.append(selection.since)
    if selection.until:
        where.append(f"m.measured_at <= {mark}")
        args.append(selection.until + ("T99" if len(selection.until) == 10 else ""))
    for column, chosen in (("station", selection.stations), ("driver", selection.drivers), ("id", selection.ids)):
        if chosen:
            where.append(f"m.{column} IN ({', '.join([mark] * len(chosen))})")
            args.extend(chosen)
    pivot = []
    for name in names:
        pivot.append(f"max(CASE WHEN p.name = {mark} THEN p.value END)")
        pivot.append(f"max(CASE WHEN p.name = {mark} THEN p.std END)")
    pivot_args = [n for name in names for n in (name, name)]
    sql = (f"SELECT {', '.join('m.' + c for c in COLUMNS)}{', ' if pivot else ''}{', '.join(pivot)} "
           f"FROM measurements m LEFT JOIN parameters p ON p.measurement_id = m.id"
           f"{' WHERE ' + ' AND '.join(where) if where else ''} "
           f"GROUP BY {', '.join('m.' + c for c in COLUMNS)} ORDER BY m.measured_at, m.id")
    return sql, pivot_args + args, names


def population_of_rows(rows, names) -> Population:
    n = len(COLUMNS)
    columns = list(zip(*rows)) if rows else [()] * (n + 2 * len(names))
    values = {name: tuple(_finite(v) for v in columns[n + 2 * i]) for i, name in enumerate(names)}
    stds = {name: tuple(_finite(v) for v in columns[n + 2 * i + 1]) for i, name in enumerate(names)}
    head = [tuple(c) for c in columns[:n]]
    return Population(*head, values=values, stds=stds)


def _finite(v) -> float | None:
    # The index keeps what measurement.json said, checked finite where it entered (analysis.archive.record).
    if v is None:
        return None
    v = float(v)
    return v if v == v and abs(v) != float("inf") else None
