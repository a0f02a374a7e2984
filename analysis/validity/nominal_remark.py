"""A remark, not a verdict: RE against the nominal impedance the user entered, when it lies outside what real
drivers show but inside what plausibility still accepts.

analysis.validity.plausibility turns the validity red only beyond RE_OVER_NOMINAL_RED (0.3 to 2 times the
nominal: a probe's ratio missing from the sidecar). In between, an RE of 3 Ω on a driver entered as 8 Ω is
possible (a 4 Ω driver entered as 8 Ω, or a current scale a little off) and went unsaid; the Results page says it.
"""
from __future__ import annotations

from analysis.validity.plausibility import RE_OVER_NOMINAL_RED

RE_OVER_NOMINAL_TYPICAL = (0.6, 0.95)        # RE / nominal impedance of real drivers, as plausibility says


def re_nominal_remark(re_ohm: float | None, nominal_ohm) -> str:
    """One sentence when RE / nominal lies outside RE_OVER_NOMINAL_TYPICAL (and inside the red bounds, which
    the validity says already); "" otherwise or when either is unknown."""
    if re_ohm is None or isinstance(nominal_ohm, bool) or not isinstance(nominal_ohm, (int, float)):
        return ""
    if not nominal_ohm > 0 or not re_ohm > 0:
        return ""
    ratio = re_ohm / float(nominal_ohm)
    low, high = RE_OVER_NOMINAL_TYPICAL
    if low <= ratio <= high or not RE_OVER_NOMINAL_RED[0] <= ratio <= RE_OVER_NOMINAL_RED[1]:
        return ""
    likely = (f"a {_nearest_nominal(re_ohm)} Ω driver entered as {float(nominal_ohm):g} Ω, or a current scale "
              "that reads high" if ratio < low else "a current scale that reads low, or a nominal entered too low")
    return (f"Re {re_ohm:.3g} Ω is {ratio:.2f} times the nominal {float(nominal_ohm):g} Ω entered; real drivers "
            f"have {low:g} to {high:g} times it: {likely}?")


def _nearest_nominal(re_ohm: float) -> str:
    """The usual nominal impedance a driver of this RE has (RE about 0.8 of it)."""
    nominals = (2, 4, 6, 8, 16, 32)
    return f"{min(nominals, key=lambda z: abs(0.8 * z - re_ohm)):g}"
