"""How well a fit explains the measurement, in words a technician reads without the statistics.

One clause per channel:
- reduced chi^2 up to NOISE_LEVEL: "explains the impedance down to its noise";
- a band of misfit (analysis.diagnosis.residuals) holding at least BAND_SHARE of the channel's misfit: "misses 12 % of
  the impedance between 200 and 800 Hz", the percentage being the largest relative deviation
  |measured - model| / |model| in the band;
- otherwise: "explains the impedance to within 2.3 times its noise" (misfit spread over the range).
The numbers (reduced chi^2, AIC, BIC, counts) go to the details, never to the headline.
"""
from __future__ import annotations

import math

import numpy as np

from analysis.diagnosis.residuals import channel_finding
from analysis.fit.least_squares import ChannelFit, FitResult

# A reduced chi^2 this close to 1 is noise: the model has nothing left to explain.
NOISE_LEVEL = 1.5
# A band holding less of the channel's misfit than this is a peak of a misfit spread everywhere, not the place
# the model misses.
BAND_SHARE = 0.25
CHANNEL_NAMES = {"impedance": "impedance", "displacement": "displacement"}


def _hz(f: float) -> str:
    return f"{f / 1000:.3g} kHz" if f >= 1000 else f"{f:.3g} Hz"


def _band_deviation_percent(ch: ChannelFit, f_low: float, f_high: float) -> float:
    band = (ch.freqs >= f_low) & (ch.freqs <= f_high)
    model = ch.model[band]
    measured = ch.measured[band]
    with np.errstate(divide="ignore", invalid="ignore"):
        deviation = (np.abs(measured - np.abs(model)) if not ch.has_phase else np.abs(measured - model)) \
            / np.abs(model)
    deviation = deviation[np.isfinite(deviation)]
    return 100.0 * float(deviation.max()) if deviation.size else math.nan


def channel_clause(ch: ChannelFit) -> str:
    what = CHANNEL_NAMES.get(ch.name, ch.name)
    if not math.isfinite(ch.chi2_red):
        return f"cannot say how well it explains the {what} (no usable lines)"
    if ch.chi2_red <= NOISE_LEVEL:
        return f"explains the {what} down to its noise"
    finding = channel_finding(ch)
    if finding is not None and finding.share >= BAND_SHARE:
        percent = _band_deviation_percent(ch, finding.f_low, finding.f_high)
        if math.isfinite(percent):
            amount = f"{percent:.2g} %" if percent >= 0.1 else "less than 0.1 %"
            return f"misses {amount} of the {what} between {_hz(finding.f_low)} and {_hz(finding.f_high)}"
    return f"explains the {what} to within {math.sqrt(ch.chi2_red):.2g} times its noise"


def fit_headline(fit: FitResult) -> str:
    """'The model explains the impedance down to its noise and misses 3 % of the displacement between …'."""
    if not fit.channels:
        return "The model was fitted to no data."
    if len(fit.channels) > 1 and fit_is_at_noise(fit):
        what = " and the ".join(CHANNEL_NAMES.get(name, name) for name in fit.channels)
        return f"The model explains the {what} down to their noise."
    clauses = [channel_clause(ch) for ch in fit.channels.values()]
    text = "The model " + (clauses[0] if len(clauses) == 1 else ", ".join(clauses[:-1]) + " and " + clauses[-1])
    return text + "."


def fit_is_at_noise(fit: FitResult) -> bool:
    return all(ch.chi2_red <= NOISE_LEVEL for ch in fit.channels.values())
