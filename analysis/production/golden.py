"""Limits proposed from golden units: mean +- k sigma per parameter, never tighter than the measurement can tell.

For each key parameter measured on every golden unit:

    u          = the root mean square of the units' own standard uncertainties (what one measurement can tell)
    half-width = k * max(sigma of the golden units, u)

A golden population that happens to be tighter than the measurement's own
noise would otherwise give limits that good units fail by chance; the floor
says so in the entry's note. The proposal is a linpar-limits/1 document
(analysis.limits), in the parameters' customary units, for the engineer to
review before storing it as a new limits version (`linpar qa limits --store`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import datetime, timezone

import numpy as np

from analysis.archive.names import ArchiveError

MIN_GOLDEN = 2
FEW_GOLDEN = 10


@dataclass(frozen=True)
class ProposedLimit:
    name: str
    n: int
    mean: float              # SI
    sigma: float             # between the golden units
    uncertainty: float | None    # of one measurement (RMS of the reported standard uncertainties)
    half_width: float        # k x max(sigma, uncertainty)
    floored: bool            # the measurement's uncertainty, not the spread, set the width
    unit: str                # customary, as the limits file gives it
    scale: float             # customary = SI x scale

    def entry(self, k: float) -> dict:
        lo, hi = sorted(((self.mean - self.half_width) * self.scale, (self.mean + self.half_width) * self.scale))
        why = (f"the measurement's own uncertainty {self.uncertainty * abs(self.scale):.3g} (wider than the spread "
               f"{self.sigma * abs(self.scale):.3g})" if self.floored else f"sigma {self.sigma * abs(self.scale):.3g}")
        return {"min": _round(lo, down=True), "max": _round(hi, down=False), "unit": self.unit,
                "note": f"mean {self.mean * self.scale:.6g} +- {k:g} x {why} of {self.n} golden units"}

    def as_json(self) -> dict:
        return {"parameter": self.name, "n": self.n, "mean": self.mean, "sigma": self.sigma,
                "uncertainty": self.uncertainty, "half_width": self.half_width, "floored": self.floored}


def _round(value: float, down: bool) -> float:
    """Six significant digits, rounded outwards: the limit written is never tighter than the one computed."""
    if value == 0 or not math.isfinite(value):
        return value
    step = 10 ** (math.floor(math.log10(abs(value))) - 5)
    return (math.floor if down else math.ceil)(value / step) * step


def check_golden(population) -> None:
    """ArchiveError (one line) when a unit of `population` cannot be a golden unit: a broken measurement (red), or
    one its limits could not judge. Checked where units are marked golden and where limits are proposed."""
    bad = [f"{i} ({v})" for i, v, d in zip(population.ids, population.validity, population.verdicts)
           if v == "red" or d in ("invalid", "not judged")]
    if bad:
        raise ArchiveError(f"a golden unit must be a valid measurement the model describes: {', '.join(bad[:5])} "
                           "is not: measure it again or leave it out")


def propose_limits(population, k: float, ids=(), name: str = "") -> tuple[dict, list[ProposedLimit], list[str]]:
    """(linpar-limits/1 document, the limits with their numbers, notes) from the golden units' population."""
    from analysis.limits import parameter_units
    if len(population) < MIN_GOLDEN:
        raise ArchiveError(f"limits from golden units need at least {MIN_GOLDEN} of them; {len(population)} found")
    check_golden(population)
    units = parameter_units()
    notes, proposed = [], []
    if len(population) < FEW_GOLDEN:
        notes.append(f"only {len(population)} golden units: a sigma from fewer than {FEW_GOLDEN} is uncertain by "
                     "more than +-25 %; measure more for limits to rely on")
    for pname, values in population.values.items():
        x = values                                   # NaN: not measured (analysis.archive.population)
        if not np.all(np.isfinite(x)):
            if np.any(np.isfinite(x)):
                notes.append(f"{pname}: not measured on every golden unit: no limit proposed")
            continue
        s = population.stds[pname]
        s = s[np.isfinite(s)]
        u = float(np.sqrt(np.mean(s ** 2))) if s.size else None
        sigma = float(np.std(x, ddof=1))
        floored = u is not None and u > sigma
        half = k * (u if floored else sigma)
        _si, customary, scale = units.get(pname, ("", "", 1.0))
        if not half > 0:
            notes.append(f"{pname}: every golden unit reads the same and no uncertainty is known: no limit proposed")
            continue
        proposed.append(ProposedLimit(pname, int(x.size), float(x.mean()), sigma, u, half, floored, customary, scale))
    if not proposed:
        raise ArchiveError("no parameter was measured on every golden unit: no limits to propose")
    made = datetime.now(timezone.utc).isoformat(timespec="seconds").replace("+00:00", "Z")
    document = {"format": "linpar-limits/1",
                "name": name or f"from {len(population)} golden units, mean +- {k:g} sigma",
                "source": {"golden": list(ids or population.ids), "k": k, "proposed_at": made},
                "parameters": {p.name: p.entry(k) for p in proposed}}
    return document, proposed, notes
