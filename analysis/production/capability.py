"""Process capability of one parameter against its limits: Cp, Cpk (within), Pp, Ppk (overall), yield.

For individual values (one measurement per unit, in the order measured):

    sigma_within  = MR_bar / d2,   MR_bar the mean moving range |x[i] - x[i-1]|, d2 = 2 / sqrt(pi) (n = 2)
    sigma_overall = the sample standard deviation (n - 1)
    Cp  = (USL - LSL) / (6 sigma_within)      Cpk = min(USL - mean, mean - LSL) / (3 sigma_within)
    Pp  = (USL - LSL) / (6 sigma_overall)     Ppk = min(USL - mean, mean - LSL) / (3 sigma_overall)

(AIAG SPC manual; NIST/SEMATECH e-Handbook of Statistical Methods, 6.1.6).
The within-subgroup sigma comes from neighbours only, so it is what the
process could do; the overall sigma includes drift and offsets between
stations, so it is what the process did: Cpk well above Ppk says the line
moves. With one limit only, Cp and Pp are undefined (None) and Cpk, Ppk are
the one side's. Yield is observed: the fraction of units within the limits,
bounds included (as analysis.limits judges one measurement).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

D2_PAIRS = 2.0 / math.sqrt(math.pi)      # E|x1 - x2| / sigma for two normal values: 1.1284
MIN_N = 2


@dataclass(frozen=True)
class Capability:
    n: int
    mean: float | None
    sigma_within: float | None
    sigma_overall: float | None
    minimum: float | None
    maximum: float | None
    low: float | None              # the limits used (SI), None when one-sided or absent
    high: float | None
    cp: float | None
    cpk: float | None
    pp: float | None
    ppk: float | None
    within: int                    # units inside the limits
    below: int
    above: int

    @property
    def yield_fraction(self) -> float | None:
        return None if self.n == 0 or (self.low is None and self.high is None) else self.within / self.n

    def intervals(self) -> dict[str, tuple[float, float] | None]:
        """Each index's 95 % confidence interval from its n units (analysis.production.capability_interval)."""
        from analysis.production.capability_interval import centred_interval, spread_interval
        return {"cp": spread_interval(self.cp, self.n), "cpk": centred_interval(self.cpk, self.n),
                "pp": spread_interval(self.pp, self.n), "ppk": centred_interval(self.ppk, self.n)}

    def as_json(self) -> dict:
        from analysis.production.capability_interval import too_few
        return {"n": self.n, "mean": self.mean, "sigma_within": self.sigma_within, "sigma_overall": self.sigma_overall,
                "min": self.minimum, "max": self.maximum, "lsl": self.low, "usl": self.high, "cp": self.cp,
                "cpk": self.cpk, "pp": self.pp, "ppk": self.ppk,
                # The indices are estimates: their intervals, and why they are no verdict below the minimum count.
                "intervals_95": {k: list(v) if v is not None else None for k, v in self.intervals().items()},
                "too_few": too_few(self.n) or None,
                "yield": self.yield_fraction, "within": self.within, "below": self.below, "above": self.above}


def _indices(mean: float, sigma: float | None, low: float | None, high: float | None) -> tuple:
    """(C_p-like, C_pk-like) for one sigma; None where undefined."""
    if sigma is None or not sigma > 0 or (low is None and high is None):
        return None, None
    spread = (high - low) / (6.0 * sigma) if low is not None and high is not None else None
    sides = [s for s in ((high - mean) if high is not None else None,
                         (mean - low) if low is not None else None) if s is not None]
    return spread, min(sides) / (3.0 * sigma)


def capability(values, low: float | None, high: float | None) -> Capability:
    """The capability of `values` (time order; None or NaN entries are dropped first) against [low, high]."""
    if not isinstance(values, np.ndarray):          # a list from a caller; the statistics pass arrays
        values = [np.nan if v is None else v for v in values]
    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    n = int(x.size)
    below = int(np.count_nonzero(x < low)) if low is not None else 0
    above = int(np.count_nonzero(x > high)) if high is not None else 0
    within = n - below - above
    if n == 0:
        return Capability(0, None, None, None, None, None, low, high, None, None, None, None, 0, 0, 0)
    mean = float(np.mean(x))
    sigma_within = float(np.mean(np.abs(np.diff(x)))) / D2_PAIRS if n >= MIN_N else None
    sigma_overall = float(np.std(x, ddof=1)) if n >= MIN_N else None
    cp, cpk = _indices(mean, sigma_within, low, high)
    pp, ppk = _indices(mean, sigma_overall, low, high)
    return Capability(n, mean, sigma_within, sigma_overall, float(x.min()), float(x.max()), low, high,
                      cp, cpk, pp, ppk, within, below, above)
