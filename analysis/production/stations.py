"""Which station reads high: each pair of stations compared by Welch's t test, and the station that differs
from every other one named.

For a parameter and each pair of stations (a, b) with at least two units each:

    offset = mean(a) - mean(b)
    se     = sqrt(var(a) / n_a + var(b) / n_b)         Welch's unequal-variance t test
    t      = offset / se, its degrees of freedom by Welch-Satterthwaite, p two-sided

A pair differs when p < 0.01 / (number of pairs) (Bonferroni: a line of many
stations does not flag one by chance). Pairs, rather than each station
against the rest: when one station reads high, the others taken against a
rest that contains it look low, and would be flagged too. A station "reads
high" (or low) when it differs, the same way, from every other station.
Each station's offset from the mean of the station means is shown too,
and in units of the population's sigma: significant and small (a long run)
is another finding than significant and large.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from analysis.production.student_t import t_two_sided

ALPHA = 0.01
MIN_UNITS = 2


@dataclass(frozen=True)
class StationMean:
    station: str
    n: int
    mean: float
    sigma: float
    offset: float                # mean - the mean of the station means
    offset_sigmas: float | None  # offset / sigma of the whole population
    reads: str                   # "high", "low", or "" (not different from every other station)

    def as_json(self) -> dict:
        return {"station": self.station, "n": self.n, "mean": self.mean, "sigma": self.sigma, "offset": self.offset,
                "offset_sigmas": self.offset_sigmas, "reads": self.reads}


@dataclass(frozen=True)
class StationPair:
    a: str
    b: str
    offset: float                # mean(a) - mean(b)
    t: float | None
    df: float | None
    p: float | None
    significant: bool

    def as_json(self) -> dict:
        return {"a": self.a, "b": self.b, "offset": self.offset, "t": self.t, "df": self.df, "p": self.p,
                "significant": self.significant}


@dataclass(frozen=True)
class StationComparison:
    stations: tuple[StationMean, ...] = ()
    pairs: tuple[StationPair, ...] = ()

    def as_json(self) -> dict:
        return {"stations": [s.as_json() for s in self.stations], "pairs": [p.as_json() for p in self.pairs],
                "alpha": ALPHA}


def welch(a: np.ndarray, b: np.ndarray) -> tuple[float, float | None, float | None, float | None]:
    """(mean(a) - mean(b), t, degrees of freedom, two-sided p); None where no spread makes t undefined."""
    offset = float(a.mean() - b.mean())
    va, vb = float(a.var(ddof=1)) / a.size, float(b.var(ddof=1)) / b.size
    if not va + vb > 0:
        return offset, None, None, None
    t = offset / math.sqrt(va + vb)
    df = (va + vb) ** 2 / (va ** 2 / (a.size - 1) + vb ** 2 / (b.size - 1))
    return offset, t, df, t_two_sided(t, df)


@dataclass(frozen=True)
class StationCodes:
    """Each unit's station as a small integer (its index in `names`, sorted): grouping 100,000 units by
    station is then array work, done once for every parameter."""

    names: tuple[str, ...]
    codes: np.ndarray

    @classmethod
    def of(cls, stations) -> "StationCodes":
        names = tuple(sorted(set(stations)))
        index = {s: i for i, s in enumerate(names)}
        return cls(names, np.fromiter(map(index.__getitem__, stations), dtype=np.intp, count=len(stations)))

    def subset(self, chosen: np.ndarray) -> "StationCodes":
        return StationCodes(self.names, self.codes[chosen])


def compare_stations(values, stations) -> StationComparison:
    """Every pair of the stations that have at least MIN_UNITS units; empty with fewer than two such."""
    x = np.asarray([np.nan if v is None else v for v in values], dtype=float)
    ok = np.isfinite(x)
    return compare_station_codes(x[ok], StationCodes.of(list(stations)).subset(ok))


def compare_station_codes(x: np.ndarray, stations: StationCodes) -> StationComparison:
    """compare_stations of finite values `x` and their stations' codes."""
    groups = {s: x[stations.codes == i] for i, s in enumerate(stations.names)}
    groups = {s: g for s, g in groups.items() if g.size >= MIN_UNITS}
    if len(groups) < 2:
        return StationComparison()
    n_pairs = len(groups) * (len(groups) - 1) // 2
    pairs = []
    for a, b in itertools.combinations(groups, 2):
        offset, t, df, p = welch(groups[a], groups[b])
        pairs.append(StationPair(a, b, offset, t, df, p, p is not None and p < ALPHA / n_pairs))
    overall = float(np.std(x, ddof=1))
    centre = float(np.mean([g.mean() for g in groups.values()]))
    means = []
    for s, g in groups.items():
        signs = {(1 if p.offset > 0 else -1) * (1 if p.a == s else -1)
                 for p in pairs if s in (p.a, p.b) and p.significant}
        differs_from_all = sum(1 for p in pairs if s in (p.a, p.b) and p.significant) == len(groups) - 1
        reads = ("high" if signs == {1} else "low" if signs == {-1} else "") if differs_from_all else ""
        offset = float(g.mean()) - centre
        means.append(StationMean(s, int(g.size), float(g.mean()), float(g.std(ddof=1)), offset,
                                 offset / overall if overall > 0 else None, reads))
    return StationComparison(tuple(means), tuple(pairs))
