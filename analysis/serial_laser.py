"""What a recording whose displacement came from a serial laser needs, wherever it is analysed.

A serial laser samples at 0.25 - 4 kHz: its displacement carries nothing above
``displacement_max_hz`` (a top-level key of the sidecar, written when the
measurement aligned the laser's stream), and analysis.spectra keeps Hx only
up to there. The alignment by host times leaves the laser's link latency in
the data (a USB adapter's packets: 1 - 16 ms late, with jitter). So the
default model of such a recording has `delay-x`, whose tau_x starts from the
delay the data place (``delay_start``, analysis/laser_delay.py): from 0 the
fit finds a delay only up to ~0.3 ms. When the data cannot place it, the
displacement is red (``with_delay_verdict``).

analysis.pipeline.analyze_recording applies both, so that `linpar measure`,
`linpar analyze`, a report, the statistics and the window give one recording
the same numbers. Only `measure` did: analysed again later, a recording with
8 ms of link latency had Bl 2.4 times too large and a remedy that blamed the
laser's sign.
"""
from __future__ import annotations

import dataclasses
import threading
from typing import TYPE_CHECKING, TypeVar

import numpy as np

from analysis.effects import DEFAULT_EFFECTS, Effect, Site, get_effect
from analysis.fit.least_squares import FitData, fit_model, start_values
from analysis.model.composed import Model
from analysis.recording.format import Recording
from analysis.validity.assessment import ABSENT
from analysis.validity.findings import LASER_DELAY_NOT_FOUND, Finding, Severity

if TYPE_CHECKING:
    from analysis.laser_delay import DelaySearch

Result = TypeVar("Result")          # analysis.pipeline.AnalysisResult, which imports this module

DISPLACEMENT_MAX_KEY = "displacement_max_hz"
SERIAL_LASER = "serial laser"       # the sidecar's measurement.displacement_source of such a recording


def from_serial_laser(recording: Recording) -> bool:
    """The displacement came from a serial laser, placed on the audio's time line by host times."""
    measurement = recording.extra.get("measurement") if recording.extra else None
    source = measurement.get("displacement_source") if isinstance(measurement, dict) else None
    return source == SERIAL_LASER or (recording.extra is not None and DISPLACEMENT_MAX_KEY in recording.extra)


def recording_default_effects(recording: Recording) -> tuple[Effect, ...]:
    """The analysis' default model, plus `delay-x` for a serial laser's recording: the delay its alignment
    leaves, from tens of microseconds (the clocks) to milliseconds (a USB link), would otherwise be spread
    over the driver's parameters (Hx is known to ~1e-5, and 30 us is 0.2 degrees at 20 Hz, 11 at 1 kHz)."""
    ids = DEFAULT_EFFECTS + (("delay-x",) if from_serial_laser(recording) else ())
    return tuple(get_effect(i) for i in ids)


def delay_start(data: FitData, model: Model, cancel: threading.Event | None = None,
                found: list[DelaySearch] | None = None) -> dict[str, float]:
    """A start for tau_x (delay-x) from the data, {} when the model has no tau_x.

    Everything in Hx but Bl and the delay is known once Z is fitted, so
    Hx_measured / Hx_model(Bl = 1) = exp(-s tau) / Bl, whose delay
    analysis.laser_delay finds over SEARCH_S (coarse grid, then refined).
    What it found is appended to ``found`` (whether the data place it, for
    the verdict).
    """
    from analysis.laser_delay import find_delay     # scipy.optimize: only where a delay is searched

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


def with_delay_verdict(result: Result, search: DelaySearch) -> Result:
    """The result with the delay search in its validity, and a red displacement when the data cannot place it."""
    from analysis.laser_delay import SEARCH_S
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
