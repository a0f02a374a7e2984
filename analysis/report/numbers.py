"""Numbers for people: customary units, as many digits as the uncertainty allows."""
from __future__ import annotations

import math

from analysis.derived import ParameterValue

# Display units written the way reports print them.
PRETTY_UNITS = {"ohm": "Ω", "uF": "µF", "us": "µs", "T*m": "T·m", "ohm*s^n": "Ω·sⁿ", "-": ""}


def pretty_unit(unit: str) -> str:
    return PRETTY_UNITS.get(unit, unit)


def format_number(value: float | None, std: float | None = None) -> str:
    """The value rounded to the second significant digit of its uncertainty (6 digits without one)."""
    if value is None or not math.isfinite(value):
        return "n/a"
    if std is not None and std > 0 and math.isfinite(std):
        decimals = max(0, min(10, 1 - int(math.floor(math.log10(std)))))
        if abs(value) < 1e6 and (abs(value) >= 1e-3 or value == 0):
            return f"{value:.{decimals}f}"
    return f"{value:.6g}" if std is None else f"{value:.4g}"


def format_std(std: float | None) -> str:
    """Two significant digits, written out ("0.000016", "1200"): an exponent is unreadable beside its value."""
    if std is None or not math.isfinite(std):
        return "–"
    if std <= 0:
        return "0"
    decimals = 1 - int(math.floor(math.log10(std)))
    if decimals > 10:
        return f"{std:.2g}"
    rounded = round(std, decimals)
    return f"{rounded:.{max(0, decimals)}f}"


def parameter_cells(p: ParameterValue) -> tuple[str, str, str, str]:
    """(value, 1-sigma, unit, relative uncertainty) in customary units."""
    if p.value is None:
        return "n/a", "", pretty_unit(p.display_unit), ""
    v = p.value * p.display_scale
    s = None if p.std is None else p.std * abs(p.display_scale)
    # A relative uncertainty of a level in dB means nothing: its std in dB already is one.
    relative_ok = s is not None and v != 0 and math.isfinite(s) and not p.display_unit.startswith("dB")
    rel = f"{100 * s / abs(v):.2g} %" if relative_ok else ""
    return format_number(v, s), format_std(s), pretty_unit(p.display_unit), rel
