"""QA limits: pass or fail per parameter and overall, from a JSON limits file.

    {
      "format": "linpar-limits/1",
      "name": "6-inch woofer, production QA",                     (optional)
      "parameters": {
        "RE":  {"nominal": 3.0,  "tolerance": "5%",  "unit": "ohm"},
        "fs":  {"nominal": 70,   "tolerance": 5,     "unit": "Hz"},    absolute tolerance, in "unit"
        "Mms": {"min": 11, "max": 13, "unit": "g"},                    customary unit...
        "Cms": {"max": 0.0005, "unit": "m/N"},                         ...or SI, stated per entry
        "Qts": {"nominal": 0.46, "tolerance": "10%", "unit": "-"}
      }
    }

Each entry gives either `nominal` and `tolerance` (a number in `unit`, or a
string "N%" of the nominal), or `min` and/or `max`. `unit` is required: the
parameter's SI unit or its customary one (mH or H, g or kg, l or m^3, ...),
so that a limit can never be read in the wrong unit. A parameter that the
measurement could not give (Bl without the laser) fails, with the reason.

A parameter is judged by its interval, value +- INTERVAL_K x std (its total
standard uncertainty, noise and model parts): pass when the interval lies
inside the limits, FAIL when it lies wholly outside, "uncertain" when it
straddles a limit (measure again). An optional top-level
`"fit_error_percent": {"impedance": 3, "displacement": 10}` sets how far (rms
misfit in %) the model may miss each curve before the unit is not judged
(defaults: analysis.fit.error.FIT_ERROR_DEFAULTS).

A limits file that breaks these rules raises LimitsError, whose one-line
message names the file, the line and key, and what was expected.
"""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Mapping

from analysis.errors import LinparError
from analysis.files import read_text
from analysis.fit.error import FIT_ERROR_DEFAULTS
from analysis.parameter_names import CODE_NAMES
from analysis.qa_interval import FAIL, INTERVAL_K, PASS, UNCERTAIN
from analysis.text_boundary import control_found

if TYPE_CHECKING:       # analysis.derived is imported where limits judge parameters, not to read a limits file
    from analysis.derived import ParameterValue
    from analysis.validity.result import ResultValidity

FORMAT = "linpar-limits/1"
FIT_ERROR_CHANNELS = ("impedance", "displacement")
ENTRY_KEYS = {"nominal", "tolerance", "min", "max", "unit", "note"}
# Spellings of units that mean the same thing.
_ALIASES = {"Ω": "ohm", "ohms": "ohm", "µF": "uF", "μF": "uF", "L": "l", "m3": "m^3", "": "1", "-": "1",
            "Tm": "T*m", "T·m": "T*m", "N/A": "T*m", "dB SPL": "dB"}
# (?:[0-9]*\.)?[0-9]+ rather than [0-9]*\.?[0-9]+: the same numbers, but a long run of digits cannot be
# split between two quantifiers in n ways, so a refused string costs linear, not quadratic, time.
_PERCENT = re.compile(r"^\s*((?:[0-9]*\.)?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*%\s*$")


class LimitsError(LinparError, ValueError):
    def __init__(self, message: str):
        super().__init__(" ".join(str(message).splitlines()))


def _unit(text: str) -> str:
    return _ALIASES.get(text.strip(), text.strip())


def parameter_units() -> dict[str, tuple[str, str, float]]:
    """name -> (SI unit, customary unit, customary = SI x scale) for every parameter linpar can report."""
    from analysis.derived import DERIVED
    from analysis.effects import CATALOGUE
    from analysis.model.composed import BASE_PARAMS, BL_PARAM
    table = {}
    for spec in (*BASE_PARAMS, BL_PARAM, *(p for e in CATALOGUE.values() for p in e.params)):
        table.setdefault(spec.name, (spec.unit, spec.display_unit, spec.display_scale))
    for d in DERIVED:
        table.setdefault(d.name, (d.unit, d.display_unit, d.display_scale))
    return table


