"""The fit error: how far the model misses each measured curve, in % (what Klippel's LPM sheets print).

Per channel, over the lines the fit used (its fitted band): the rms of the
misfit relative to the measured value, sqrt(mean(|model - measured|^2 /
|measured|^2)), complex where the phase was measured, on the magnitude where
it was not. Unlike the reduced chi^2 it does not grow with the number of
periods averaged: a real driver measured well shows 1.5-3 % on the impedance,
however clean the recording. A line at its noise floor says nothing of the model's misfit: where the
noise is known (a recording's, an imported curve's estimate) lines standing less than MIN_SNR times their
noise above it (a laser at its noise floor far above fs) are left out. QA judges whether the model describes the
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
    """channel -> rms relative misfit (a fraction) of an analysis.fit.FitResult over its lines above the noise
    floor (module doc); NaN for a channel with no such line."""
    out = {}
    for name, ch in fit.channels.items():
        model = ch.model if ch.has_phase else np.abs(ch.model)
        size = np.abs(ch.measured)
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.abs(model - ch.measured) ** 2 / size ** 2
            keep = size >= MIN_SNR * ch.std if fit.noise_known else np.ones(rel.shape, dtype=bool)
        keep &= np.isfinite(rel)
        out[name] = float(np.sqrt(np.mean(rel[keep]))) if keep.any() else float("nan")
    return out


def fit_error_percent(fit) -> dict[str, float]:
    """channel -> fit error in %, finite channels only (JSON has no NaN)."""
    return {name: 100.0 * v for name, v in rms_relative_residual(fit).items() if np.isfinite(v)}


def band_text(validity, channel: str) -> str:
    """" (14.6-915 Hz)": the band a channel's fit error was measured over, from a result's validity
    (analysis.validity.result.ResultValidity; None: no band), or ""."""
    band = ((validity.fit_band_hz if validity is not None else None) or {}).get(channel)
    return f" ({hz_text(band[0])}-{hz_text(band[1])} Hz)" if band else ""


def hz_text(f: float) -> str:
    """A frequency in Hz without its unit: "14.6", "915", "20000" (never "2e+04")."""
    return f"{f:.3g}" if f < 1000 else f"{f:.0f}"


def fit_error_text(validity) -> str:
    """"impedance 2.8 % (14.6-915 Hz), displacement 1.8 % (14.6-138 Hz)": each curve's fit error and its band."""
    errors = (validity.fit_error_percent if validity is not None else None) or {}
    return ", ".join(f"{name} {value:.2g} %{band_text(validity, name)}" for name, value in errors.items())
