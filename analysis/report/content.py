"""What a report says, independent of how it is rendered (HTML or PDF).

A report is built from a StoredResult (analysis.archive.results) and the
measurement's header (driver, serial, date, operator, station): the same
content whether the measurement comes from the archive or was analysed on
the fly. Everything is already formatted for people here (customary units,
rounded to the uncertainty); the renderers only lay it out.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, Mapping

from analysis.archive.results import StoredResult
from analysis.fit.error import band_text, hz_text
from analysis.fit.report import fit_report_rows
from analysis.fit.methods import DEFAULT_METHOD, METHODS
from analysis.report.customer import (calibration_rows, file_name, model_title, parameter_row_cells,
                                      split_parameters)
from analysis.report.numbers import determined, format_number, format_std, pretty_unit, readable_number
from analysis.report.qa import LimitRow, QASection, qa_section
from analysis.validity.result import ResultValidity

CHANNEL_TITLES = {"voltage": "Voltage", "current": "Current", "displacement": "Displacement"}
HEADER_FIELDS = (("driver", "Driver"), ("serial", "Serial number"), ("measured_at", "Date"),
                 ("operator", "Operator"), ("station", "Station"), ("template", "Template"),
                 ("software", "Measured with"), ("id", "Measurement id"), ("source", "Source"),
                 ("reported_with", "Reported with"))
# Shown with "–" when unknown: a reader sees that they are missing.
ALWAYS_SHOWN = ("driver", "serial", "measured_at", "operator", "station")
SETTING_LABELS = {
    "sample_rate_hz": ("Sample rate", "Hz"), "period_samples": ("Period", "samples"),
    "periods_analysed": ("Periods analysed", ""), "settle_periods": ("Settle periods", ""),
    "excited_lines": ("Excited lines", ""), "f_min_hz": ("Lowest line", "Hz"), "f_max_hz": ("Highest line", "Hz"),
    "duration_s": ("Duration", "s"), "voltage_rms_v": ("Drive voltage", "V rms"), "channels": ("Channels", ""),
    # Imported curves (analysis.curves.stored): the band each was fitted over, [low, high].
    "impedance_band_hz": ("Impedance fitted", "Hz"), "displacement_band_hz": ("Hx fitted", "Hz"),
}


@dataclass(frozen=True, kw_only=True)
class Finding:
    channel: str
    severity: str
    code: str
    message: str
    remedy: str


@dataclass(frozen=True)
class Light:
    channel: str
    status: str          # green | yellow | red | absent | unknown
    findings: tuple[Finding, ...] = ()


@dataclass(frozen=True)
class ParameterRow:
    name: str
    value: str
    std: str
    unit: str
    relative: str
    note: str            # why a value is missing
    fitted: bool
    determined: bool = True     # False: the value reads NOT_DETERMINED (analysis.report.numbers.determined)


@dataclass(frozen=True)
class ReportContent:
    title: str
    header: tuple[tuple[str, str], ...]
    overall: str
    lights: tuple[Light, ...]
    peak_displacement: str
    parameters: tuple[ParameterRow, ...]            # the Thiele-Small set with Sd, as the workstation names them
    model: tuple[tuple[str, str], ...]              # the model in words and how well it fits
    settings: tuple[tuple[str, str], ...]
    calibration: tuple[tuple[str, str], ...]        # in words: each input's full scale
    result: StoredResult = field(repr=False)
    notes: tuple[str, ...] = ()          # e.g. why there is no SPL plot
    qa: QASection | None = None          # the verdict against a limits file, when one was given
    # The appendix: the engineering detail a customer's page leaves out.
    internal: tuple[ParameterRow, ...] = ()         # the model's own quantities (CMES, LCES, ...)
    fit: tuple[tuple[str, str], ...] = ()           # effects by id, chi^2, AIC/BIC, correlations
    calibration_detail: tuple[tuple[str, str], ...] = ()     # the recording's calibration keys as stored

    @property
    def has_spl(self) -> bool:
        return self.result.sd_m2 is not None and "displacement" in self.result.curves

    @property
    def has_displacement(self) -> bool:
        return "displacement" in self.result.curves


def _lights(validity: ResultValidity) -> tuple[Light, ...]:
    lights = []
    for name, channel in validity.channels.items():
        findings = tuple(Finding(channel=name, severity=str(f.severity), code=f.code, message=f.message,
                                 remedy=f.remedy) for f in channel.findings)
        lights.append(Light(name, str(channel.status or "unknown"), findings))
    return tuple(lights)


def _effect(effect_id: str, result: StoredResult):
    from analysis.effects import CATALOGUE
    return result.user_effects.get(effect_id) or CATALOGUE.get(effect_id)


def _effect_title(effect_id: str, result: StoredResult) -> str:
    e = _effect(effect_id, result)
    return f"{effect_id} ({e.title})" if e else effect_id


def _user_effect_rows(result: StoredResult) -> list[tuple[str, str]]:
    """Each effect of the user's own with its formula, site and file: the report says what was fitted."""
    return [(f"Own effect {e.id}", f"{e.formula.text} at the {e.site.key} site ({e.acts_as}); file "
                                   f"{file_name(e.source)}")
            for e in result.user_effects.values() if e.id in result.effects]


