"""The results of one analysis as a JSON document, and that document read back.

`results_document(result, recording)` is what the archive keeps as
results.json: everything a report or an export needs without fitting again:
the parameter table (SI, with the customary unit and its scale), the model
(effect ids, fitted values, standard errors, reduced chi^2 per channel, AIC,
BIC), the validity, and the measured lines of Z and Hx with their per-line
uncertainty and the model at those lines. `StoredResult.from_json` reads it
back; a report of a fresh analysis goes the same way, so archived and fresh
reports cannot differ.

JSON has no NaN: a missing or non-finite number is null.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from analysis.bounds import FREQUENCY, SD
from analysis.derived import ParameterValue
from analysis.errors import LinparError
from analysis.fit.report import fit_report_json
from analysis.json_finite import finite
from analysis.session import session_of
from analysis.validity.result import ResultValidity, ResultValidityError

FORMAT = "linpar-results/1"
CHANNELS = ("impedance", "displacement")


def _num(x) -> float | None:
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def _list(a) -> list:
    return [_num(v) for v in np.asarray(a, dtype=float)]


def _settings_of(recording, result) -> dict:
    spectra = result.spectra
    if result.fit is not None:
        freqs = result.fit.channels["impedance"].freqs
    else:       # nothing fitted: the band the excitation drove
        freqs = np.asarray(spectra.excited_bins, dtype=float) * spectra.bin_width
    out = {
        "sample_rate_hz": spectra.sample_rate,
        "period_samples": spectra.period_samples,
        "periods_analysed": spectra.n_periods,
        "excited_lines": len(spectra.excited_bins),
        "f_min_hz": _num(freqs.min()) if len(freqs) else None,
        "f_max_hz": _num(freqs.max()) if len(freqs) else None,
    }
    if recording is not None:
        out["settle_periods"] = recording.settle_periods
        out["duration_s"] = recording.duration_s
        out["channels"] = [c.signal for c in recording.channels]
        u = recording.signal("voltage")
        if u is not None:
            out["voltage_rms_v"] = _num(np.sqrt(np.mean(np.square(u))))
    return out


def results_document(result, recording=None) -> dict:
    """The JSON document of an analysis.pipeline.AnalysisResult (and of its recording's settings).

    A result with nothing fitted (a broken measurement: analysis.validity.fit) is kept too, so that it can
    be archived, reported and exported as judged: its parameters are "not measured" with the reason, its
    model has no effects and says why under "not_fitted", and it has no curves.

    Every archived or reported result goes through here, so its uncertainties include the model part
    (analysis.fit.model_uncertainty: refitted here when the caller has not; the same result when it has).
    """
    from analysis.fit.model_uncertainty import model_uncertainty
    result = model_uncertainty(result)
    fit = result.fit
    parameters = {}
    for name, p in result.parameters.items():
        parameters[name] = {"value": _num(p.value), "std": _num(p.std), "unit": p.unit,
                            "display_unit": p.display_unit, "display_scale": p.display_scale,
                            "reason": p.reason, "fitted": p.fitted}
        # The uncertainty's two parts, when estimated (issue 29): QA, reports and exports read them back.
        parameters[name].update({k: _num(v) for k, v in (("std_noise", p.std_noise), ("std_model", p.std_model))
                                 if v is not None})
    doc = {
        "format": FORMAT,
        "parameters": parameters,
        "model": _model_json(fit) if fit is not None else not_fitted_model(result.not_fitted),
        "validity": result.validity.as_json(),
        "sd_m2": _num(result.sd_m2),
        # Imported curves (analysis.curves.stored) have no spectra: their settings are their fitted bands.
        "settings": _settings_of(recording, result) if hasattr(result, "spectra") else {},
        "curves": {} if fit is None else _curves_json(fit),
    }
    session = session_of(recording) if recording is not None else {}
    if session:
        doc["session"] = session
    return doc


def not_fitted_model(why: str | None) -> dict:
    """The "model" of a result with nothing fitted: no effects, no values, and why."""
    why = why or "nothing could be fitted"
    return {"effects": [], "with_displacement": False, "user_effects": [], "values": {}, "stderr": {},
            "chi2_red": {}, "aic": None, "bic": None, "n_data": 0, "n_parameters": 0, "converged": False,
            "message": why, "not_fitted": why}


def _model_json(fit) -> dict:
    return {"effects": list(fit.model.effect_ids), "method": fit.method,
            "with_displacement": fit.model.with_displacement,
            "user_effects": user_effects_json(fit.model.effects),
            "values": {k: _num(v) for k, v in fit.values.items()},
            "stderr": {k: _num(v) for k, v in fit.stderr.items()},
            "chi2_red": {k: _num(v) for k, v in fit.chi2_red_by_channel().items()},
            "aic": _num(fit.aic), "bic": _num(fit.bic), "n_data": fit.n_data,
            "n_parameters": fit.n_varying, "converged": bool(fit.success), "message": fit.message,
            "noise_known": fit.noise_known, "report": finite(fit_report_json(fit))}


def _curves_json(fit) -> dict:
    curves = {}
    for name, ch in fit.channels.items():
        curves[name] = {"unit": "ohm" if name == "impedance" else "m/V", "has_phase": bool(ch.has_phase),
                        "freqs_hz": _list(ch.freqs), "measured_re": _list(np.real(ch.measured)),
                        "measured_im": _list(np.imag(ch.measured)), "std": _list(ch.std),
                        "model_re": _list(np.real(ch.model)), "model_im": _list(np.imag(ch.model))}
    return curves


def user_effects_json(effects) -> list[dict]:
    """Effects of the user's own, with their file's text: a stored result re-analyses the same way later,
    whatever has become of the file."""
    return [{"id": e.id, "file": e.source, "text": e.text} for e in effects if getattr(e, "text", "")]


def _user_effects(model: Mapping) -> dict:
    """The stored effects of the user's own, rebuilt from their text (by id)."""
    from analysis.effects.file_error import EffectFileError
    from analysis.effects.user import effect_from_text
    stored = model.get("user_effects") or []
    if not isinstance(stored, list):
        raise ResultsFormatError("model.user_effects: expected a list")
    effects = {}
    for i, entry in enumerate(stored):
        where = f"model.user_effects[{i}]"
        if not isinstance(entry, Mapping) or not isinstance(entry.get("text"), str):
            raise ResultsFormatError(f"{where}: expected an object with the effect file's text")
        try:
            effect = effect_from_text(entry["text"], str(entry.get("file") or "effect file"))
        except EffectFileError as exc:
            raise ResultsFormatError(f"{where}: {exc}") from None
        effects[effect.id] = effect
    return effects


@dataclass(frozen=True)
class Curve:
    """Measured lines of one channel, their uncertainty and the model at the same lines."""

    name: str
    unit: str
    freqs: np.ndarray
    measured: np.ndarray      # complex (magnitude only when has_phase is False)
    std: np.ndarray
    model: np.ndarray
    has_phase: bool = True

    @property
    def normalized_residual(self) -> np.ndarray:
        """As analysis.fit.least_squares.ChannelFit: (model - measured) per component in units of its std."""
        sigma = self.std / np.sqrt(2.0)
        if not self.has_phase:
            return (np.abs(self.model) - self.measured.real) / sigma
        return (self.model - self.measured) / sigma


class ResultsFormatError(LinparError, ValueError):
    pass


def _get(doc: Mapping, key: str, kind, where: str):
    if not isinstance(doc, Mapping) or key not in doc:
        raise ResultsFormatError(f"{where}{key}: missing")
    value = doc[key]
    if kind is not None and not isinstance(value, kind):
        raise ResultsFormatError(f"{where}{key}: expected a JSON {kind.__name__ if isinstance(kind, type) else 'value'}")
    return value


def _array(values, where: str) -> np.ndarray:
    if not isinstance(values, list):
        raise ResultsFormatError(f"{where}: expected a list of numbers")
    try:
        return np.array([np.nan if v is None else float(v) for v in values], dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ResultsFormatError(f"{where}: expected a list of numbers") from None


def _number(value, where: str) -> float | None:
    """A JSON number or null as float or None (None for a non-finite one, as _num writes it); else an error."""
    if value is None:
        return None
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        try:
            return _num(value)
        except OverflowError:      # an integer beyond the float range
            return None
    raise ResultsFormatError(f"{where}: expected a number or null")


def _object(doc: Mapping, key: str, where: str) -> dict:
    value = doc.get(key)
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise ResultsFormatError(f"{where}{key}: expected a JSON object")
    return dict(value)


@dataclass(frozen=True, kw_only=True)
class StoredResult:
    parameters: dict[str, ParameterValue]
    effects: tuple[str, ...]
    with_displacement: bool
    values: dict[str, float]
    model_info: dict[str, Any]
    validity: ResultValidity
    sd_m2: float | None
    settings: dict
    curves: dict[str, Curve] = field(default_factory=dict)
    user_effects: dict = field(default_factory=dict)     # id -> the Effect rebuilt from its stored file text
    session: dict = field(default_factory=dict)          # the recording's traceability (analysis.session)
    # Imported curves (analysis.curves.stored): the exporting tool's fitted |Z| / |Hx| as (freqs, magnitude in
    # SI), and how far it lies from the measured curve and from linpar's fit (analysis.curves.reference).
    reference_curves: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    reference_fit: dict = field(default_factory=dict)

    @classmethod
    def from_json(cls, doc: Mapping) -> "StoredResult":
        if _get(doc, "format", str, "") != FORMAT:
            raise ResultsFormatError(f"format: expected {FORMAT!r}")
        parameters = {}
        for name, p in _get(doc, "parameters", dict, "").items():
            where = f"parameters.{name}."
            if not isinstance(p, Mapping):
                raise ResultsFormatError(f"parameters.{name}: expected a JSON object")
            scale = _number(_get(p, "display_scale", (int, float), where), where + "display_scale")
            if scale is None:
                raise ResultsFormatError(f"{where}display_scale: expected a finite number")
            reason = p.get("reason")
            parameters[name] = ParameterValue(name=name, value=_number(p.get("value"), where + "value"),
                                              std=_number(p.get("std"), where + "std"),
                                              unit=_get(p, "unit", str, where),
                                              display_unit=_get(p, "display_unit", str, where), display_scale=scale,
                                              reason=None if reason is None else str(reason),
                                              fitted=bool(p.get("fitted", False)),
                                              std_noise=_number(p.get("std_noise"), where + "std_noise"),
                                              std_model=_number(p.get("std_model"), where + "std_model"))
        model = _get(doc, "model", dict, "")
        effects = tuple(str(e) for e in _get(model, "effects", list, "model."))
        values = {}
        for k, v in _get(model, "values", dict, "model.").items():
            values[k] = _number(v, f"model.values.{k}")
            if values[k] is None:       # the model's curves are drawn from these: each must be a number
                raise ResultsFormatError(f"model.values.{k}: found {v!r}, expected a finite number")
        curves = {}
        for name, c in _get(doc, "curves", dict, "").items():
            if name not in CHANNELS:
                continue
            where = f"curves.{name}."
            arr = {k: _array(_get(c, k, list, where), where + k)
                   for k in ("freqs_hz", "measured_re", "measured_im", "std", "model_re", "model_im")}
            if len({len(a) for a in arr.values()}) != 1:
                raise ResultsFormatError(f"{where}: the lists differ in length")
            bad = np.flatnonzero(~((arr["freqs_hz"] >= FREQUENCY.low) & (arr["freqs_hz"] <= FREQUENCY.high)))
            if bad.size:
                raise ResultsFormatError(f"{where}freqs_hz[{bad[0]}]: found {arr['freqs_hz'][bad[0]]!r}, "
                                         f"expected {FREQUENCY.expected()}")
            curves[name] = Curve(name, str(c.get("unit", "")), arr["freqs_hz"],
                                 arr["measured_re"] + 1j * arr["measured_im"], arr["std"],
                                 arr["model_re"] + 1j * arr["model_im"], bool(c.get("has_phase", True)))
        sd = doc.get("sd_m2")
        return cls(parameters=parameters, effects=effects,
                   with_displacement=bool(model.get("with_displacement", "displacement" in curves)), values=values,
                   model_info=dict(model), validity=_validity(doc),
                   sd_m2=None if sd is None else SD.check(sd, "sd_m2", ResultsFormatError),
                   settings=_object(doc, "settings", ""), curves=curves, user_effects=_user_effects(model),
                   session=_session(doc), reference_curves=_reference_curves(doc),
                   reference_fit=_object(doc, "reference_fit", ""))

    def model(self):
        """The analysis.model.composed.Model the values belong to (rebuilt from the effect ids and the stored effect files)."""
        from analysis.effects import parse_effects
        from analysis.model.composed import Model
        return Model(parse_effects(",".join(self.effects) or "none", self.user_effects), self.with_displacement)

    def model_curve(self, name: str, freqs: np.ndarray) -> np.ndarray:
        """The fitted model of 'impedance' (ohm) or 'displacement' (m/V) at any frequencies."""
        model = self.model()
        s = 2j * np.pi * np.asarray(freqs, dtype=float)
        return model.impedance(s, self.values) if name == "impedance" else model.displacement(s, self.values)

    @property
    def overall(self) -> str:
        return str(self.validity.overall)

    @property
    def not_fitted(self) -> str | None:
        """Why nothing was fitted (a broken measurement), or None for a fitted result."""
        why = self.model_info.get("not_fitted")
        return str(why) if why else None


def _validity(doc: Mapping) -> ResultValidity:
    try:
        return ResultValidity.from_json(_object(doc, "validity", ""))
    except ResultValidityError as exc:
        raise ResultsFormatError(str(exc)) from None


def _reference_curves(doc: Mapping) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    out = {}
    for name, c in _object(doc, "reference_curves", "").items():
        if name not in CHANNELS:
            continue
        where = f"reference_curves.{name}."
        freqs = _array(_get(c, "freqs_hz", list, where), where + "freqs_hz")
        magnitude = _array(_get(c, "magnitude", list, where), where + "magnitude")
        if len(freqs) != len(magnitude):
            raise ResultsFormatError(f"{where}: the lists differ in length")
        out[name] = (freqs, magnitude)
    return out


def _session(doc: Mapping) -> dict:
    session = doc.get("session")
    if session is not None and not isinstance(session, Mapping):
        raise ResultsFormatError("session: expected a JSON object")
    from analysis.session import trace_header
    return trace_header({}, session)


def stored_from_recording(path, sd_m2: float | None = None, effects=None):
    """Analyse a recording file now: (StoredResult, header, calibration), as an archived copy would give."""
    from analysis.pipeline import analyze_recording
    from analysis.recording.format import read_recording
    recording = read_recording(path)
    result = analyze_recording(recording, sd_m2, effects)
    stored = StoredResult.from_json(results_document(result, recording))
    return stored, header_of_recording(recording, path), calibration_of(recording)


def header_of_recording(recording, path=None) -> dict:
    """The report's header of a recording (analysis.session.trace_header), and its file as the source.

    A recording made without a session (another tool, an old file) is dated by its file's time.
    """
    from datetime import datetime, timezone
    from pathlib import Path

    from analysis.session import recording_header
    header = recording_header(recording)
    source = recording.source or path
    if "measured_at" not in header and source is not None:
        try:
            when = datetime.fromtimestamp(Path(source).stat().st_mtime, timezone.utc)
            header["measured_at"] = when.isoformat(timespec="seconds").replace("+00:00", "Z") + " (file time)"
        except (OSError, TypeError, ValueError):
            pass
    if source is not None:
        header["source"] = str(source)
    return header


def calibration_of(recording) -> dict:
    """What a report shows under Calibration: the sidecar's "calibration" and "capture"."""
    extra = recording.extra or {}
    return {k: extra[k] for k in ("calibration", "capture") if k in extra}
