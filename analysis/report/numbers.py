"""Numbers for people: customary units, as many digits as the uncertainty allows."""
from __future__ import annotations

import math
from decimal import Decimal

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


SHORT_DIGITS = 4        # significant digits of a value read against a limit, when its sigma supports as many


def short_number(value: float, std: float | None = None, digits: int = SHORT_DIGITS) -> str:
    """At most `digits` significant digits, fewer when the sigma supports fewer (down to its second digit); no
    exponent below 1e6. The Results and QA pages' value and the report's QA table: "3.020", where the full
    rounding to a sigma of 5e-6 reads "3.0199964"."""
    if value == 0 or not math.isfinite(value):
        return f"{value:.{digits}g}"
    magnitude = math.floor(math.log10(abs(value)))
    decimals = digits - 1 - magnitude
    if std is not None and math.isfinite(std) and std > 0:
        # Never finer than the sigma's second digit: a value far below its sigma (a parameter on its bound at
        # 9e-9 mH, sigma 1.9 mH) reads "0.0", not "0.000000009".
        decimals = min(decimals, 1 - math.floor(math.log10(std)))
    if abs(value) >= 1e6 or decimals > 9:
        return f"{value:.{digits}g}"
    return f"{round(value, decimals) + 0.0:.{max(0, decimals)}f}"      # + 0.0: no "-0.0"


def plain_number(value: float, digits: int = 3) -> str:
    """`digits` significant digits, trailing zeros dropped, never an exponent ("0.27", "0.0000123", "19.6"): a
    margin beside its value."""
    text = f"{value:.{digits}g}"
    return format(Decimal(text), "f") if "e" in text and math.isfinite(value) else text


_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def readable_number(value: float, digits: int = 2) -> str:
    """`digits` significant digits for people: written out ("120", "0.0025") from 1e-4 to 1e5, else with a power of
    ten ("2.8 × 10⁸"), never Python's "1.2e+02" (a customer reads that as a typo)."""
    if not math.isfinite(value) or value == 0 or 1e-4 <= abs(value) < 1e5:
        return plain_number(value, digits) if math.isfinite(value) else f"{value}"
    mantissa, exponent = f"{value:.{digits - 1}e}".split("e")
    return f"{mantissa} × 10{str(int(exponent)).translate(_SUPERSCRIPT)}"


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


def percent_text(percent: float) -> str:
    """A relative uncertainty written as its sigma is: two significant digits, a trailing zero kept ("3.0 %" in
    the column of "2.8 %", not "3 %"), a power of ten below 1e-4 %."""
    return f"{format_std(percent) if percent >= 1e-4 else readable_number(percent)} %"


NOT_DETERMINED = "not determined"
NOT_DETERMINED_NOTE = ("not determined: the 1σ is at least the value itself (100 % or more): the data do not fix "
                       "this parameter.")


def determined(p: ParameterValue) -> bool:
    """False when the parameter's 1-sigma is at least its value: "6 ± 25" is as much 0 or 30 as 6, and a number
    printed alone would be read as a measured one. A level in dB has no relative uncertainty to judge by."""
    if p.value is None or p.std is None or math.isnan(p.std) or p.display_unit.startswith("dB"):
        return True
    return p.std < abs(p.value)


def parameter_cells(p: ParameterValue) -> tuple[str, str, str, str]:
    """(value, 1-sigma, unit, relative uncertainty) in customary units; the value NOT_DETERMINED when the data do
    not determine it (determined)."""
    if p.value is None:
        return "n/a", "", pretty_unit(p.display_unit), ""
    v = p.value * p.display_scale
    s = None if p.std is None else p.std * abs(p.display_scale)
    # A relative uncertainty of a level in dB means nothing: its std in dB already is one.
    relative_ok = s is not None and v != 0 and math.isfinite(s) and not p.display_unit.startswith("dB")
    rel = percent_text(100 * s / abs(v)) if relative_ok else ""
    value = format_number(v, s) if determined(p) else NOT_DETERMINED
    return value, format_std(s), pretty_unit(p.display_unit), rel