@dataclass(frozen=True)
class Limit:
    name: str
    unit: str                 # as written in the file
    to_si: float              # SI = value in `unit` x to_si
    low: float | None         # SI
    high: float | None        # SI
    text: str                 # how the file said it (its unit in proper notation), for the pages and reports

    def judge(self, p: ParameterValue | None) -> "Verdict":
        if p is None or p.value is None:
            why = p.reason if p is not None else "not in this measurement's results"
            return Verdict(self, None, False, f"not measured: {why}", FAIL)
        known = p.std is not None and math.isfinite(p.std)
        half = INTERVAL_K * abs(p.std) if known else 0.0
        lo, hi = p.value - half, p.value + half
        inside = (self.low is None or lo >= self.low) and (self.high is None or hi <= self.high)
        outside = (self.low is not None and hi < self.low) or (self.high is not None and lo > self.high)
        outcome = PASS if inside else FAIL if outside else UNCERTAIN
        if not known and outcome == PASS:
            # A value without an uncertainty is no interval inside the limits: a pass the data do not support.
            outcome = UNCERTAIN
        note = "" if known else "no uncertainty estimated: a value inside the limits is not enough to pass"
        return Verdict(self, p.value, outcome == PASS, note, outcome, (lo, hi))


@dataclass(frozen=True)
class Verdict:
    limit: Limit
    value: float | None       # SI
    passed: bool
    note: str
    outcome: str = ""         # PASS, FAIL or UNCERTAIN (the interval straddles a limit)
    interval: tuple[float, float] | None = None      # value +- INTERVAL_K x std, SI

    def margin(self) -> tuple[float, str] | None:
        """(distance to the nearest bound in SI, "min" or "max"): positive inside, negative outside.

        Outside, the bound it is outside of. None when the parameter was not measured.
        """
        if self.value is None:
            return None
        sides = [(self.value - self.limit.low, "min")] if self.limit.low is not None else []
        if self.limit.high is not None:
            sides.append((self.limit.high - self.value, "max"))
        return min(sides)

    def tolerance_used(self) -> float | None:
        """|value - centre| / half-width of a two-sided limit (1.0 on a bound), or None."""
        low, high = self.limit.low, self.limit.high
        if self.value is None or low is None or high is None or high <= low:
            return None
        return abs(self.value - (low + high) / 2) / ((high - low) / 2)

    def as_json(self) -> dict:
        return {"parameter": self.limit.name, "value": self.value, "low": self.limit.low, "high": self.limit.high,
                "unit": parameter_units()[self.limit.name][0], "limit": self.limit.text,
                "pass": self.passed, "outcome": self.outcome,
                **({"interval": list(self.interval), "k": INTERVAL_K} if self.interval is not None else {}),
                **({"note": self.note} if self.note else {})}


@dataclass(frozen=True)
class Limits:
    path: Path
    name: str
    limits: tuple[Limit, ...]
    fit_error_percent: Mapping[str, float] = field(default_factory=lambda: dict(FIT_ERROR_DEFAULTS))

    def judge(self, parameters: Mapping[str, ParameterValue]) -> tuple[Verdict, ...]:
        return tuple(limit.judge(parameters.get(limit.name)) for limit in self.limits)


def _line_of(text: str, key: str, after: int = 0) -> int:
    at = text.find(f'"{key}"', after)
    return text.count("\n", 0, at) + 1 if at >= 0 else 0


def load_limits(path: str | Path) -> Limits:
    path = Path(path)
    text = read_text(path, "config", "a JSON limits file", LimitsError)     # a FIFO, a device: refused unread
    try:
        doc = json.loads(text, parse_constant=_refuse_constant)
    except json.JSONDecodeError as exc:
        raise LimitsError(f"{path}: line {exc.lineno} column {exc.colno}: {exc.msg}: expected JSON") from None
    except ValueError as exc:
        raise LimitsError(f"{path}: {exc}") from None
    except RecursionError:
        raise LimitsError(f"{path}: JSON nested too deeply: expected a JSON limits file") from None
    try:
        # Valid JSON may escape half of a UTF-16 pair ("\\ud800"): text that no report or terminal can show.
        json.dumps(doc, ensure_ascii=False).encode("utf-8")
    except UnicodeEncodeError as exc:
        raise LimitsError(f"{path}: a string holds {exc.object[exc.start:exc.end]!r}, half of a UTF-16 "
                          "surrogate pair: expected Unicode text") from None
    return parse_limits(doc, text, path)


def _finite(value: int | float) -> bool:
    try:
        return math.isfinite(value)
    except OverflowError:       # an integer beyond the float range
        return False


def _refuse_constant(name: str):
    raise ValueError(f"{name} is not a number: expected finite numbers")


