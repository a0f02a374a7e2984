"""What chance allows a chi^2: the noise floor's test and the site ranking's share both use it.

chi^2 over m values at the noise has mean m and standard deviation sqrt(2 m); above
m + CHANCE_SIGMAS * sqrt(2 m) it is structure, not noise.
"""
from __future__ import annotations

import math

CHANCE_SIGMAS = 3.0


def within_chance(chi2: float, dof: float) -> bool:
    """chi^2 with `dof` degrees of freedom no larger than chance allows (CHANCE_SIGMAS above its mean)."""
    return chi2 <= dof + CHANCE_SIGMAS * math.sqrt(2.0 * max(dof, 1.0))
