"""A population of stored measurements for statistics: who, where, when, the verdict and the key parameters.

`Selection` says which measurements (dates, stations, drivers, ids: exact
names, not the substrings `archive list` matches: statistics of "QA1" must
not take "QA10"). `Population` is what the archive gives for them, oldest
first, so that a control chart reads them in the order they were measured:
the who, where and when as columns of strings, each parameter as one float
array. How each back end reads it in bulk: analysis.archive.population_read.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from datetime import datetime, timezone

import numpy as np

from analysis.archive.names import ArchiveError, check_id_prefix
from analysis.archive.record import one_line_text
from analysis.bounds import YEAR


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
    """Columns of equal length, oldest measurement first.

    A parameter's values (SI) and standard deviations are one float array each, aligned with `ids`; NaN where
    the measurement has no finite value (not measured, or undetermined). Arrays, not a row per unit: a line's
    100,000 units are read in bulk and the statistics stay in numpy (analysis.archive.population_read).
    Sequences with None (as tests write them) are taken too and turned into such arrays.
    """

    ids: tuple[str, ...]
    measured_at: tuple[str, ...]
    stations: tuple[str, ...]
    drivers: tuple[str, ...]
    serials: tuple[str, ...]
    operators: tuple[str, ...]
    validity: tuple[str, ...]
    verdicts: tuple[str | None, ...]
    limits_versions: tuple[int | None, ...]
    values: dict[str, np.ndarray] = field(default_factory=dict)    # SI
    stds: dict[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self):
        object.__setattr__(self, "values", {n: finite_or_nan(v) for n, v in self.values.items()})
        object.__setattr__(self, "stds", {n: finite_or_nan(v) for n, v in self.stds.items()})

    def __len__(self) -> int:
        return len(self.ids)

    def value(self, name: str, unit: int) -> float | None:
        """The unit's value of the parameter; None when it has none."""
        return _number(self.values[name][unit])

    def std(self, name: str, unit: int) -> float | None:
        return _number(self.stds[name][unit]) if name in self.stds else None


def finite_or_nan(numbers) -> np.ndarray:
    """A float array of `numbers` (None, NaN and infinities: NaN). The archive keeps what measurement.json
    said, checked finite where it entered (analysis.archive.record); a non-finite value judges nothing."""
    x = np.array([np.nan if v is None else v for v in numbers] if not isinstance(numbers, np.ndarray) else numbers,
                 dtype=float)
    x[~np.isfinite(x)] = np.nan
    return x


def _number(v) -> float | None:
    return None if v != v else float(v)
