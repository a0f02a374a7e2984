"""From a recording to the full parameter table: spectra, judged channels, fit, derived parameters.

A broken measurement is judged, not refused (analysis.validity.fit): the
channels are judged first; a silent or copied voltage or current leaves the
impedance nothing to fit, and the result then carries its validity with
every parameter "not measured" and why (`fit` is None); a silent
displacement is left out, and the electrical parameters are fitted as for a
recording without the laser. After the fit, a misfit far above the noise is
a finding too. Callers that need a fit (a diagnosis, a report, the archive)
call `require_fit`, which raises NotAnalysable with the reason.
"""
from __future__ import annotations

import dataclasses
import functools
import math
import threading
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Iterator, Sequence

import numpy as np

from analysis.derived import NO_DISPLACEMENT, ParameterValue, parameter_table, unmeasured_table
from analysis.effects import Effect, DEFAULT_EFFECTS, get_effect
from analysis.errors import LinparError
from analysis.fit.bands import bands_hz, piston_band
from analysis.fit.error import FIT_ERROR_DEFAULTS, fit_error_percent
from analysis.fit.least_squares import FitCancelled, FitData, FitError, FitResult
from analysis.fit.startvalues import StartValueError, start_context
from analysis.fit.methods import DEFAULT_METHOD, fit_with
from analysis.model.composed import Model, ModelError
from analysis.model.lumped import resonance_frequency
from analysis.recording.format import IN_MEMORY, Recording, RecordingError, read_recording, recording_paths
from analysis.serial_laser import delay_start, from_serial_laser, recording_default_effects, with_delay_verdict
from analysis.spectra import Spectra, SpectrumError, estimate_spectra
from analysis.validity.plausibility import plausibility_findings
from analysis.validity.assessment import Validity, assess, capture_of
from analysis.validity.findings import DRIFT
from analysis.validity.fit import UnusableChannels, misfit_findings, unusable_channels
from analysis.validity.result import ResultValidity

if TYPE_CHECKING:   # loaded when used: a recording without a sidecar's "capture" or a drifting current needs neither
    from analysis.heating import CoilHeating
    from analysis.validity.capture import CaptureInfo


# Displacement lines below which Hx carries too little to fit Bl (and a delay) from.
MIN_X_LINES = 3


class NotAnalysable(LinparError):
    """A recording whose channels leave nothing to fit (message: which and why, with the remedy)."""


# eq=False: with its spectra's arrays, == raised for any two that were not the same object; so no __eq__ and
# __hash__ are generated at every start (Python 3.11 execs each dataclass method).
@dataclass(frozen=True, kw_only=True, eq=False)
class AnalysisResult:
    """A recording's analysis: its parameters, the fit they came from and its judged channels.

    `report()` is the text `linpar analyze` prints, `as_json()` the object `linpar analyze --json` prints.
    """

    spectra: Spectra
    fit: FitResult | None               # None: nothing could be fitted (not_fitted says why)
    parameters: dict[str, ParameterValue]
    sd_m2: float | None
    source: Path | None = None
    validity: ResultValidity = field(default_factory=ResultValidity)
    not_fitted: str | None = None
    # The model part of the uncertainties (analysis.fit.model_uncertainty.ModelPart): None until estimated.
    model_part: object | None = None
    # The lines fitted (the piston band when the model misses the whole band: analysis.fit.bands); None: every
    # usable line of the spectra.
    data: FitData | None = None
    # When the parameters come from the piston band: the same model fitted over every usable line, where it
    # fails (the Model lab starts from it, so that the physics the model lacks shows where it acts).
    whole_band_fit: FitResult | None = None

    @property
    def model(self) -> Model:
        return require_fit(self).model

    def report(self) -> str:
        """The parameter table, the fit's summary, the validity and the fit's report (analysis.result_text)."""
        from analysis.result_text import format_result
        return format_result(self)

    def as_json(self) -> dict:
        """The parameters, the model and the validity as JSON-ready values (result_json)."""
        return result_json(self)


