"""Predicted sound pressure from the displacement transfer function (docs/physics.md section 4).

Far field of a piston in half space (2 pi sr) at distance r:

    P(s) = s^2 * Hx(s) * U * Sd * rho / (2 pi r)

U is the RMS drive voltage, so P is an RMS pressure; SPL = 20 log10(|P| / 20 uPa).
Valid while the diaphragm moves as a piston and is small against the wavelength.
"""
from __future__ import annotations

import numpy as np

from analysis.derived import P_REF, RHO


def predicted_spl(freqs: np.ndarray, hx: np.ndarray, sd_m2: float, voltage_rms: float = 2.83,
                  distance_m: float = 1.0) -> np.ndarray:
    """SPL in dB re 20 uPa at `freqs` for Hx in m/V."""
    if sd_m2 <= 0 or distance_m <= 0 or voltage_rms <= 0:
        raise ValueError("Sd, the distance and the voltage must be positive")
    s = 2j * np.pi * np.asarray(freqs)
    pressure = s**2 * np.asarray(hx) * voltage_rms * sd_m2 * RHO / (2 * np.pi * distance_m)
    with np.errstate(divide="ignore"):
        return 20 * np.log10(np.abs(pressure) / P_REF)
