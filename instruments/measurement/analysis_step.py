"""The analysis of a measured recording: analysis.pipeline.analyze_recording, minus Hx lines not measured.

A serial laser samples at 0.25 - 4 kHz; its displacement, resampled onto the
audio grid, carries nothing above ``displacement_max_hz`` (a top-level key of
the sidecar, set by the runner). The excitation's lines above it are still
needed for Z, but Hx there would be 0 with no noise: a fit that weighs those
lines by their (vanishing) noise is pulled to Hx = 0 where the driver's Hx
is not. So Hx keeps only the lines at or below ``displacement_max_hz``.

With `delay-x` in the model, its tau_x starts from the phase of Hx
(``delay_start``) rather than from 0.

This is the workaround until the analysis core reads the key itself (the
change is one restriction in analysis.spectra.estimate_spectra; see
docs in the measurement report): until then, `linpar analyze` of such a
recording weighs the empty lines, and `linpar measure` analyses through here.
"""
from __future__ import annotations

import dataclasses
import threading
from typing import Sequence

import numpy as np

from analysis.effects import Effect, Site
from analysis.fit.least_squares import FitData, fit_model, start_values
from analysis.model.composed import Model
from analysis.pipeline import AnalysisResult, analyze_recording, analyze_spectra, naming_the_file
from analysis.recording.format import Recording
from analysis.spectra import Spectra, estimate_spectra

DISPLACEMENT_MAX_KEY = "displacement_max_hz"
COARSE_HZ = 200.0


def displacement_max_hz(recording: Recording) -> float | None:
    value = recording.extra.get(DISPLACEMENT_MAX_KEY) if recording.extra else None
    return None if value is None else float(value)


def measured_lines_only(spectra: Spectra, max_hz: float | None) -> Spectra:
    """The spectra with Hx restricted to the lines at or below ``max_hz`` (None: unchanged)."""
    x = spectra.displacement
    if max_hz is None or x is None:
        return spectra
    return dataclasses.replace(spectra, displacement=x.restricted(x.freqs <= max_hz))


def delay_start(data: FitData, model: Model, cancel: threading.Event | None = None) -> dict[str, float]:
    """A start for tau_x (delay-x) from the data, {} when the model has no tau_x.

    The host times leave the laser's link latency in the alignment (a USB
    adapter's latency timer: 1 - 16 ms), and from 0 the fit finds a delay only
    up to ~0.3 ms. Everything in Hx but Bl and the delay is known once Z is
    fitted, so Hx_measured / Hx_model(Bl = 1) = exp(-s tau) / Bl: its phase is
    -w tau. The slope is taken on the lines below COARSE_HZ first (dense
    enough to unwrap a delay of a few ms), then on all lines with that part
    removed.
    """
    x = data.displacement
    if x is None or "tau_x" not in {p.name for p in model.param_specs} or x.freqs.size < 3:
        return {}
    electrical = tuple(e for e in model.effects if e.site is not Site.DISPLACEMENT)
    z_only = fit_model(FitData(data.impedance), Model(electrical, with_displacement=False), cancel=cancel)
    values = {**start_values(model, data), **z_only.values, "Bl": 1.0, "tau_x": 0.0}
    ratio = x.value / model.displacement(2j * np.pi * x.freqs, values)
    weight = np.abs(x.value / x.std) ** 2
    tau = 0.0
    for band in (x.freqs <= COARSE_HZ, np.ones(x.freqs.size, dtype=bool)):
        if band.sum() < 3:
            continue
        w, f = 2 * np.pi * x.freqs[band], weight[band]
        phase = np.unwrap(np.angle(ratio[band] * np.exp(1j * w * tau)))
        phase -= 2 * np.pi * np.round(phase[0] / (2 * np.pi))      # the lowest line is near 0, not 2 pi k
        tau -= float(np.sum(f * w * phase) / np.sum(f * w * w))
    return {"tau_x": tau}


def analyse_measurement(recording: Recording, sd_m2: float | None = None, effects: Sequence[Effect] | None = None,
                        cancel: threading.Event | None = None) -> AnalysisResult:
    """What analyze_recording returns, with Hx only where the laser measured (module doc)."""
    max_hz = displacement_max_hz(recording)
    if max_hz is None:
        return analyze_recording(recording, sd_m2, effects, cancel)
    with naming_the_file(recording):
        spectra = measured_lines_only(estimate_spectra(recording), max_hz)
    return analyze_spectra(recording, spectra, sd_m2, effects, cancel, start_of=delay_start)
