"""Statistics over units: per parameter n, mean, sigma, min/max, Cp/Cpk, Pp/Ppk, yield, the control chart with
its alarms, a histogram, and the stations compared; plus the verdicts as the stations recorded them.

Which units count: a measurement whose validity is red, or that its limits
version could not judge ("invalid", "not judged": the model does not
describe it), has parameters that judge nothing (docs/physics.md section 5): it
is left out, and counted, with the reason, where the user reads the result.
The limits the capability is computed against are one stored version (the
newest unless another is asked for); the recorded verdicts each keep the
version that made them.
"""
from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from analysis.production.capability import Capability, capability
from analysis.production.control_chart import DEFAULT_BASELINE, ControlChart, control_chart
from analysis.production.stations import StationCodes, StationComparison, compare_station_codes

NOT_JUDGEABLE = ("invalid", "not judged")
UNJUDGED = "unjudged"          # stored when the archive had no limits: no verdict recorded


@dataclass(frozen=True)
class ParameterStats:
    name: str
    unit: str                       # SI
    display_unit: str
    display_scale: float            # customary = SI x scale
    ids: tuple[str, ...]            # the units counted, in time order (the chart's points)
    capability: Capability
    chart: ControlChart | None
    histogram: tuple[np.ndarray, np.ndarray]     # (bin edges, counts), SI
    stations: StationComparison
    limit_text: str | None          # the limit as its file says it

    def as_json(self) -> dict:
        edges, counts = self.histogram
        return {"parameter": self.name, "unit": self.unit, "display_unit": self.display_unit,
                "display_scale": self.display_scale, "limit": self.limit_text, **self.capability.as_json(),
                "control_chart": None if self.chart is None else self.chart.as_json(self.ids),
                "histogram": {"edges": edges.tolist(), "counts": counts.tolist()},
                "stations": self.stations.as_json()}


@dataclass(frozen=True)
class ProductionStats:
    selection: str
    n_measurements: int
    excluded: dict[str, int]                        # reason -> units left out
    limits: object | None                           # analysis.archive.limits_store.LimitsVersion
    verdicts: dict[str, int]                        # recorded verdicts (as judged when stored)
    verdicts_by_version: dict[int, dict[str, int]]
    parameters: dict[str, ParameterStats] = field(default_factory=dict)

    # (units that passed their first test, units whose first test was judged): a retest is not a first pass.
    first_tests: tuple[int, int] = (0, 0)

    @property
    def first_pass_yield(self) -> float | None:
        passed, judged = self.first_tests
        return passed / judged if judged else None

    def as_json(self) -> dict:
        return {"selection": self.selection, "measurements": self.n_measurements, "excluded": self.excluded,
                "limits": None if self.limits is None else {"version": self.limits.version, "name": self.limits.name},
                "verdicts": self.verdicts, "first_pass_yield": self.first_pass_yield,
                "verdicts_by_limits_version": {str(k): v for k, v in self.verdicts_by_version.items()},
                "parameters": [p.as_json() for p in self.parameters.values()]}


def _excluded_reason(validity: str, verdict: str | None) -> str | None:
    if validity == "red":
        return "validity red (the measurement is invalid)"
    if verdict in NOT_JUDGEABLE:
        # "not judged" also holds the uncertain units (analysis.validity.fit.STORED_VERDICT): measured again.
        why = ("the measurement is invalid" if verdict == "invalid" else
               "the model does not describe the measurement, or a parameter's interval straddles a limit")
        return f"not judgeable ({verdict}: {why})"
    return None


def _histogram(x: np.ndarray, low: float | None, high: float | None) -> tuple[np.ndarray, np.ndarray]:
    if x.size == 0:
        return np.array([]), np.array([], dtype=int)
    lo = min([x.min(), *(v for v in (low,) if v is not None)])
    hi = max([x.max(), *(v for v in (high,) if v is not None)])
    if hi <= lo:
        lo, hi = lo - 0.5 * abs(lo or 1.0) * 1e-6, hi + 0.5 * abs(hi or 1.0) * 1e-6
    bins = int(min(40, max(6, math.ceil(math.sqrt(x.size)))))
    counts, edges = np.histogram(x, bins=bins, range=(lo, hi))
    return edges, counts


