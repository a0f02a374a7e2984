"""Up to 8 measurements' parameters side by side, in customary units, with their spread.

For each parameter: every measurement's value and standard uncertainty, the
mean, the standard deviation between the measurements and each one's
deviation from the first (the reference) in percent. The spread between
measurements set against their own uncertainties says whether two drivers
differ or only the measurements do.
"""
from __future__ import annotations

import math
import statistics
from dataclasses import dataclass

from analysis.archive.names import ArchiveError

MAX_COMPARED = 8


@dataclass(frozen=True)
class ComparisonRow:
    name: str
    display_unit: str
    values: tuple[float | None, ...]      # customary units, one per measurement
    stds: tuple[float | None, ...]
    mean: float | None
    spread: float | None                  # standard deviation between the measurements
    deviation_percent: tuple[float | None, ...]   # from the first measurement

    def as_json(self) -> dict:
        return {"name": self.name, "unit": self.display_unit, "values": list(self.values), "stds": list(self.stds),
                "mean": self.mean, "spread": self.spread, "deviation_percent": list(self.deviation_percent)}


@dataclass(frozen=True)
class Comparison:
    ids: tuple[str, ...]
    labels: tuple[str, ...]               # driver and serial (else the id), for column headings
    rows: tuple[ComparisonRow, ...]
    measured_at: tuple[str, ...] = ()     # ISO 8601 UTC, one per measurement

    def as_json(self) -> dict:
        return {"ids": list(self.ids), "labels": list(self.labels), "measured_at": list(self.measured_at),
                "rows": [r.as_json() for r in self.rows]}


def _finite(x: float) -> float | None:
    # A stored value times its display scale can overflow; the statistics module fails on infinities.
    return x if math.isfinite(x) else None


def compare(archive, ids) -> Comparison:
    ids = list(ids)
    if not 1 <= len(ids) <= MAX_COMPARED:
        raise ArchiveError(f"compare takes 1 to {MAX_COMPARED} measurements, got {len(ids)}")
    measurements = [archive.get(i) for i in ids]
    if len({m.id for m in measurements}) != len(measurements):
        raise ArchiveError("the same measurement is named twice")
    results = [m.result() for m in measurements]
    names: list[str] = []
    for r in results:
        names += [n for n in r.parameters if n not in names]
    rows = []
    for name in names:
        ps = [r.parameters.get(name) for r in results]
        ref = next(p for p in ps if p is not None)
        values, stds = [], []
        for p in ps:
            ok = p is not None and p.value is not None
            values.append(_finite(p.value * p.display_scale) if ok else None)
            stds.append(_finite(p.std * abs(p.display_scale)) if ok and p.std is not None else None)
        present = [v for v in values if v is not None]
        mean = statistics.fmean(present) if present else None
        spread = statistics.stdev(present) if len(present) >= 2 else None
        first = values[0]
        dev = tuple(None if v is None or first in (None, 0) or not math.isfinite(first) else 100.0 * (v - first) / abs(first)
                    for v in values)
        rows.append(ComparisonRow(name, ref.display_unit, tuple(values), tuple(stds), mean, spread, dev))
    labels = tuple(" ".join(x for x in (m.entry.driver, m.entry.serial) if x) or m.id for m in measurements)
    return Comparison(tuple(m.id for m in measurements), labels, tuple(rows),
                      tuple(m.entry.measured_at for m in measurements))
