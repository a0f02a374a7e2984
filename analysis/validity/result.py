"""A result's validity: the checks' judgement of its channels and what the fit adds, typed, with its JSON.

The checks (analysis.validity.assessment) give a Validity; a result
(analysis.pipeline.AnalysisResult, analysis.curves.fitting.CurveAnalysis,
an archived analysis.archive.results.StoredResult) carries a ResultValidity:
the same lights and findings, plus what was learnt after the checks (the
fit error and its bands, the coil's heating, the laser's delay search, the
model part of the uncertainties), or, for imported curves, why nothing was
checked. `as_json()` is the object `linpar analyze --json` prints under
"validity", and what the archive stores; `from_json()` reads it back:

    recording: {"overall", "channels": {name: {"status", "findings": [...]}}, "peak_displacement_m",
                "fit_error_percent"?, "fit_band_hz"?, "heating"?, "laser_delay"?, "model_part"?}
    imported curves: {"overall": "unknown" | "red", "note", "uncertainties", "rms_relative_residual",
                      "fit_error_percent", "magnitude_only", "ranges_hz", "notes", "channels"?, ...}

A key present in a stored document that this version does not know is kept
(`other`) and written back, so that nothing read is lost.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Mapping

from analysis.errors import LinparError
from analysis.validity.assessment import ChannelValidity, Validity
from analysis.validity.findings import Finding, Severity
from analysis.validity.frozen_json import frozen, rebuilt, thawed

if TYPE_CHECKING:   # imported curves' validity: loaded by the curves' fitting and by a stored one read back
    from analysis.validity.imported_curves import ImportedCurves

__all__ = ["UNKNOWN", "ResultValidity", "ResultValidityError"]

UNKNOWN = "unknown"         # the overall light of what no check judged (imported curves, a result without one)


class ResultValidityError(LinparError, ValueError):
    """A stored "validity" object that cannot be read (message: the key and what was expected)."""


# The keys a ResultValidity knows; any other key of a stored document is kept in `other`.
_RECORDING_KEYS = ("overall", "channels", "peak_displacement_m", "fit_error_percent", "fit_band_hz", "heating",
                   "laser_delay", "model_part")
_CURVE_KEYS = ("note", "uncertainties", "rms_relative_residual", "magnitude_only", "ranges_hz", "notes")


@dataclass(frozen=True, kw_only=True, slots=True)
class ResultValidity:
    """A result's validity (module doc). `overall` is a Severity, or UNKNOWN for what no check judged."""

    overall: str = UNKNOWN
    # Recordings: always voltage, current and displacement; imported curves: the impedance when it is no driver's.
    channels: Mapping[str, ChannelValidity] = field(default_factory=dict)
    peak_displacement_m: float | None = None                # None: no displacement (never NaN)
    fit_error_percent: Mapping[str, float] | None = None    # None: nothing fitted (or stored before it existed)
    fit_band_hz: Mapping[str, tuple[float, float]] | None = None
    heating: Mapping[str, Any] | None = None                # analysis.heating.CoilHeating.as_json()
    laser_delay: Mapping[str, Any] | None = None            # analysis.laser_delay.DelaySearch.as_json()
    model_part: Mapping[str, Any] | None = None             # analysis.fit.model_uncertainty.ModelPart.as_json()
    imported: ImportedCurves | None = None                  # imported curves: why nothing was checked
    other: Mapping[str, Any] = field(default_factory=dict)  # a stored document's keys this version does not know

    def __post_init__(self) -> None:
        object.__setattr__(self, "overall", _light(self.overall))
        object.__setattr__(self, "channels", MappingProxyType(dict(self.channels)))
        peak = self.peak_displacement_m
        object.__setattr__(self, "peak_displacement_m", float(peak) if peak is not None and math.isfinite(peak)
                           else None)
        for name in ("fit_error_percent", "fit_band_hz", "heating", "laser_delay", "model_part", "other"):
            object.__setattr__(self, name, frozen(getattr(self, name)))

    def __reduce__(self):
        # Mapping proxies cannot be pickled (nor deep-copied): the fields as plain values, frozen again on the
        # way in, so that a result can still go to another process or be copied.
        fields = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        plain = {name: dict(value) if name == "channels" else value if name == "imported" else thawed(value)
                 for name, value in fields.items()}
        return rebuilt, (type(self), plain)

    @classmethod
    def checked(cls, validity: Validity, **fit: Any) -> "ResultValidity":
        """The checks' validity of a recording, with what the fit adds (the fields' names)."""
        return cls(overall=validity.overall, channels=validity.channels,
                   peak_displacement_m=validity.peak_displacement_m, **fit)

    def replace(self, **changes: Any) -> "ResultValidity":
        return dataclasses.replace(self, **changes)

    @property
    def findings(self) -> tuple[Finding, ...]:
        """Every channel's findings, channel by channel."""
        return tuple(f for ch in self.channels.values() for f in ch.findings)

    def channel_findings(self, channel: str) -> tuple[Finding, ...]:
        """The findings of one channel; () when the result has no such channel."""
        judged = self.channels.get(channel)
        return () if judged is None else judged.findings

    def codes(self, channel: str) -> set[str]:
        return {f.code for f in self.channel_findings(channel)}

    @property
    def heating_words(self) -> str | None:
        """The coil's warming in words when it was significant (analysis.heating), else None."""
        heating = self.heating or {}
        if not heating.get("significant"):
            return None
        return str(heating.get("text") or "") or None

    def as_json(self) -> dict:
        """The object `linpar analyze --json` prints under "validity" (module doc), keys in that order."""
        out: dict[str, Any] = {"overall": str(self.overall)}
        if self.imported is None:
            out["channels"] = {name: ch.as_json() for name, ch in self.channels.items()}
            out["peak_displacement_m"] = self.peak_displacement_m
            _put(out, "fit_error_percent", self.fit_error_percent)
        else:
            c = self.imported
            out.update(note=c.note, uncertainties=c.uncertainties,
                       rms_relative_residual=thawed(c.rms_relative_residual))
            _put(out, "fit_error_percent", self.fit_error_percent)
            out.update(magnitude_only=thawed(c.magnitude_only), ranges_hz=thawed(c.ranges_hz),
                       notes=thawed(c.notes))
            if self.channels:
                out["channels"] = {name: ch.as_json() for name, ch in self.channels.items()}
        for name in ("fit_band_hz", "heating", "laser_delay", "model_part"):
            _put(out, name, getattr(self, name))
        out.update(thawed(self.other))
        return out

    @classmethod
    def from_json(cls, doc: Any) -> "ResultValidity":
        """A stored "validity" object read back (ResultValidityError, naming the key, when it cannot be)."""
        if doc is None:
            return cls()
        if not isinstance(doc, Mapping):
            raise ResultValidityError("validity: expected an object")
        imported = None
        if "note" in doc:
            from analysis.validity.imported_curves import ImportedCurves
            imported = ImportedCurves(
                note=str(doc.get("note") or ""), uncertainties=str(doc.get("uncertainties") or ""),
                rms_relative_residual=_mapping(doc, "rms_relative_residual"),
                magnitude_only=tuple(str(n) for n in _list(doc, "magnitude_only")),
                ranges_hz=_mapping(doc, "ranges_hz"), notes=tuple(str(n) for n in _list(doc, "notes")))
        known = _RECORDING_KEYS + (_CURVE_KEYS if imported is not None else ())
        peak = doc.get("peak_displacement_m")
        if peak is not None and (isinstance(peak, bool) or not isinstance(peak, (int, float))):
            raise ResultValidityError("validity.peak_displacement_m: expected a number or null")
        return cls(overall=_stored_light(doc.get("overall", UNKNOWN)),
                   channels={str(name): _channel(str(name), ch) for name, ch in _mapping(doc, "channels").items()},
                   peak_displacement_m=None if peak is None else float(peak),
                   **{name: _optional_mapping(doc, name)
                      for name in ("fit_error_percent", "fit_band_hz", "heating", "laser_delay", "model_part")},
                   imported=imported, other={k: v for k, v in doc.items() if k not in known})