def parse_limits(doc, text: str, path: Path) -> Limits:
    from analysis.report.numbers import pretty_unit

    def fail(line: int, key: str, message: str):
        where = f"line {line}: " if line else ""
        raise LimitsError(f"{path}: {where}{key}: {message}")

    if not isinstance(doc, dict):
        fail(1, "(top level)", "expected a JSON object with \"format\" and \"parameters\"")
    if doc.get("format") != FORMAT:
        fail(_line_of(text, "format"), "format", f"found {doc.get('format')!r}, expected {FORMAT!r}")
    params = doc.get("parameters")
    if not isinstance(params, dict) or not params:
        fail(_line_of(text, "parameters"), "parameters", "expected an object of parameter limits, "
                                                         "e.g. {\"RE\": {\"nominal\": 3.0, \"tolerance\": \"5%\", \"unit\": \"ohm\"}}")
    name = doc.get("name")
    if name is not None:
        # The name is copied into every judged measurement's record, reports and terminals: one line of text.
        what = control_found(name) if isinstance(name, str) else f"a {type(name).__name__}"
        if what:
            fail(_line_of(text, "name"), "name", f"holds {what}; expected one line of text")
    units = parameter_units()
    start = text.find('"parameters"')
    limits = []
    given_as: dict[str, str] = {}
    for given, entry in params.items():
        line = _line_of(text, given, max(start, 0))
        key = f"parameters.{given}"
        # The name the window and the reports show (Re, Le) is the parameter's too: a user copies it from there.
        name = CODE_NAMES.get(given, given)
        if name not in units:
            fail(line, key, f"unknown parameter: expected one of {', '.join(units)}")
        if name in given_as:
            fail(line, key, f"the same parameter as {given_as[name]!r}: give its limits once")
        given_as[name] = given
        si, customary, scale = units[name]
        if not isinstance(entry, dict):
            fail(line, key, "expected an object with nominal/tolerance or min/max, and unit")
        extra = set(entry) - ENTRY_KEYS
        if extra:
            fail(line, f"{key}.{sorted(extra)[0]}", f"unknown key: expected {', '.join(sorted(ENTRY_KEYS))}")
        unit = entry.get("unit")
        accepted = {_unit(si): 1.0, _unit(customary): 1.0 / scale}
        if not isinstance(unit, str) or _unit(unit) not in accepted:
            expected = f"{si!r}" if _unit(si) == _unit(customary) else f"{si!r} (SI) or {customary!r}"
            fail(line, f"{key}.unit", f"found {unit!r}, expected {expected}")
        to_si = accepted[_unit(unit)]
        # The file's numbers and unit, the unit in proper notation (Ω, T·m); dimensionless: no unit in the text.
        shown_unit = "" if _unit(unit) == "1" else pretty_unit(unit)

        def number(k):
            v = entry.get(k)
            if v is None:
                return None
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not _finite(v):
                fail(line, f"{key}.{k}", f"found {v!r}, expected a number in {unit}")
            return float(v)

        nominal, low, high = number("nominal"), number("min"), number("max")
        tolerance = entry.get("tolerance")
        if nominal is not None:
            if low is not None or high is not None:
                fail(line, key, "give either nominal and tolerance, or min and/or max, not both")
            if tolerance is None:
                fail(line, f"{key}.tolerance", f"missing: expected a number in {unit} or a percentage like \"5%\"")
            m = _PERCENT.match(tolerance) if isinstance(tolerance, str) else None
            if m:
                delta = abs(nominal) * float(m.group(1)) / 100.0
                said = f"{nominal:g} {shown_unit} ± {m.group(1)} %".replace("  ", " ")
            elif isinstance(tolerance, (int, float)) and not isinstance(tolerance, bool) and _finite(tolerance) \
                    and tolerance >= 0:
                delta = float(tolerance)
                said = f"{nominal:g} ± {delta:g} {shown_unit}".rstrip()
            else:
                fail(line, f"{key}.tolerance", f"found {tolerance!r}, expected a non-negative number in {unit} "
                                               "or a percentage like \"5%\"")
            low, high = nominal - delta, nominal + delta
        else:
            if tolerance is not None:
                fail(line, f"{key}.nominal", "missing: a tolerance needs a nominal value")
            if low is None and high is None:
                fail(line, key, "expected nominal and tolerance, or min and/or max")
            if low is not None and high is not None and low > high:
                fail(line, key, f"min {low:g} is above max {high:g}")
            if low is not None and high is not None:
                said = f"{low:g} .. {high:g} {shown_unit}".rstrip()
            else:
                said = (f"≥ {low:g} {shown_unit}" if high is None else f"≤ {high:g} {shown_unit}").rstrip()
        lo_si = None if low is None else low * to_si
        hi_si = None if high is None else high * to_si
        if not all(math.isfinite(v) for v in (lo_si, hi_si) if v is not None):
            fail(line, key, f"the limits overflow ({said}): expected finite bounds")
        limits.append(Limit(name, unit, to_si, lo_si, hi_si, said))
    tolerance = _fit_error_tolerance(doc.get("fit_error_percent"), text, path)
    return Limits(path, str(doc.get("name") or path.stem), tuple(limits), tolerance)