def require_fit(result: AnalysisResult, doing: str = "") -> FitResult:
    """The result's fit; NotAnalysable (naming the file, what was being done and why) when it has none."""
    if result.fit is not None:
        return result.fit
    where = f"{result.source}: " if result.source is not None else ""
    raise NotAnalysable(f"{where}{'cannot ' + doing + ': ' if doing else ''}{result.not_fitted}")


def merged(*findings: dict) -> dict:
    """Findings by channel from several checks, in one mapping."""
    out: dict = {}
    for by_channel in findings:
        for channel, found in by_channel.items():
            out.setdefault(channel, []).extend(found)
    return out


def default_effects() -> tuple[Effect, ...]:
    return tuple(get_effect(i) for i in DEFAULT_EFFECTS)


def resolve_sd(recording: Recording, sd_m2: float | None) -> float | None:
    if sd_m2 is not None:
        return sd_m2
    sd = recording.driver.get("sd_m2") if recording.driver else None
    return float(sd) if sd else None


def analyze_recording(recording: Recording, sd_m2: float | None = None,
                      effects: Sequence[Effect] | None = None,
                      cancel: threading.Event | None = None, method: str = DEFAULT_METHOD) -> AnalysisResult:
    """The judged analysis of a recording; `effects` None: the default model, with `delay-x` for a serial
    laser's recording, whose delay is searched first (analysis/serial_laser.py)."""
    with naming_the_file(recording):
        spectra = estimate_spectra(recording)
    if effects is None:
        effects = recording_default_effects(recording)
    if not from_serial_laser(recording):
        return analyze_spectra(recording, spectra, sd_m2, effects, cancel, method=method)
    found: list = []        # the delay search's DelaySearch
    result = analyze_spectra(recording, spectra, sd_m2, effects, cancel, method=method,
                             start_of=functools.partial(delay_start, found=found))
    return with_delay_verdict(result, found[0]) if found else result


@contextmanager
def naming_the_file(recording: Recording) -> Iterator[None]:
    """An error of the analysis (no excited line, too few lines, no resonance, a fit that fails) names the
    recording's file: the user may have given many (stats, levels)."""
    try:
        yield
    except (SpectrumError, StartValueError, FitError, ModelError) as exc:
        if isinstance(exc, FitCancelled) or recording.source is None or str(recording.source) in str(exc):
            raise
        raise type(exc)(f"{recording.source}: {exc}") from None


StartOf = Callable[[FitData, Model, "threading.Event | None"], dict]


def analyze_spectra(recording: Recording, spectra: Spectra, sd_m2: float | None = None,
                    effects: Sequence[Effect] | None = None, cancel: threading.Event | None = None,
                    start_of: StartOf | None = None, method: str = DEFAULT_METHOD) -> AnalysisResult:
    """The judged analysis of a recording's spectra (module doc); `start_of(data, model, cancel)` may give
    start values for the fit; `method` names the identification (analysis.fit.methods)."""
    with naming_the_file(recording):
        return _analyzed(recording, spectra, sd_m2, effects, cancel, start_of, method)


