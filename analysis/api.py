"""The library's front door: a recording read, analysed, diagnosed, or made, each in one call.

    import analysis
    rec = analysis.synthesize(driver="paper", noise=analysis.TYPICAL_NOISE)
    result = analysis.analyze(rec)              # or a path: analysis.analyze("woofer.wav")
    print(result.report())                      # what `linpar analyze` prints; result.as_json() its --json
    found = analysis.diagnose(rec)              # found.report(), found.as_json(): what `linpar diagnose` prints

These are the paths the CLI takes, so a notebook gets the numbers, the words and the JSON the command line
gives. docs/library.md walks through them. Options are keyword-only: a call reads the way it works.
"""
from __future__ import annotations

import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Mapping, Sequence, Union

if TYPE_CHECKING:
    from analysis.curves.fitting import CurveAnalysis
    from analysis.curves.imported import ImportedCurves
    from analysis.diagnosis.result import DiagnosisResult
    from analysis.effects import Effect
    from analysis.pipeline import AnalysisResult
    from analysis.recording.format import Recording
    from analysis.synthesis import ChannelNoise

    Source = Union[str, Path, Recording, ImportedCurves]

# The simulator (analysis.synthesis, where TYPICAL_NOISE is) is loaded by synthesize only: an analysis does not
# pay for its dataclass at start-up.
__all__ = ["analyze", "diagnose", "synthesize"]


def _effects(effects: str | Sequence[str | Effect] | None) -> tuple[Effect, ...]:
    """Effects given as ids ('lr2,creep-log', 'none', or a sequence of ids, as Model.effect_ids) or as Effect
    objects; None: the default model. An unknown id raises UnknownEffectError, naming the known ones."""
    from analysis.effects import get_effect, parse_effects
    if effects is None or isinstance(effects, str):
        return tuple(parse_effects(effects))
    return tuple(get_effect(e) if isinstance(e, str) else e for e in effects)


def _recording(source) -> Recording:
    from analysis.recording.format import Recording, read_recording
    return source if isinstance(source, Recording) else read_recording(source)


def _is_curves(source) -> bool:
    # Imported curves exist only once their module is loaded: a recording's analysis does not load the curves'
    # fitting (scipy.ndimage) to find that out.
    imported = sys.modules.get("analysis.curves.imported")
    return imported is not None and isinstance(source, imported.ImportedCurves)


def analyze(source: Source, *, sd_m2: float | None = None, effects: str | Sequence[str | Effect] | None = None,
            method: str | None = None, model_part: bool = True,
            cancel: threading.Event | None = None) -> AnalysisResult | CurveAnalysis:
    """The parameters of a recording (a path, or a Recording) or of imported curves (import_curves).

    sd_m2: the radiating area (default: the recording's sidecar's); effects: the model's effects (default
    lr2,creep-log; magnitude-only curves their own); method: 'joint' (Z and Hx together, the default) or 'paper'
    (Z first, then Hx). model_part: estimate the part of each uncertainty the model's form leaves open (refits
    with the other forms of the inductance and the creep, and for a recording with effects a real driver has
    added, when the model misses the data by more than the noise), as `linpar analyze` does.
    """
    from analysis.fit.model_uncertainty import model_uncertainty
    chosen = None if effects is None else _effects(effects)
    if _is_curves(source):         # effects, method None: fit_curves chooses (magnitude-only curves have their own)
        from analysis.curves.fitting import fit_curves
        result = fit_curves(source.impedance, source.displacement, chosen, sd_m2, source.fit_range,
                            source.notes, method=method)
    else:
        from analysis.pipeline import analyze_recording
        result = analyze_recording(_recording(source), sd_m2, chosen, cancel=cancel, method=method or "joint")
    return model_uncertainty(result, cancel=cancel) if model_part else result


def diagnose(source: Source, *, start: str | Sequence[str | Effect] = "none", sd_m2: float | None = None,
             parallel: bool = True, cancel: threading.Event | None = None,
             progress: Callable[[str], None] | None = None) -> DiagnosisResult:
    """Which physical effects the model `start` (default: the textbook model) lacks, and where the misfit is.

    The recording's channels are judged first (a broken impedance raises NotAnalysable, with why); its drift
    finding and Sd go with the diagnosis, for its words and its derived parameters. parallel: refit the
    candidates on a process pool.
    """
    from analysis.diagnosis.candidates import diagnose as run
    from analysis.diagnosis.result import DiagnosisResult
    from analysis.model.composed import Model
    from analysis.parallel import fit_executor
    model_effects = _effects(start)
    if _is_curves(source):
        from analysis.curves.fitting import curve_data
        data, _ = curve_data(source.impedance, source.displacement, source.fit_range, source.notes)
        sd, drift = sd_m2, None
    else:
        from analysis.diagnosis.words import drift_from_validity
        from analysis.pipeline import judged_fit_data, resolve_sd
        recording = _recording(source)
        data, validity = judged_fit_data(recording, "be diagnosed")
        sd, drift = resolve_sd(recording, sd_m2), drift_from_validity(validity)
    model = Model(model_effects, with_displacement=data.displacement is not None)
    with fit_executor(None if parallel else 1) as executor:
        found = run(data, model, executor=executor, cancel=cancel, progress=progress)
    return DiagnosisResult(diagnosis=found, sd_m2=sd, drift=drift)


def synthesize(*, driver: str | Path = "paper", values: Mapping[str, float] | None = None,
               effects: str | None = None, noise: ChannelNoise | None = None, level_v_rms: float = 1.0,
               sample_rate: int = 48000, period_samples: int = 16384, n_periods: int = 8, settle_periods: int = 1,
               f_min: float = 5.0, f_max: float = 10000.0, displacement: bool = True, sd_m2: float | None = None,
               seed: int | None = 0) -> Recording:
    """A recording of a driver measured with a multitone, made by the linear simulator (analysis.synthesis).

    driver: a built-in driver's name or a driver file (analysis.drivers), whose effects, values and Sd are
    used unless `effects`, `values` (each overriding the driver's value of that name) or `sd_m2` are given.
    noise: white noise per channel (None: none; analysis.TYPICAL_NOISE is a realistic measurement's); a
    multitone of `level_v_rms` from f_min to f_max, `n_periods` periods of `period_samples` after `settle_periods`.
    """
    from analysis.drivers import load_driver
    from analysis.effects import parse_effects
    from analysis.model.composed import Model, ModelError
    from analysis.multitone import design_multitone
    from analysis.synthesis import ChannelNoise, synthesize_recording
    chosen = load_driver(driver)
    if effects is None:
        effects = ",".join(chosen.effects) or "none"
    model = Model(parse_effects(effects), with_displacement=displacement)
    merged = {**chosen.parameters, **(values or {})}
    missing = [spec.name for spec in model.param_specs if spec.name not in merged]
    if missing:
        raise ModelError(f"values: the model {model.describe()} needs {', '.join(missing)}, which neither the "
                         f"driver {chosen.name!r} nor `values` gives")
    multitone = design_multitone(sample_rate, period_samples, f_min, f_max, rms=level_v_rms)
    area = chosen.sd_m2 if sd_m2 is None else sd_m2
    return synthesize_recording(model, merged, multitone.waveform,
                                multitone.excited_bins, sample_rate, n_periods, settle_periods,
                                ChannelNoise() if noise is None else noise, seed=seed,
                                driver={"name": chosen.name, **({"sd_m2": area} if area else {})})
