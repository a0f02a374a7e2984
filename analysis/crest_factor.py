"""Phases for a low crest factor: L^p-norm descent on the phases of a multitone.

Minimising ||x||_p for rising p approaches minimising the peak (p -> inf)
while staying smooth enough for a quasi-Newton method (scipy's L-BFGS-B).
Only the phases move, so the amplitude spectrum stays exactly as designed.
The waveform is evaluated on a grid of at least _POINTS_PER_TOP_CYCLE points
per cycle of the top line, so peaks between samples count too.
"""
from __future__ import annotations

import math

import numpy as np
import scipy.fft
import scipy.optimize

# Exponents of the L^p continuation, powers of two so y**p is a few squarings.
_P_SCHEDULE = (4, 8, 16, 32, 64, 128)
# Points per cycle of the highest line on the grid where the peak is minimised.
_POINTS_PER_TOP_CYCLE = 6
_LBFGS_MEMORY = 8


def reduce_crest_factor(bins: np.ndarray, amplitudes: np.ndarray, phases: np.ndarray,
                         iterations: int) -> np.ndarray:
    """Phases with a lower peak: L^p-norm descent, best waveform kept.

    The gradient of log ||x||_p with respect to the phases costs one FFT:
    d x[n] / d phase_i = -A_i sin(w_i n + phase_i), so the gradient is
    -A_i Im(exp(j phase_i) conj(G[k_i])) with G the FFT of x**(p-1)/sum(x**p).
    """
    if iterations == 0 or bins.size == 1:
        return phases
    # Any grid of more than 2*k_max points holds the same periodic signal.
    grid = scipy.fft.next_fast_len(_POINTS_PER_TOP_CYCLE * (int(bins[-1]) + 1), real=True)
    spectrum = np.zeros(grid // 2 + 1, dtype=np.complex128)
    line_scale = amplitudes * (grid / 2)
    best = {"peak": np.inf, "phases": phases}

    def log_norm_and_gradient(ph: np.ndarray, p: int) -> tuple[float, np.ndarray]:
        rotation = np.exp(1j * ph)
        spectrum[bins] = line_scale * rotation
        x = scipy.fft.irfft(spectrum, grid)
        peak = np.max(np.abs(x))
        if peak < best["peak"]:  # rms is fixed by the amplitudes: lowest peak = lowest crest
            best["peak"], best["phases"] = peak, ph.copy()
        y = x / peak  # NB: normalised so y**p neither overflows nor underflows to all-zero
        y_p = y * y
        for _ in range(int(math.log2(p)) - 1):
            y_p *= y_p
        total = y_p.sum()
        y_p_minus_1 = np.divide(y_p, y, out=np.zeros_like(y), where=y != 0)
        g = scipy.fft.rfft(y_p_minus_1 / (peak * total))[bins]
        return math.log(peak) + math.log(total) / p, -amplitudes * np.imag(rotation * np.conj(g))

    per_stage = max(1, math.ceil(iterations / len(_P_SCHEDULE)))
    current = phases
    for p in _P_SCHEDULE:
        current = scipy.optimize.minimize(log_norm_and_gradient, current, args=(p,), jac=True, method="L-BFGS-B",
                                           options={"maxiter": per_stage, "maxcor": _LBFGS_MEMORY}).x
    return best["phases"]
