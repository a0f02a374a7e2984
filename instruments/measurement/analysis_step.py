"""The analysis of a measured recording: analysis.pipeline.analyze_recording, minus Hx lines not measured.

A serial laser samples at 0.25 - 4 kHz; its displacement, resampled onto the
audio grid, carries nothing above ``displacement_max_hz`` (a top-level key of
the sidecar, set by the runner). The excitation's lines above it are still
needed for Z, but Hx there would be 0 with no noise: a fit that weighs those
lines by their (vanishing) noise is pulled to Hx = 0 where the driver's Hx
is not. So Hx keeps only the lines at or below ``displacement_max_hz``.

With `delay-x` in the model, its tau_x starts from the delay the data place
(``delay_start``, analysis/laser_delay.py) rather than from 0.

This is the workaround until the analysis core reads the key itself (the
change is one restriction in analysis.spectra.estimate_spectra; see
docs in the measurement report): until then, `linpar analyze` of such a
recording weighs the empty lines, and `linpar measure` analyses through here.
"""
from __future__ import annotations

import dataclasses
import functools
import threading
from typing import Sequence

import numpy as np

from analysis.effects import Effect, Site
from analysis.fit.least_squares import FitData, fit_model, start_values
from analysis.model.composed import Model
from analysis.laser_delay import SEARCH_S, DelaySearch, find_delay
from analysis.pipeline import AnalysisResult, analyze_recording, analyze_spectra, naming_the_file
from analysis.recording.format import Recording
from analysis.spectra import Spectra, estimate_spectra
from analysis.validity.assessment import ABSENT
from analysis.validity.findings import LASER_DELAY_NOT_FOUND, Finding, Severity

DISPLACEMENT_MAX_KEY = "displacement_max_hz"


def displacement_max_hz(recording: Recording) -> float | None:
    value = recording.extra.get(DISPLACEMENT_MAX_KEY) if recording.extra else None
    return None if value is None else float(value)


def measured_lines_only(spectra: Spectra, max_hz: float | None) -> Spectra:
    """The spectra with Hx restricted to the lines at or below ``max_hz`` (None: unchanged)."""
    x = spectra.displacement
    if max_hz is None or x is None:
        return spectra
    return dataclasses.replace(spectra, displacement=x.restricted(x.freqs <= max_hz))


def delay_start(data: FitData, model: Model, cancel: threading.Event | None = None,
                found: list[DelaySearch] | None = None) -> dict[str, float]:
    """A start for tau_x (delay-x) from the data, {} when the model has no tau_x.

    The host times leave the laser's link latency in the alignment (a USB
    adapter's packets: 1 - 16 ms late, with jitter), and from 0 the fit
    finds a delay only up to ~0.3 ms. Everything in Hx but Bl and the delay
    is known once Z is fitted, so Hx_measured / Hx_model(Bl = 1) =
    exp(-s tau) / Bl, whose delay analysis.laser_delay finds over -10 ...
    +40 ms (coarse grid, then refined). What it found is appended to
    ``found`` (whether the data place it, for the verdict).
    """
    x = data.displacement
    if x is None or "tau_x" not in {p.name for p in model.param_specs} or x.freqs.size < 3:
        return {}
    electrical = tuple(e for e in model.effects if e.site is not Site.DISPLACEMENT)
    z_only = fit_model(FitData(data.impedance), Model(electrical, with_displacement=False), cancel=cancel)
    values = {**start_values(model, data), **z_only.values, "Bl": 1.0, "tau_x": 0.0}
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = x.value / model.displacement(2j * np.pi * x.freqs, values)
        weight = np.abs(x.value / x.std) ** 2
    search = find_delay(x.freqs, ratio, weight)
    if found is not None:
        found.append(search)
    return {"tau_x": search.delay_s}


def analyse_measurement(recording: Recording, sd_m2: float | None = None, effects: Sequence[Effect] | None = None,
                        cancel: threading.Event | None = None) -> AnalysisResult:
    """What analyze_recording returns, with Hx only where the laser measured (module doc); a serial laser's
    delay searched over the whole range, and red when the data cannot place it (``laser_delay`` in the
    validity says what the search found)."""
    max_hz = displacement_max_hz(recording)
    if max_hz is None:
        return analyze_recording(recording, sd_m2, effects, cancel)
    with naming_the_file(recording):
        spectra = measured_lines_only(estimate_spectra(recording), max_hz)
    found: list[DelaySearch] = []
    result = analyze_spectra(recording, spectra, sd_m2, effects, cancel,
                             start_of=functools.partial(delay_start, found=found))
    return with_delay_verdict(result, found[0]) if found else result


def with_delay_verdict(result: AnalysisResult, search: DelaySearch) -> AnalysisResult:
    """The result with the delay search in its validity, and a red displacement when the data cannot place it."""
    validity = result.validity.replace(laser_delay=search.as_json())
    channel = validity.channels.get("displacement")
    if not search.placed and channel is not None and channel.status != ABSENT:
        lost = Finding(
            "displacement", LASER_DELAY_NOT_FOUND, Severity.RED,
            f"the laser's delay cannot be placed from the data (searched {SEARCH_S[0] * 1e3:g} to "
            f"{SEARCH_S[1] * 1e3:g} ms: best {search.delay_s * 1e3:.3f} ms, the lines agree {search.score:.2f}, "
            f"the next peak only {search.chi2_margin:.3g} chi^2 worse)",
            "Bl, Mms and Kms are not to be trusted; check the laser's link (a USB adapter's latency) and that "
            "the displacement stands well above its noise, then measure again", search.chi2_margin)
        channels = {**validity.channels, "displacement": dataclasses.replace(
            channel, status=str(Severity.RED), findings=channel.findings + (lost,))}
        validity = validity.replace(channels=channels, overall=Severity.RED)
    return dataclasses.replace(result, validity=validity)