def _analyzed(recording: Recording, spectra: Spectra, sd_m2: float | None, effects: Sequence[Effect] | None,
              cancel: threading.Event | None, start_of: StartOf | None, method: str) -> AnalysisResult:
    validity, unusable, spectra = _judged(recording, spectra)
    effects = tuple(default_effects() if effects is None else effects)
    sd = resolve_sd(recording, sd_m2)
    if unusable.impedance is not None:
        model = Model(effects, with_displacement=False)
        return AnalysisResult(spectra=spectra, fit=None, parameters=unmeasured_table(model, unusable.impedance),
                              sd_m2=sd, source=recording.source, validity=ResultValidity.checked(validity),
                              not_fitted=unusable.impedance)
    data = FitData.from_spectra(spectra)
    model = Model(effects, with_displacement=data.displacement is not None)
    start = start_of(data, model, cancel) if start_of is not None else None
    fit = fit_with(method, data, model, start=start, cancel=cancel)
    corrected, heating = without_coil_heating(recording, spectra, validity, fit.values["RE"])
    if corrected is not spectra:        # the noise estimate was the drift's: fit again on the honest one
        spectra = corrected
        data = FitData.from_spectra(spectra)
        fit = fit_with(method, data, model, start=fit.values, cancel=cancel)
    whole_band_fit, every_line = fit, data
    fit, data = in_the_piston_band(fit, data, method, cancel)
    parameters = parameter_table(fit, sd, unusable.displacement or NO_DISPLACEMENT)
    # Numbers no loudspeaker can have are judged like broken signals: red, with the likely cause.
    implausible = plausibility_findings(recording, spectra, parameters, sd, validity.peak_displacement_m)
    judged = ResultValidity.checked(validity.with_findings(merged(misfit_findings(fit), implausible)),
                                    fit_error_percent=fit_error_percent(fit),   # what QA judges the misfit by
                                    fit_band_hz=bands_hz(data),                 # ... over these bands
                                    heating=None if heating is None else heating.as_json())
    return AnalysisResult(spectra=spectra, fit=fit, parameters=parameters, sd_m2=sd, source=recording.source,
                          validity=judged, data=data, whole_band_fit=None if data is every_line else whole_band_fit)


def misses_the_band(fit: FitResult) -> bool:
    """True when the cone does not move as a piston over the whole band, as the laser sees it: the fit misses the
    displacement by more than the fit error a real driver measured well shows. The impedance alone does not
    decide: a current sense 5.2 us late misses Z by 5.6 % over every line (Hx by 8.8 %), and over the piston
    band its delay hides in LE (+38 %, Z's fit error 0.6 %): such a recording stays whole and not judged."""
    errors = fit_error_percent(fit)
    return "displacement" in errors and not errors["displacement"] <= FIT_ERROR_DEFAULTS["displacement"]


def in_the_piston_band(fit: FitResult, data: FitData, method: str, cancel: threading.Event | None
                       ) -> tuple[FitResult, FitData]:
    """The fit and its lines; when the cone does not move as a piston over the whole band (misses_the_band), the
    model fitted again over the band where a lumped piston holds (analysis.fit.bands), if it misses that less."""
    if not misses_the_band(fit):
        return fit, data
    values = dict(fit.values)
    band = piston_band(data, resonance_frequency(values))
    if band is None:
        return fit, data
    # From the whole band's values and from the model's own start: the first may hold a creep that imitated the
    # cone mode (the realistic subwoofer, seed 4: lambda 0.62 there, a chi^2 13 % above the cold start's 0.23).
    banded = min((fit_with(method, band, fit.model, start=start, cancel=cancel) for start in (values, None)),
                 key=lambda f: f.chi2 if math.isfinite(f.chi2) else math.inf)
    errors, before = fit_error_percent(banded), fit_error_percent(fit)
    if not all(errors.get(name, math.inf) <= before[name] for name in before):
        return fit, data
    return banded, band


def without_coil_heating(recording: Recording, spectra: Spectra, validity: Validity,
                         re_fit: float) -> tuple[Spectra, CoilHeating | None]:
    """The spectra with the voice coil's warming taken out of the noise estimate, and the heating found, when
    the validity check found the current drifting (analysis.heating); the spectra as they are otherwise."""
    if not any(f.code == DRIFT for f in validity.channels["current"].findings):
        return spectra, None
    from analysis.heating import coil_heating, without_heating
    heating = coil_heating(recording, spectra, re_fit)
    if heating is None or not heating.significant:
        return spectra, heating
    return without_heating(recording, spectra, heating), heating