def _light(overall: Any) -> str:
    """A Severity for green/yellow/red, the text itself otherwise (UNKNOWN)."""
    text = str(overall)
    return Severity(text) if text in set(Severity) else text


def _stored_light(overall: Any) -> str:
    if not isinstance(overall, str):
        raise ResultValidityError(f"validity.overall: expected one of green, yellow, red, {UNKNOWN}")
    return overall


def _put(out: dict, key: str, value: Any) -> None:
    if value is not None:
        out[key] = thawed(value)


def _mapping(doc: Mapping, key: str) -> Mapping:
    value = doc.get(key)
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise ResultValidityError(f"validity.{key}: expected an object")
    return value


def _optional_mapping(doc: Mapping, key: str) -> Mapping | None:
    return None if doc.get(key) is None else _mapping(doc, key)


def _list(doc: Mapping, key: str) -> list:
    value = doc.get(key)
    if value is None:
        return []
    if not isinstance(value, list):
        raise ResultValidityError(f"validity.{key}: expected a list")
    return value


def _channel(name: str, doc: Any) -> ChannelValidity:
    where = f"validity.channels.{name}"
    if not isinstance(doc, Mapping):
        raise ResultValidityError(f"{where}: expected an object")
    status = doc.get("status")
    if status is not None and not isinstance(status, str):
        raise ResultValidityError(f"{where}.status: expected a text")
    findings = doc.get("findings")
    findings = [] if findings is None else findings
    if not isinstance(findings, list):
        raise ResultValidityError(f"{where}.findings: expected a list")
    return ChannelValidity(name, status, tuple(_finding(name, f, f"{where}.findings[{i}]")
                                               for i, f in enumerate(findings)))


def _finding(channel: str, doc: Any, where: str) -> Finding:
    if not isinstance(doc, Mapping):
        raise ResultValidityError(f"{where}: expected an object")
    severity = doc.get("severity")
    if severity not in set(Severity):
        raise ResultValidityError(f"{where}.severity: expected one of green, yellow, red")
    value = doc.get("value")
    if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))):
        raise ResultValidityError(f"{where}.value: expected a number or null")
    return Finding(channel, str(doc.get("code") or ""), Severity(severity), str(doc.get("message") or ""),
                   str(doc.get("remedy") or ""), math.nan if value is None else float(value))