def _fit_error_tolerance(entry, text: str, path: Path) -> dict[str, float]:
    """The file's "fit_error_percent" over the defaults: channel -> largest fit error in % that is judged."""
    tolerance = dict(FIT_ERROR_DEFAULTS)
    if entry is None:
        return tolerance
    line = _line_of(text, "fit_error_percent")
    where = f"{path}: line {line}: fit_error_percent" if line else f"{path}: fit_error_percent"
    if not isinstance(entry, dict):
        raise LimitsError(f"{where}: expected an object such as {{\"impedance\": 3, \"displacement\": 10}} (%)")
    for channel, value in entry.items():
        if channel not in FIT_ERROR_CHANNELS:
            raise LimitsError(f"{where}: {str(channel)[:40]!r}: unknown curve: expected {' or '.join(FIT_ERROR_CHANNELS)}")
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not _finite(value) or value <= 0:
            raise LimitsError(f"{where}.{channel}: found {str(value)[:40]!r}, expected a positive number of %")
        tolerance[channel] = float(value)
    return tolerance
def judge_result(limits: Limits, parameters: Mapping[str, ParameterValue], validity: ResultValidity | str) -> dict:
    """The QA verdict as JSON (analysis.qa_verdict): "pass", "fail", "uncertain", "invalid" (the measurement
    itself is red) or "not judged" (the model misses a curve by more than the file's fit-error tolerance);
    `validity`: the result's validity, or its overall light alone.

    Neither an invalid nor a not-judged result has its parameters judged against
    their limits (docs/physics.md section 5): the why says what to do.
    """
    from analysis.qa_verdict import judge
    judgement = judge(limits, parameters, validity)
    doc = {"file": str(limits.path), "name": limits.name, "verdict": judgement.verdict, "why": judgement.why,
           "interval_k": INTERVAL_K, "fit_error_tolerance_percent": dict(limits.fit_error_percent),
           "parameters": [v.as_json() for v in judgement.verdicts]}
    if judgement.fit_error_percent:
        doc["fit_error_percent"] = dict(judgement.fit_error_percent)
        bands = None if isinstance(validity, str) else validity.fit_band_hz
        if bands:
            doc["fit_band_hz"] = {name: list(band) for name, band in bands.items()}
    return doc


def format_verdicts(limits: Limits, parameters: Mapping[str, ParameterValue], validity: ResultValidity | str) -> str:
    """A table for the terminal: each limit in its file's unit, the measured interval, pass, FAIL or uncertain."""
    from analysis.qa_verdict import judge, outcome_word, telling_digits
    judgement = judge(limits, parameters, validity)
    lines = [f"QA limits: {limits.name} ({limits.path}); each parameter judged by value ± {INTERVAL_K:g} σ"]
    for limit, v in zip(limits.limits, judgement.verdicts):
        unit = "" if _unit(limit.unit) == "1" else limit.unit
        shown = "n/a" if v.value is None else f"{v.value / limit.to_si:.5g} {unit}".rstrip()
        if v.interval is not None and v.interval[0] != v.interval[1]:
            # As many digits as tell the interval's ends from each other and from the limit's bounds.
            ends = [x / limit.to_si for x in v.interval]
            digits = telling_digits(*ends, *(b / limit.to_si for b in (limit.low, limit.high) if b is not None))
            shown += f" ({ends[0]:.{digits}g} .. {ends[1]:.{digits}g})"
        mark = outcome_word(v, judgement.judged)
        lines.append(f"  {limit.name:<14}{shown:>34}   limit {limit.text:<28} {mark}"
                     + (f"  ({v.note})" if v.note else ""))
    if judgement.fit_error_percent:
        from analysis.fit.error import band_text
        shown = None if isinstance(validity, str) else validity
        lines.append("  fit error: " + ", ".join(
            f"{name} {err:.2g} %{band_text(shown, name)} (tolerance {limits.fit_error_percent.get(name, float('nan')):g} %)"
            for name, err in judgement.fit_error_percent.items()))
    lines.append(f"QA: {judgement.headline} — {judgement.why}")
    return "\n".join(lines)
