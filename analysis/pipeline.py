"""From a recording to the full parameter table: spectra, fit, derived parameters."""
from __future__ import annotations

import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

from analysis.derived import ParameterValue, parameter_table
from analysis.effects import Effect, DEFAULT_EFFECTS, get_effect
from analysis.fit import FitData, FitResult, fit_model
from analysis.model import Model
from analysis.recording import IN_MEMORY, Recording, RecordingError, read_recording, recording_paths
from analysis.spectra import Spectra, estimate_spectra
from analysis.validity import CaptureInfo, CaptureInfoError, assess, capture_of


@dataclass(frozen=True)
class AnalysisResult:
    spectra: Spectra
    fit: FitResult
    parameters: dict[str, ParameterValue]
    sd_m2: float | None
    source: Path | None = None
    validity: dict = field(default_factory=lambda: {"overall": "unknown"})

    @property
    def model(self) -> Model:
        return self.fit.model


def default_effects() -> tuple[Effect, ...]:
    return tuple(get_effect(i) for i in DEFAULT_EFFECTS)


def resolve_sd(recording: Recording, sd_m2: float | None) -> float | None:
    if sd_m2 is not None:
        return sd_m2
    sd = recording.driver.get("sd_m2") if recording.driver else None
    return float(sd) if sd else None


def analyze_recording(recording: Recording, sd_m2: float | None = None,
                      effects: Sequence[Effect] | None = None,
                      cancel: threading.Event | None = None) -> AnalysisResult:
    capture = checked_capture(recording)      # before the fit: a sidecar that cannot be judged is refused at once
    spectra = estimate_spectra(recording)
    data = FitData.from_spectra(spectra)
    model = Model(tuple(default_effects() if effects is None else effects),
                  with_displacement=data.displacement is not None)
    fit = fit_model(data, model, cancel=cancel)
    sd = resolve_sd(recording, sd_m2)
    validity = assess(recording, spectra, capture).as_json()      # per channel, with the peak excursion
    return AnalysisResult(spectra, fit, parameter_table(fit, sd), sd, recording.source, validity)


def checked_capture(recording: Recording) -> CaptureInfo | None:
    """The sidecar's "capture" object, or RecordingError naming the sidecar and the key."""
    try:
        return capture_of(recording)
    except CaptureInfoError as exc:
        where = recording_paths(recording.source)[1] if recording.source is not None else IN_MEMORY
        raise RecordingError(f"{where}: {exc}") from None


def analyze_path(path: str | Path, sd_m2: float | None = None,
                 effects: Sequence[Effect] | None = None) -> AnalysisResult:
    return analyze_recording(read_recording(path), sd_m2, effects)


def result_json(result: AnalysisResult) -> dict:
    """The object `linpar analyze --json` prints."""
    return {
        "parameters": {name: p.as_json() for name, p in result.parameters.items()},
        "model": model_json(result.fit),
        "validity": result.validity,
    }


def model_json(fit: FitResult) -> dict:
    return {
        "effects": list(fit.model.effect_ids),
        "chi2_red": fit.chi2_red_by_channel(),
        "aic": fit.aic,
        "bic": fit.bic,
        "n_data": fit.n_data,
        "n_parameters": fit.n_varying,
        "converged": fit.success,
    }
