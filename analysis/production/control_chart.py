"""Individuals and moving-range (I-MR) control chart, with the Western Electric rules flagged.

The chart's centre line and sigma come from a baseline: the first `baseline`
units of the selection (phase I), sigma from their mean moving range
(MR_bar / d2, d2 = 2/sqrt(pi)), so that a later drift moves the points, not
the limits. Every unit, baseline included, is then judged by the rules
(Western Electric Statistical Quality Control Handbook, 1956; NIST/SEMATECH
e-Handbook 6.3.2):

    WE1  one point beyond 3 sigma
    WE2  2 of 3 points in a row beyond 2 sigma, on one side
    WE3  4 of 5 points in a row beyond 1 sigma, on one side
    WE4  8 points in a row on one side of the centre line
    MR   a moving range above its upper limit D4 * MR_bar (D4 = 3.267): a jump between two units

A rule fires at the point that completes its pattern (that point is itself
beyond the line). Overlapping firings of one rule on one side are one alarm,
which names every point involved. The four rules together raise a false
alarm about once in 92 points of a stable process (in-control average run
length): an alarm is a reason to look, not a verdict.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from analysis.production.capability import D2_PAIRS

D4_PAIRS = 3.267
DEFAULT_BASELINE = 50
MIN_BASELINE = 10
RULES = {
    "WE1": "one point beyond 3 sigma",
    "WE2": "2 of 3 points in a row beyond 2 sigma on one side",
    "WE3": "4 of 5 points in a row beyond 1 sigma on one side",
    "WE4": "8 points in a row on one side of the centre line",
    "MR": "a jump between two units: the moving range above its upper limit",
}
# rule -> (window length, how many beyond, how far in sigma)
_ZONE_RULES = {"WE1": (1, 1, 3.0), "WE2": (3, 2, 2.0), "WE3": (5, 4, 1.0), "WE4": (8, 8, 0.0)}


@dataclass(frozen=True)
class Alarm:
    rule: str                       # RULES' key
    side: str                       # "above", "below" (of the centre line), or "" (MR)
    points: tuple[int, ...]         # the chart's points involved, in order
    triggers: tuple[int, ...]       # the points at which the rule fired

    @property
    def title(self) -> str:
        return RULES[self.rule]

    def as_json(self, ids=None) -> dict:
        doc = {"rule": self.rule, "title": self.title, "side": self.side, "points": list(self.points),
               "first": self.triggers[0]}
        if ids is not None:
            doc["measurements"] = [ids[i] for i in self.points]
        return doc


@dataclass(frozen=True)
class ControlChart:
    values: np.ndarray              # the individuals, in time order
    baseline: int                   # the first `baseline` points set the limits
    centre: float
    sigma: float                    # within, from the baseline's moving ranges
    moving_ranges: np.ndarray       # |x[i] - x[i-1]|, i = 1 ... n-1
    mr_centre: float
    alarms: Sequence[Alarm]         # an AlarmList: each Alarm made when it is read

    @property
    def judges(self) -> bool:
        """Whether its baseline is long enough to raise alarms (MIN_BASELINE units)."""
        return self.baseline >= MIN_BASELINE

    @property
    def ucl(self) -> float:
        return self.centre + 3 * self.sigma

    @property
    def lcl(self) -> float:
        return self.centre - 3 * self.sigma

    @property
    def mr_ucl(self) -> float:
        return D4_PAIRS * self.mr_centre

    def flagged(self) -> np.ndarray:
        """Indices of the points some alarm involves."""
        return np.array(sorted({i for a in self.alarms for i in a.points}), dtype=int)

    def as_json(self, ids=None) -> dict:
        return {"baseline": self.baseline, "centre": self.centre, "sigma": self.sigma, "ucl": self.ucl,
                "lcl": self.lcl, "mr_centre": self.mr_centre, "mr_ucl": self.mr_ucl, "judges": self.judges,
                "alarms": [a.as_json(ids) for a in self.alarms]}


def control_chart(values, baseline: int = DEFAULT_BASELINE) -> ControlChart | None:
    """The I-MR chart of finite `values` in time order; None with fewer than two points or no spread."""
    x = np.asarray(values, dtype=float)
    if x.size < 2:
        return None
    b = int(min(max(baseline, 2), x.size))
    mr = np.abs(np.diff(x))
    mr_centre = float(np.mean(mr[: b - 1]))
    sigma = mr_centre / D2_PAIRS
    if not sigma > 0:
        return None
    centre = float(np.mean(x[:b]))
    z = (x - centre) / sigma
    # Limits from fewer than MIN_BASELINE units are too unsure to raise alarms on (8 units gave 6 alarms, each
    # said to come "about once in 92 units of a stable process"): the points are drawn, no alarm is raised.
    runs = [] if b < MIN_BASELINE else \
        [r for rule in _ZONE_RULES for r in _zone_alarms(z, rule)] + _jump_alarms(mr, D4_PAIRS * mr_centre)
    return ControlChart(x, b, centre, sigma, mr, mr_centre, AlarmList(runs))


def _zone_alarms(z: np.ndarray, rule: str) -> list["_Runs"]:
    window, needed, zone = _ZONE_RULES[rule]
    runs: list[_Runs] = []
    if z.size < window:
        return runs
    for side, sign in (("above", 1.0), ("below", -1.0)):
        beyond = sign * z > zone
        counts = np.convolve(beyond.astype(int), np.ones(window, dtype=int), mode="valid")   # window ending at i
        fired = np.flatnonzero((counts >= needed) & beyond[window - 1:]) + window - 1
        runs += _grouped(rule, side, fired, fired - window + 1, beyond)
    return runs


def _jump_alarms(mr: np.ndarray, limit: float) -> list["_Runs"]:
    # The moving range k is between points k and k + 1: it fires at k + 1 and involves both.
    fired = np.flatnonzero(mr > limit) + 1
    return _grouped("MR", "", fired, fired - 1, None)


@dataclass(frozen=True)
class _Runs:
    """The alarms of one rule on one side, as arrays: alarm j involves points[begin[j]:end[j]] and fired at
    fired[first[j]:last[j]]."""
    rule: str
    side: str
    points: np.ndarray
    fired: np.ndarray
    begin: np.ndarray
    end: np.ndarray
    first: np.ndarray
    last: np.ndarray

    def alarm(self, j: int) -> Alarm:
        return Alarm(self.rule, self.side, tuple(self.points[self.begin[j]:self.end[j]].tolist()),
                     tuple(self.fired[self.first[j]:self.last[j]].tolist()))


def _grouped(rule: str, side: str, fired: np.ndarray, starts: np.ndarray, beyond: np.ndarray | None) -> list[_Runs]:
    """One alarm per run of firings whose windows overlap or touch: every point beyond the line in the run's
    span (all of them for a jump), and the points where the rule fired. Array work only, linear in the number
    of points: a drift fires a rule at every unit of 100,000."""
    if fired.size == 0:
        return []
    breaks = np.flatnonzero(starts[1:] > fired[:-1] + 1) + 1
    first = np.concatenate(([0], breaks))
    last = np.concatenate((breaks, [fired.size]))           # exclusive
    low, high = starts[first], fired[last - 1]
    if beyond is None:
        positions = np.arange(int(low.min()), int(high.max()) + 1)
    else:
        positions = np.flatnonzero(beyond)
    begin = np.searchsorted(positions, low, "left")
    end = np.searchsorted(positions, high, "right")
    return [_Runs(rule, side, positions, fired, begin, end, first, last)]


class AlarmList(Sequence):
    """A chart's alarms in the order (first trigger, rule), every rule's alarms merged, each Alarm made only
    when it is read: a drifting line raises tens of thousands, and `qa stats` prints ten of them."""

    def __init__(self, runs: list[_Runs]):
        self._runs = runs
        which = np.concatenate([np.full(r.first.size, k) for k, r in enumerate(runs)] or [np.zeros(0, int)])
        index = np.concatenate([np.arange(r.first.size) for r in runs] or [np.zeros(0, int)])
        trigger = np.concatenate([r.fired[r.first] for r in runs] or [np.zeros(0, int)])
        ranks = {rule: i for i, rule in enumerate(sorted({r.rule for r in runs}))}
        rank = np.array([ranks[r.rule] for r in runs], dtype=int)[which] if runs else which
        order = np.lexsort((rank, trigger))                  # by trigger, then rule's name (a stable sort)
        self._which, self._index = which[order].tolist(), index[order].tolist()

    def __len__(self) -> int:
        return len(self._which)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return tuple(self[k] for k in range(*i.indices(len(self))))
        return self._runs[self._which[i]].alarm(self._index[i])