def _judged(recording: Recording, spectra: Spectra) -> tuple[Validity, UnusableChannels, Spectra]:
    """The channels judged, what they leave to fit, and the spectra without an unusable displacement."""
    capture = checked_capture(recording)      # a sidecar that cannot be judged is refused at once
    validity = assess(recording, spectra, capture)
    unusable = unusable_channels(validity)
    x = spectra.displacement
    if unusable.displacement is None and x is not None and unusable.impedance is None:
        lines = int(np.sum(np.isfinite(x.value) & (x.freqs > 0)))
        if lines < MIN_X_LINES:     # e.g. a displacement_max_hz below the excitation: Bl from nothing
            unusable = dataclasses.replace(unusable, displacement=(
                f"the displacement cannot be used: {lines} of its lines lie in the laser's band (at least "
                f"{MIN_X_LINES} are needed for Bl); check the sidecar's displacement_max_hz and the laser's rate"))
    if unusable.displacement is not None and x is not None:
        spectra = dataclasses.replace(spectra, displacement=None)
    return validity, unusable, spectra


def judged_fit_data(recording: Recording, doing: str) -> tuple[FitData, ResultValidity]:
    """The lines a fit of the recording may use and its judged channels (module doc), the coil's
    heating taken out of the noise (and said in its `heating`) when the current drifts; NotAnalysable
    naming the file and `doing` when the impedance has none."""
    with naming_the_file(recording):
        validity, unusable, spectra = _judged(recording, estimate_spectra(recording))
    if unusable.impedance is not None:
        where = f"{recording.source}: " if recording.source is not None else ""
        raise NotAnalysable(f"{where}cannot {doing}: {unusable.impedance}")
    judged = ResultValidity.checked(validity)
    if any(f.code == DRIFT for f in validity.channels["current"].findings):
        # RE for the words only (the correction does not need it): the lowest real part of Z, as the fit starts
        spectra, heating = without_coil_heating(recording, spectra, validity, start_context(spectra.impedance).RE)
        if heating is not None:
            judged = judged.replace(heating=heating.as_json())
    return FitData.from_spectra(spectra), judged


def checked_capture(recording: Recording) -> CaptureInfo | None:
    """The sidecar's "capture" object, or RecordingError naming the sidecar and the key."""
    try:
        return capture_of(recording)
    except LinparError as exc:
        # capture_of loads analysis.validity.capture only when the sidecar has a capture to read
        from analysis.validity.capture import CaptureInfoError
        if not isinstance(exc, CaptureInfoError):
            raise
        where = recording_paths(recording.source)[1] if recording.source is not None else IN_MEMORY
        raise RecordingError(f"{where}: {exc}") from None


def analyze_path(path: str | Path, sd_m2: float | None = None,
                 effects: Sequence[Effect] | None = None, method: str = DEFAULT_METHOD) -> AnalysisResult:
    return analyze_recording(read_recording(path), sd_m2, effects, method=method)


def result_json(result: AnalysisResult) -> dict:
    """The object `linpar analyze --json` prints, the uncertainties with their model part (refitted here when
    the caller has not: analysis.fit.model_uncertainty)."""
    from analysis.fit.model_uncertainty import model_uncertainty
    result = model_uncertainty(result)
    return {
        "parameters": {name: p.as_json() for name, p in result.parameters.items()},
        "model": model_json(result.fit) if result.fit is not None else
        {"effects": [], "converged": False, "not_fitted": result.not_fitted},
        "validity": result.validity.as_json(),
    }


def model_json(fit: FitResult) -> dict:
    from analysis.fit.added_effects import stuck_effect_notes
    return {
        "effects": list(fit.model.effect_ids),
        "method": fit.method,
        "chi2_red": fit.chi2_red_by_channel(),
        "aic": fit.aic,
        "bic": fit.bic,
        "n_data": fit.n_data,
        "n_parameters": fit.n_varying,
        "converged": fit.success,
        # An added effect held on its bound far from the data: it may fit worse than none (one line each).
        "notes": stuck_effect_notes(fit),
    }
