"""Start values for the fit, read off the measured impedance and Hx.

The fit must converge without hand tuning on drivers from a 2-inch
full-range to an 18-inch woofer, so nothing here assumes a driver size:

- RE: the lowest real part of Z (the motional branch and eddy-current
  losses only add to it);
- fs and RES: the motional peak of Re(Z) - RE, ignoring a rise that merely
  continues to the top line (that is the voice coil's inductance);
- Qms from the half-value bandwidth of that peak (a parallel resonance);
- LE from Im(Z) / w at the top lines, where the motional branch is spent;
- Bl by linear least squares: Hx = G / Bl with G known once Z is fitted.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from analysis.errors import LinparError
from analysis.spectra import TransferFunction


class StartValueError(LinparError, ValueError):
    """The data show no resonance to start from."""


@dataclass(frozen=True, slots=True)
class StartContext:
    """What the impedance says before any fit: the numbers the start values and the effects' guesses use."""

    RE: float
    fs: float
    RES: float
    Qms: float
    LE_high: float      # Im(Z) / w at the top lines
    f_min: float
    f_max: float
    # The slope d(phase)/dw (s) of measured / model over the top octave, once a model has been
    # fitted (analysis.diagnosis.candidates sets them): where a delay should start. 0 before any fit.
    z_phase_slope: float = 0.0
    x_phase_slope: float = 0.0
    # The measured impedance itself, for effects whose start needs more of it than these numbers
    # (a vented box reads its two peaks). None when the context was made by hand.
    impedance: TransferFunction | None = field(default=None, compare=False, repr=False)

    @property
    def CMES(self) -> float:
        return self.Qms / (2 * np.pi * self.fs * self.RES)

    @property
    def LCES(self) -> float:
        return 1.0 / ((2 * np.pi * self.fs) ** 2 * self.CMES)

    def base_values(self) -> dict[str, float]:
        return {"RE": self.RE, "LE": self.LE_high, "CMES": self.CMES, "LCES": self.LCES, "RES": self.RES}


def _motional_peak(f: np.ndarray, excess: np.ndarray) -> int:
    """Index of the motional resonance peak in Re(Z) - RE."""
    # Local maxima, not at the top edge (a rise to the top is inductive).
    interior = np.flatnonzero((excess[1:-1] >= excess[:-2]) & (excess[1:-1] >= excess[2:])) + 1
    if interior.size == 0:
        raise StartValueError("no resonance peak in the real part of the impedance: is the driver connected "
                              "and does the frequency range include its resonance?")
    # Prefer the largest peak; a breakup peak is usually much smaller than the main one.
    return int(interior[np.argmax(excess[interior])])


def _half_value_bandwidth(f: np.ndarray, excess: np.ndarray, k: int) -> float:
    half = excess[k] / 2
    lo = k
    while lo > 0 and excess[lo] > half:
        lo -= 1
    hi = k
    while hi < len(f) - 1 and excess[hi] > half:
        hi += 1
    f_lo = np.interp(half, [excess[lo], excess[lo + 1]], [f[lo], f[lo + 1]]) if lo < k else f[0]
    f_hi = np.interp(half, [excess[hi], excess[hi - 1]], [f[hi], f[hi - 1]]) if hi > k else f[-1]
    if excess[lo] > half:   # the peak's low side runs past the lowest line: mirror the high side
        f_lo = f[k] ** 2 / f_hi
    if excess[hi] > half:
        f_hi = f[k] ** 2 / f_lo
    return max(f_hi - f_lo, 1e-6 * f[k])


def start_context(z: TransferFunction) -> StartContext:
    finite = np.isfinite(z.value)
    f = z.freqs[finite]
    Z = z.value[finite]
    if f.size < 5:
        raise StartValueError(f"only {f.size} impedance lines: at least 5 are needed to fit the model")
    if z.has_phase:
        real, imag = Z.real, Z.imag
    else:
        # Magnitude only: around the resonance the phase of Z is small, so |Z|
        # stands in for Re(Z); at the top |Z|^2 = RE^2 + (w*LE)^2 gives LE.
        real = np.abs(Z)
        imag = np.sqrt(np.maximum(real**2 - np.min(real) ** 2, 0.0))
    RE = float(np.min(real))
    if RE <= 0:
        RE = float(np.min(np.abs(Z)))
    if not (np.isfinite(RE) and RE > 0):
        # A zero at one line would divide by zero below (CMES = Qms / (w RES), RES ~ 1e-3 RE).
        raise StartValueError(f"the impedance is {RE:g} ohm at a line: expected the resistance of a voice coil; "
                              "check the voltage sense and the current sense")
    excess = real - RE
    k = _motional_peak(f, excess)
    fs = float(f[k])
    RES = float(max(excess[k], 1e-3 * RE))
    Qms = float(np.clip(fs / _half_value_bandwidth(f, excess, k), 0.3, 100.0))
    top = slice(max(len(f) - 5, k + 1), None)
    LE = float(np.median(imag[top] / (2 * np.pi * f[top]))) if len(f[top]) else 0.0
    return StartContext(RE=RE, fs=fs, RES=RES, Qms=Qms, LE_high=max(LE, 1e-7),
                        f_min=float(f[0]), f_max=float(f[-1]), impedance=z)


def impedance_peaks(ctx: StartContext, n: int = 2) -> tuple[np.ndarray, np.ndarray] | None:
    """(frequencies, heights) of the n highest interior peaks of Re(Z) - RE, in rising frequency; None without them."""
    z = ctx.impedance
    if z is None or not z.has_phase:
        return None
    ok = np.isfinite(z.value)
    f, excess = z.freqs[ok], z.value[ok].real - ctx.RE
    interior = np.flatnonzero((excess[1:-1] >= excess[:-2]) & (excess[1:-1] >= excess[2:])) + 1
    if interior.size < n:
        return None
    top = np.sort(interior[np.argsort(excess[interior])[-n:]])
    return f[top], excess[top]


def linear_gain(model_values: np.ndarray, measured: np.ndarray, std: np.ndarray) -> float:
    """The real g minimising sum |g*model - measured|^2 / std^2."""
    w = 1.0 / np.maximum(std, 1e-300) ** 2
    ok = np.isfinite(model_values) & np.isfinite(measured) & np.isfinite(w)
    num = np.sum(w[ok] * (np.conj(model_values[ok]) * measured[ok]).real)
    den = np.sum(w[ok] * np.abs(model_values[ok]) ** 2)
    return float(num / den)


TOP_BAND_RATIO = 2.0     # the top octave


def phase_slope(freqs: np.ndarray, measured: np.ndarray, model_values: np.ndarray, std: np.ndarray) -> float:
    """d(phase)/dw of measured / model over the top octave, weighted by each line's noise (s).

    The phase is unwrapped from the lowest line up, so a delay whose phase
    wraps at the top is followed as long as it moves less than half a turn
    between neighbouring lines. A pure delay tau leaves exactly w*tau; a
    model whose other parameters have bent to absorb some of it leaves less.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = measured / model_values
        weight = (np.abs(measured) / np.maximum(std, 1e-300)) ** 2
    ok = np.isfinite(ratio) & np.isfinite(weight) & (ratio != 0)
    if ok.sum() < 2:
        return 0.0
    f, phase, weight = freqs[ok], np.unwrap(np.angle(ratio[ok])), weight[ok]
    top = f >= f[-1] / TOP_BAND_RATIO
    w = 2.0 * np.pi * f[top]
    den = float(np.sum(weight[top] * w * w))
    return float(np.sum(weight[top] * w * phase[top]) / den) if den > 0 else 0.0
