"""The fit error: how far the model misses each measured curve, in % (what Klippel's LPM sheets print).

Per channel, over the lines the fit used (its fitted band): the rms of the
misfit relative to the measured value, sqrt(mean(|model - measured|^2 /
|measured|^2)), complex where the phase was measured, on the magnitude where
it was not. Unlike the reduced chi^2 it does not grow with the number of
periods averaged: a real driver measured well shows 1.5-3 % on the impedance,
however clean the recording. What the noise leaves on a line is not the model's misfit: where the
noise is known (a recording's, an imported curve's estimate) each line's expected noise share is taken
out of the mean square, and lines standing less than MIN_SNR times their noise above it (a laser at its
noise floor far above fs) are left out. QA judges whether the model describes the
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
# A line within this many standard deviations of its noise floor says nothing of the model's misfit.
MIN_SNR = 3.0


def rms_relative_residual(fit) -> dict[str, float]:
    """channel -> rms relative misfit (a fraction) of an analysis.fit.FitResult, the noise's share out (module
    doc); NaN for a channel with no line."""
    out = {}
    for name, ch in fit.channels.items():
        model = ch.model if ch.has_phase else np.abs(ch.model)
        size = np.abs(ch.measured)
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.abs(model - ch.measured) ** 2 / size ** 2
            if fit.noise_known:
                # E|residual|^2 of noise alone: the complex variance, or one component's on a magnitude.
                noise = ch.std ** 2 / (1.0 if ch.has_phase else 2.0) / size ** 2
                keep = size >= MIN_SNR * ch.std
            else:
                noise, keep = np.zeros_like(rel), np.ones(rel.shape, dtype=bool)
        keep &= np.isfinite(rel) & np.isfinite(noise)
        out[name] = float(np.sqrt(max(np.mean(rel[keep] - noise[keep]), 0.0))) if keep.any() else float("nan")
    return out


def fit_error_percent(fit) -> dict[str, float]:
    """channel -> fit error in %, finite channels only (JSON has no NaN)."""
    return {name: 100.0 * v for name, v in rms_relative_residual(fit).items() if np.isfinite(v)}
