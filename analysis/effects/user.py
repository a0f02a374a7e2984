"""Effects of the user's own: one TOML file each, checked where it is read.

The format (docs/effects.md has the whole of it):

    id = "rms-sqrt-f"
    title = "Viscous damping rising with the square root of frequency"
    site = "mechanical"
    formula = "r * (sqrt(w / ws) - 1)"
    physics = "Air pumped through the spider and the surround adds damping that grows with frequency."

    [parameters.r]
    unit = "kg/s"
    start = 0.5
    min = -10
    max = 10

Optional: `category` (one effect per category in a model; by default the effect is a category of its
own), `signature`, `typical`, `reference`, and per parameter `description` and `typical = [lo, hi]`
(a fit outside is flagged, as for the catalogue). Anything else is refused.

The formula (analysis.effects.formula) gives, at its site (docs/physics.md section 8):

    electrical     ohms added to the blocked impedance Ze
    force-factor   a factor on Bl, in the force and the back-EMF alike
    mechanical     kg/s added to the mechanical impedance Zm (so the model's admittance gains it / Bl^2)
    compliance     a factor on the suspension compliance Cms
    current        a factor on the measured current (so the measured Z is divided by it)
    displacement   a factor on the measured displacement

Every error is an EffectFileError whose text is one line naming the file, the key (or the formula's
column) and what was expected.
"""
from __future__ import annotations

import json
import keyword
import math
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis.effects.base import Effect, ParamSpec, Site, SITE_KEYS
from analysis.effects.file_error import EffectFileError
from analysis.effects.formula import RESERVED, Formula, FormulaError, parse_formula
from analysis.model.lumped import resonance_frequency
from analysis.text_boundary import CONTROL, CONTROL_BUT_NEWLINE, control_found


REQUIRED = ("id", "title", "site", "formula", "physics")
OPTIONAL = ("category", "signature", "typical", "reference", "parameters")
PARAMETER_REQUIRED = ("unit", "start", "min", "max")
PARAMETER_OPTIONAL = ("description", "typical")
MULTI_LINE = ("physics", "signature", "typical", "reference", "formula")
ID_PATTERN = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*\Z")
NAME_PATTERN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
MAX_FILE_BYTES = 64 * 1024
# The band and resonance a formula is first checked on (before any data: typical of a measurement);
# the fit checks it again on its own lines and fs.
CHECK_FREQS = np.geomspace(1.0, 20e3, 200)
CHECK_FS = 50.0
UNITS_AT_SITE = {Site.BLOCKED: "ohm added to Ze", Site.FORCE_FACTOR: "a factor on Bl",
                 Site.MECHANICAL: "kg/s added to Zm", Site.COMPLIANCE: "a factor on Cms",
                 Site.CURRENT: "a factor on the measured current",
                 Site.DISPLACEMENT: "a factor on the measured displacement"}


@dataclass(frozen=True)
class UserEffect(Effect):
    """The response is the file's formula F(s) taken at its site: Ze + F (electrical), Bl * F (force-factor),
    Zm + F, so Y = Zm/Bl^2 + F/Bl^2 (mechanical), Cms * F (compliance), Z / F (current: the measured
    current is I * F), Hx * F (displacement); s = j*w, ws = 2*pi*fs of the fit's own CMES and LCES."""

    formula: Formula | None = None
    source: str = ""          # the file (or package entry point) it came from
    text: str = ""            # the file's text, kept with results so that they re-analyse the same way

    @property
    def needs_bl(self) -> bool:
        return self.site is Site.MECHANICAL

    @property
    def acts_as(self) -> str:
        """What the formula's value is at the effect's site, in words: 'kg/s added to Zm'."""
        return UNITS_AT_SITE[self.site]

    def response(self, s, p):
        ws = 2.0 * np.pi * resonance_frequency(p)
        value = self.formula.evaluate(s, ws, p)
        if self.site is Site.MECHANICAL:
            return value / p["Bl"] ** 2
        if self.site is Site.CURRENT:
            with np.errstate(all="ignore"):
                return 1.0 / value
        return value

    def check_finite(self, s: np.ndarray, p, where: str) -> None:
        """EffectFileError when the formula is not a finite number at every line of `s` with the values `p`."""
        with np.errstate(all="ignore"):
            value = self.response(s, p)
        bad = ~np.isfinite(value)
        if bad.any():
            f = np.abs(np.asarray(s))[bad] / (2.0 * np.pi)
            raise EffectFileError(
                f"{self.source}: formula: gives NaN or infinity at {int(bad.sum())} of {bad.size} lines ({where}; "
                f"first at {f[0]:.4g} Hz) with the parameters at their start values; expected a finite number at "
                "every line")

    def describe(self) -> dict:
        return {**super().describe(), "formula": self.formula.text, "file": self.source, "user": True}


