"""The fit error: how far the model misses each measured curve, in % (what Klippel's LPM sheets print).

Per channel, over the lines the fit used (its fitted band): the rms of the
misfit relative to the measured value, sqrt(mean(|model - measured|^2 /
|measured|^2)), complex where the phase was measured, on the magnitude where
it was not. Unlike the reduced chi^2 it does not grow with the number of
periods averaged: a real driver measured well shows 1.5-3 % on the impedance,
however clean the recording. QA judges whether the model describes the
measurement by it (analysis.qa_verdict), and the reduced chi^2 stays in the
Model lab and the fit report.
"""
from __future__ import annotations

import numpy as np

# The fit error in % up to which QA takes the model to describe the measurement (a limits file may set its own,
# "fit_error_percent"). The impedance: LPM sheets of real drivers measured well print 1.5-3 %, and the default
# model misses the real SEAS L16RNX by 3.9 % up to 10 kHz; 5 % leaves room for a coil whose inductance no lumped
# law follows to the top of the band, while a fault of consequence misses by more (a current sense 5.2 us late:
# 5.6 % on Z, 8.8 % on Hx; a semi-inductance of 4.6 ohm at 1 kHz fitted with LR-2: 14 %). Hx: the laser sees one
# spot of a cone that stops moving as a piston (its modes) near the top of the band, so the same model misses
# Hx by more; 10 %.
FIT_ERROR_DEFAULTS = {"impedance": 5.0, "displacement": 10.0}


def rms_relative_residual(fit) -> dict[str, float]:
    """channel -> rms relative misfit (a fraction) of an analysis.fit.FitResult; NaN for a channel with no line."""
    out = {}
    for name, ch in fit.channels.items():
        model = ch.model if ch.has_phase else np.abs(ch.model)
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.abs(model - ch.measured) ** 2 / np.abs(ch.measured) ** 2
        rel = rel[np.isfinite(rel)]
        out[name] = float(np.sqrt(np.mean(rel))) if rel.size else float("nan")
    return out


def fit_error_percent(fit) -> dict[str, float]:
    """channel -> fit error in %, finite channels only (JSON has no NaN)."""
    return {name: 100.0 * v for name, v in rms_relative_residual(fit).items() if np.isfinite(v)}