def _counts(population) -> tuple[np.ndarray, dict, dict, dict]:
    """(which units count, excluded: reason -> units, verdicts -> units, limits version -> verdicts -> units).

    Counted over the few distinct (validity, verdict, version) triples rather than unit by unit; every dict
    keeps the order in which its keys first occur among the units."""
    triples = Counter(zip(population.validity, population.verdicts, population.limits_versions))
    reasons = {(v, d): _excluded_reason(v, d) for v, d, _version in triples}
    excluded, verdicts, by_version = Counter(), Counter(), {}
    for (validity, verdict, version), n in triples.items():
        if reasons[validity, verdict] is not None:
            excluded[reasons[validity, verdict]] += n
        verdicts[verdict or UNJUDGED] += n
        if version is not None:
            by_version.setdefault(version, Counter())[verdict] += n
    if not excluded:            # the usual case: every unit counts, no need to look at each one
        keep = np.ones(len(population), dtype=bool)
    else:
        kept = {pair: reason is None for pair, reason in reasons.items()}
        keep = np.fromiter(map(kept.__getitem__, zip(population.validity, population.verdicts)), dtype=bool,
                           count=len(population))
    return keep, dict(excluded), dict(verdicts), {k: dict(v) for k, v in sorted(by_version.items())}


def first_tests(population) -> tuple[int, int]:
    """(passed, judged) over each unit's first judged test: a unit is a driver and serial (in time order, the
    first measurement of it that passed or failed); a measurement without a serial is a unit of its own. A
    retest neither adds a pass nor hides the first test's fail. A test that judged nothing (invalid: a rig
    fault; not judged) says nothing of the unit: the unit's next test is its first, else a unit measured
    first with a broken lead and then failing was counted nowhere."""
    seen: set = set()
    passed = judged = 0
    for driver, serial, verdict in zip(population.drivers, population.serials, population.verdicts):
        if verdict not in ("pass", "fail"):
            continue
        if serial:
            if (driver, serial) in seen:
                continue
            seen.add((driver, serial))
        judged += 1
        passed += verdict == "pass"
    return passed, judged


def production_stats(population, limits_version=None, baseline: int = DEFAULT_BASELINE,
                     names=None, selection: str = "") -> ProductionStats:
    """The statistics of an analysis.archive.population.Population against one limits version (or none)."""
    from analysis.limits import parameter_units
    keep, excluded, verdicts, by_version = _counts(population)
    limits = {lim.name: lim for lim in limits_version.limits().limits} if limits_version is not None else {}
    units = parameter_units()
    stations = StationCodes.of(population.stations)
    ids = np.asarray(population.ids, dtype=object)
    every_id = tuple(population.ids)
    out = {}
    for name in (names or population.values):
        raw = population.values.get(name, np.array([]))
        if raw.size != keep.size:
            continue
        use = keep & np.isfinite(raw)
        x = raw[use]
        if x.size == 0 and names is None:
            continue            # a parameter no unit of the selection has (Bl without the laser)
        limit = limits.get(name)
        low, high = (limit.low, limit.high) if limit is not None else (None, None)
        si, display, scale = units.get(name, ("", "", 1.0))
        counted = every_id if x.size == ids.size else tuple(ids[use])      # usually every unit, for every parameter
        out[name] = ParameterStats(name, si, display, scale, counted, capability(x, low, high),
                                   control_chart(x, baseline), _histogram(x, low, high),
                                   compare_station_codes(x, stations.subset(use)), limit.text if limit else None)
    return ProductionStats(selection, len(population), excluded, limits_version, verdicts, by_version, out,
                           first_tests(population))