def _fail(source: str, key: str, expected: str) -> EffectFileError:
    return EffectFileError(f"{source}: {key}: {expected}")


def _string(doc: dict, key: str, source: str, required: bool = True) -> str:
    if key not in doc:
        if required:
            raise _fail(source, key, "missing; an effect file needs " + ", ".join(REQUIRED) + " and [parameters.NAME]")
        return ""
    value = doc[key]
    if not isinstance(value, str) or not value.strip():
        raise _fail(source, key, "expected a non-empty string")
    # Titles and ids are printed on one line (terminals, menus); descriptions may span lines, no more.
    what = control_found(value.strip(), CONTROL_BUT_NEWLINE if key in MULTI_LINE else CONTROL)
    if what:
        raise _fail(source, key, f"holds {what}; expected text")
    return value.strip()


def _number(table: dict, key: str, where: str, source: str) -> float:
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _fail(source, f"{where}.{key}", "expected a number")
    value = float(value)
    if not math.isfinite(value):
        raise _fail(source, f"{where}.{key}", "expected a finite number")
    return value


def _parameter(name: str, table, source: str, taken: dict[str, str]) -> ParamSpec:
    where = f"parameters.{name}"
    if not NAME_PATTERN.match(name) or keyword.iskeyword(name):
        raise _fail(source, where, "a parameter's name is a letter followed by letters, digits or _, "
                                   "and not a Python word (lambda, if, ...)")
    if name in RESERVED:
        raise _fail(source, where, f"{name!r} is a name of the formula language; choose another name")
    if name in taken:
        raise _fail(source, where, f"{name!r} is already a parameter of {taken[name]}; choose another name")
    if not isinstance(table, dict):
        raise _fail(source, where, "expected a table with unit, start, min and max")
    unknown = sorted(set(table) - set(PARAMETER_REQUIRED) - set(PARAMETER_OPTIONAL))
    if unknown:
        raise _fail(source, f"{where}.{unknown[0]}", "not a key of a parameter; expected unit, start, min, max "
                                                    "and optionally description, typical")
    if "min" not in table or "max" not in table:
        raise _fail(source, where, "expected both bounds, min and max (without them the fit can run away)")
    for key in PARAMETER_REQUIRED:
        if key not in table:
            raise _fail(source, f"{where}.{key}", "missing; a parameter needs unit, start, min and max")
    unit = table["unit"]
    if not isinstance(unit, str) or not unit.strip() or control_found(unit):
        raise _fail(source, f"{where}.unit", "expected one line of text such as \"kg/s\" or \"1\"")
    lo, hi = _number(table, "min", where, source), _number(table, "max", where, source)
    start = _number(table, "start", where, source)
    if not lo < hi:
        raise _fail(source, where, f"expected min < max, got min {lo:g} and max {hi:g}")
    if not lo <= start <= hi:
        raise _fail(source, f"{where}.start", f"expected a start between min {lo:g} and max {hi:g}, got {start:g}")
    typical = None
    if "typical" in table:
        pair = table["typical"]
        if (not isinstance(pair, list) or len(pair) != 2
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) for v in pair)
                or not pair[0] < pair[1]):
            raise _fail(source, f"{where}.typical", "expected [low, high], two finite numbers, low < high")
        typical = (float(pair[0]), float(pair[1]))
    description = table.get("description", "parameter of the user effect's formula")
    if not isinstance(description, str) or control_found(description, CONTROL_BUT_NEWLINE):
        raise _fail(source, f"{where}.description", "expected text without control characters")
    unit = unit.strip()
    return ParamSpec(name, unit, unit, 1.0, lo, hi, start, description, typical)