def uncertainty_parts(p) -> str:
    """"± 0.12 g noise, ± 0.9 g model" for the note column, where the analysis estimated the two parts."""
    unit = pretty_unit(p.display_unit)
    unit = "" if unit in ("", "-", "1") else f" {unit}"
    return ", ".join(f"± {format_std(std * abs(p.display_scale))}{unit} {what}"
                     for std, what in ((p.std_noise, "noise"), (p.std_model, "model")) if std is not None)


def _method_text(result: StoredResult) -> str:
    """The identification method's name and what it did (results stored before methods had a name: joint). The
    joint fit's words say what it had: Z alone when there was no Hx, and for imported curves each line's noise
    estimated from its curve's scatter (analysis.curves.noise), where a recording's is measured."""
    name = result.model_info.get("method") or DEFAULT_METHOD
    if name != "joint" or name not in METHODS:
        return f"{name}: {METHODS[name]}" if name in METHODS else str(name)
    fitted = "Z and Hx fitted together" if result.with_displacement else "Z fitted alone"
    noise = "its noise" if result.validity.imported is None else "the noise estimated from its curve's scatter"
    return f"{name}: {fitted}, each line weighted by {noise}"


def _chi2_text(info: Mapping) -> str:
    chi = info.get("chi2_red") or {}
    return ", ".join(f"{readable_number(v, 3)} ({channel})" if isinstance(v, (int, float)) else f"n/a ({channel})"
                     for channel, v in chi.items())


def _model_rows(result: StoredResult) -> tuple[tuple[str, str], ...]:
    """The customer's lines: the model by the titles of its effects, the fit in one line."""
    if result.not_fitted:
        return (("Model", "nothing fitted"), ("Why", result.not_fitted))
    titles = [e.title if e else effect_id for effect_id, e in ((i, _effect(i, result)) for i in result.effects)]
    info = result.model_info
    rows = [("Model", model_title(titles, result.with_displacement))]
    for channel, value in (result.validity.fit_error_percent or {}).items():
        band = band_text(result.validity, channel).strip(" ()")
        rows.append((f"Fit error ({channel})", (f"over {band}: " if band else "")
                     + f"{readable_number(value)} % (rms misfit in its fitted band)"))
    from analysis.curves.reference import comparison_detail
    for channel, beside in result.reference_fit.items():     # imported curves: the tool's fit, overlaid
        rows.append((f"The export's fit ({channel})", comparison_detail(beside)))
    from analysis.fit.model_uncertainty import model_part_words
    words = model_part_words(result.validity)
    if words:           # what each ± holds besides the noise (analysis.fit.model_uncertainty)
        rows.append(("Model part", words.removeprefix("model part: ")))
    chi = _chi2_text(info)
    if chi:
        rows.append(("Fit quality", f"reduced χ² {chi}; 1 means the model fits within the noise"))
    if not info.get("converged"):
        rows.append(("Converged", f"NO: {info.get('message', '')}"))
    return tuple(rows)


def _fit_rows(result: StoredResult) -> tuple[tuple[str, str], ...]:
    """The appendix's lines: effects by id, every statistic of the fit, its correlations and notes."""
    if result.not_fitted:
        return ()
    info = result.model_info
    effects = ", ".join(_effect_title(e, result) for e in result.effects) or "none (the textbook lumped model)"
    rows = [("Effects", effects), ("Method", _method_text(result))] + _user_effect_rows(result)
    for channel, value in (info.get("chi2_red") or {}).items():
        rows.append((f"Reduced χ² ({channel})", format_number(value) if value is not None else "n/a"))
    for key, label in (("aic", "AIC"), ("bic", "BIC")):
        value = info.get(key)
        rows.append((label, f"{value:.1f}" if isinstance(value, (int, float)) else "n/a"))
    rows.append(("Data, parameters", f"{info.get('n_data', 'n/a')} real data points, "
                                     f"{info.get('n_parameters', 'n/a')} fitted parameters"))
    converged = info.get("converged")
    rows.append(("Converged", "yes" if converged else f"NO: {info.get('message', '')}"))
    if isinstance(info.get("report"), Mapping):       # results stored before the fit kept its report have none
        rows += fit_report_rows(info["report"])
    return tuple(rows)


