"""How far a capability index from n units can be trusted: its confidence interval, and the count below which
it is not shown as a verdict at all.

    Cp, Pp  (chi-square):  Cp * sqrt(chi2_{a/2, n-1} / (n-1)) .. Cp * sqrt(chi2_{1-a/2, n-1} / (n-1))
    Cpk, Ppk (Bissell 1990, normal approximation):  Cpk -+ z_{1-a/2} sqrt(1 / (9n) + Cpk^2 / (2 (n-1)))

(NIST/SEMATECH e-Handbook of Statistical Methods, 6.1.6). The chi-square quantiles use the Wilson-Hilferty
cube-root approximation (the lower quantile within 1 % of the exact one from n = 10 on, 0.1 % at n = 25;
the interval takes its square root, half that), so that the statistics need no scipy (`linpar qa stats` starts without it). From 4 units a Cpk of 27.6 has an interval of roughly
6 to 49: a number, not a verdict; below MIN_UNITS the page greys the indices and says why.
"""
from __future__ import annotations

import math
from statistics import NormalDist

MIN_UNITS = 25            # the customary minimum before a capability index is read as a verdict
CONFIDENCE = 0.95


def _chi2_quantile(p: float, dof: int) -> float:
    """Wilson-Hilferty: dof (1 - 2/(9 dof) + z_p sqrt(2/(9 dof)))^3."""
    z = NormalDist().inv_cdf(p)
    a = 2.0 / (9.0 * dof)
    return dof * max(0.0, 1.0 - a + z * math.sqrt(a)) ** 3


def spread_interval(value: float | None, n: int, confidence: float = CONFIDENCE
                    ) -> tuple[float, float] | None:
    """The interval of Cp or Pp from n units; None when it cannot be had (n < 2, no value)."""
    if value is None or n < 2 or not math.isfinite(value):
        return None
    tail = (1.0 - confidence) / 2.0
    dof = n - 1
    return (value * math.sqrt(_chi2_quantile(tail, dof) / dof),
            value * math.sqrt(_chi2_quantile(1.0 - tail, dof) / dof))


def centred_interval(value: float | None, n: int, confidence: float = CONFIDENCE
                     ) -> tuple[float, float] | None:
    """The interval of Cpk or Ppk from n units (Bissell); None when it cannot be had."""
    if value is None or n < 2 or not math.isfinite(value):
        return None
    z = NormalDist().inv_cdf(0.5 + confidence / 2.0)
    half = z * math.sqrt(1.0 / (9.0 * n) + value * value / (2.0 * (n - 1)))
    return value - half, value + half


def too_few(n: int) -> str:
    """Why an index from n units is not a verdict; empty from MIN_UNITS on."""
    if n >= MIN_UNITS:
        return ""
    return (f"only {n} unit{'s' if n != 1 else ''}: a capability index needs at least {MIN_UNITS} "
            "to be read as a verdict (the interval shows how little it says)")