def effect_from_text(text: str, source: str, taken: dict[str, str] | None = None,
                     known_ids: frozenset[str] = frozenset()) -> UserEffect:
    """The UserEffect of an effect file's text; `source` names it in messages.

    `taken`: parameter names already in use (by the base model, the catalogue, other files), with their
    owner; `known_ids`: effect ids already in use.
    """
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise EffectFileError(f"{source}: not a TOML file ({exc}); expected key = value lines and "
                              "[parameters.NAME] tables") from None
    except RecursionError:          # tomllib recurses once per nested array or table
        raise EffectFileError(f"{source}: nested too deeply to be an effect file; expected key = value lines "
                              "and [parameters.NAME] tables") from None
    unknown = sorted(set(doc) - set(REQUIRED) - set(OPTIONAL))
    if unknown:
        raise _fail(source, unknown[0], "not a key of an effect file; expected " + ", ".join(REQUIRED)
                    + ", [parameters.NAME] and optionally category, signature, typical, reference")
    effect_id = _string(doc, "id", source)
    if not ID_PATTERN.match(effect_id) or effect_id in ("none", "textbook"):
        raise _fail(source, "id", "expected letters, digits, '-', '_' or '.', starting with a letter or digit "
                                  "(it is written in --model lists)")
    if effect_id in known_ids:
        raise _fail(source, "id", f"{effect_id!r} is already an effect (of the catalogue or another file); "
                                  "choose another id")
    site_key = _string(doc, "site", source)
    try:
        site = Site.from_key(site_key)
    except KeyError:
        raise _fail(source, "site", f"unknown site {site_key!r}; expected one of "
                                    + ", ".join(SITE_KEYS.values())) from None
    tables = doc.get("parameters", {})
    if not isinstance(tables, dict):
        raise _fail(source, "parameters", "expected tables [parameters.NAME]")
    params = tuple(_parameter(name, table, source, dict(taken or {})) for name, table in tables.items())
    formula_text = _string(doc, "formula", source)
    try:
        formula = parse_formula(formula_text, tuple(p.name for p in params))
    except FormulaError as exc:
        raise _fail(source, f"formula, {exc.where}", str(exc)) from None
    unused = [p.name for p in params if p.name not in formula.names]
    if unused:
        raise _fail(source, f"parameters.{unused[0]}", "not used in the formula; the data could not determine it")
    category = _string(doc, "category", source, required=False) or effect_id
    effect = UserEffect(
        id=effect_id, category=category, title=_string(doc, "title", source), site=site, params=params,
        physics=_string(doc, "physics", source),
        signature=_string(doc, "signature", source, required=False) or "(not given in the file)",
        typical=_string(doc, "typical", source, required=False) or "(not given in the file)",
        reference=_string(doc, "reference", source, required=False) or "(not given in the file)",
        notes=f"An effect of your own, from {source}: {formula_text} ({UNITS_AT_SITE[site]}).",
        formula=formula, source=source, text=text)
    check_values = {"CMES": 1.0, "LCES": 1.0 / (2.0 * np.pi * CHECK_FS) ** 2, "Bl": 1.0,
                    **{p.name: p.default for p in params}}
    effect.check_finite(2j * np.pi * CHECK_FREQS, check_values,
                        f"the check band 1 Hz to 20 kHz, fs {CHECK_FS:g} Hz")
    return effect


def load_effect_file(path: str | Path, taken: dict[str, str] | None = None,
                     known_ids: frozenset[str] = frozenset()) -> UserEffect:
    """Read and check one effect file (EffectFileError with one line when anything is wrong)."""
    path = Path(path)
    source = str(path)
    try:
        if not path.is_file():
            raise EffectFileError(f"{source}: no such effect file" if not path.exists() else
                                  f"{source}: not a regular file; expected a TOML effect file")
        if path.stat().st_size > MAX_FILE_BYTES:
            raise EffectFileError(f"{source}: {path.stat().st_size} bytes; an effect file is at most "
                                  f"{MAX_FILE_BYTES // 1024} KiB")
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise EffectFileError(f"{source}: not UTF-8 text; expected a TOML effect file") from None
    except OSError as exc:
        raise EffectFileError(f"{source}: cannot be read ({exc.strerror or exc})") from None
    return effect_from_text(text, source, taken, known_ids)


@dataclass(frozen=True)
class ParameterEntry:
    """One parameter as a form holds it: text, so that a wrong entry reaches the file's checks, not a crash."""

    name: str
    unit: str
    start: str
    min: str
    max: str


def _toml_value(text: str) -> str:
    """A number as TOML writes it, or the text as a TOML string (which the reader then refuses as not a number)."""
    try:
        value = float(text)
    except ValueError:
        return json.dumps(text)
    return repr(value) if math.isfinite(value) else json.dumps(text)


def effect_file_text(effect_id: str, title: str, site: str, formula: str, physics: str,
                     parameters: list[ParameterEntry], extra: dict[str, str] | None = None) -> str:
    """The TOML text of an effect file from a form's fields (the inverse of effect_from_text).

    JSON's string escapes are valid TOML basic strings, so every text goes through json.dumps.
    """
    lines = [f"id = {json.dumps(effect_id)}", f"title = {json.dumps(title)}", f"site = {json.dumps(site)}",
             f"formula = {json.dumps(formula)}", f"physics = {json.dumps(physics)}"]
    lines += [f"{key} = {json.dumps(value)}" for key, value in (extra or {}).items() if value]
    for p in parameters:
        lines += ["", f"[parameters.{json.dumps(p.name)}]", f"unit = {json.dumps(p.unit)}"]
        lines += [f"{key} = {_toml_value(getattr(p, key))}" for key in ("start", "min", "max")
                  if getattr(p, key).strip()]
    return "\n".join(lines) + "\n"