def _flatten(prefix: str, value: Any, out: list[tuple[str, str]]) -> None:
    if isinstance(value, Mapping):
        for k, v in value.items():
            _flatten(f"{prefix}.{k}" if prefix else str(k), v, out)
    elif isinstance(value, list) and len(value) > 12:
        out.append((prefix, f"{len(value)} values"))
    else:
        out.append((prefix, value if isinstance(value, str) else json.dumps(value)))


def _settings_rows(settings: Mapping) -> tuple[tuple[str, str], ...]:
    rows = []
    for key, value in settings.items():
        label, unit = SETTING_LABELS.get(key, (key, ""))
        if isinstance(value, float):
            text = format_number(value)
        elif isinstance(value, list) and all(isinstance(v, str) for v in value):
            text = ", ".join(value)
        elif (key.endswith("_band_hz") and isinstance(value, list) and len(value) == 2
              and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
            text = " – ".join(hz_text(v) for v in value)
        elif isinstance(value, (Mapping, list)):
            flat: list[tuple[str, str]] = []
            _flatten(key, value, flat)
            rows += flat
            continue
        else:
            text = str(value)
        rows.append((label, f"{text} {unit}".strip()))
    return tuple(rows)


def _rows(parameters) -> tuple[ParameterRow, ...]:
    rows = []
    for p in parameters:
        name, value, std, unit, rel = parameter_row_cells(p)
        rows.append(ParameterRow(name, value, std, unit, rel, p.reason or uncertainty_parts(p), p.fitted,
                                 determined(p)))
    return tuple(rows)


def build_report(result: StoredResult, header: Mapping[str, Any], settings: Mapping | None = None,
                 calibration: Mapping | None = None, limits=None) -> ReportContent:
    """header: driver, serial, measured_at, operator, station, id, source (any may be missing).

    limits: an analysis.limits.Limits to judge the parameters against (the report then carries the
    QA verdict); None: the report says nothing about limits.
    """
    from analysis.session import software
    # The recording's session is the base (analysis.session): the same header from the recording, the
    # archive or an export; what the caller knows (the archive's id, the file) is added.
    header = {**result.session, **{k: v for k, v in header.items() if v}, "reported_with": software()}
    if header.get("source"):
        header["source"] = file_name(header["source"])      # the file, not the folder it was in
    head = tuple((label, str(header.get(key) or "–")) for key, label in HEADER_FIELDS
                 if header.get(key) or key in ALWAYS_SHOWN)
    customer, internal = split_parameters(result.parameters, result.sd_m2)
    peak = result.validity.peak_displacement_m
    peak_text = f"{peak * 1e3:.3g} mm" if isinstance(peak, (int, float)) else "not measured"
    cal: list[tuple[str, str]] = []
    _flatten("", dict(calibration or {}), cal)
    notes = []
    if result.not_fitted:
        notes.append(f"Nothing was fitted, so there are no parameters and no plots: {result.not_fitted}")
    elif "displacement" not in result.curves:
        notes.append("No displacement channel: Bl, the mechanical parameters, Hx and SPL cannot be shown.")
    elif result.sd_m2 is None:
        notes.append("Sd unknown: no SPL prediction (give the effective radiating area).")
    title = " ".join(x for x in (str(header.get("driver") or ""), str(header.get("serial") or "")) if x)
    return ReportContent(
        title=f"Linear parameters: {title}" if title else "Linear parameters",
        header=head, overall=result.overall, lights=_lights(result.validity), peak_displacement=peak_text,
        parameters=_rows(customer), model=_model_rows(result),
        settings=_settings_rows({**dict(result.settings), **dict(settings or {})}),
        calibration=calibration_rows(calibration, imported=result.validity.imported is not None),
        result=result, notes=tuple(notes),
        qa=None if limits is None else qa_section(limits, result.parameters, result.validity),
        internal=_rows(internal), fit=_fit_rows(result), calibration_detail=tuple(cal))


__all__ = ["Finding", "Light", "LimitRow", "ParameterRow", "QASection", "ReportContent", "build_report",
           "pretty_unit"]
